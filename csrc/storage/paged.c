/* paged.c - bricked storage on the GL side: the pool texture (an atlas of
 * page bricks with their ghost borders) and the page table (RGBA32F, one
 * texel per brick: xyz = where the brick's voxel 0 lies in the pool, w < 0
 * resident, w >= 0 the brick's value when it is not in the pool). BRICKED
 * makes every non-constant brick resident at set_volume; SPARSE makes
 * resident only the bricks the frame's classification can see, re-derived
 * from the skipping grid when the classification changes. COMPRESSED keeps
 * the codes of every data brick on the GL side (compressed_pool.c) and
 * decodes the bricks the classification can see into the pool, which is
 * then a linear cache (deferred filtering); filtering in the compressed
 * domain, the code pool itself is the pool. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "storage.h"


void vxl_paged_release(vxl_storage_state *st)
{
    vxl_compressed_release(st);
    if (st->pool_tex) st->gpu->gl.DeleteTextures(1, &st->pool_tex);
    if (st->page_tex) st->gpu->gl.DeleteTextures(1, &st->page_tex);
    st->pool_tex = st->page_tex = 0;
    for (int k = 0; k < VXL_LOD_LEVELS; k++) vxl_pages_free(&st->levels[k]);
    memset(st->level_dims, 0, sizeof st->level_dims);
    st->n_levels = st->level = 0;
    st->lod_wanted_bytes = 0;
    free(st->resident);
    free(st->page_entries);
    st->resident = NULL;
    st->page_entries = NULL;
    st->pages_resident = st->pages_constant = 0;
    st->pool_bytes = 0;
    memset(st->pool_dims, 0, sizeof st->pool_dims);
}

static uint64_t page_table_bytes(const vxl_pages *pg) { return vxl_page_count(pg) * 16; }

static int pool_layout(const vxl_storage_state *st, const vxl_pages *pg, uint32_t n, uint32_t slots[3])
{
    return vxl_pool_layout(st, n, vxl_page_edge(pg), slots);
}

static uint64_t pool_bytes_for(const vxl_pages *pg, const uint32_t slots[3])
{
    const uint64_t e = vxl_page_edge(pg);
    return slots[0] * e * slots[1] * e * slots[2] * e * pg->bytes_per_voxel;
}

/* Whether the pool is the code pool (compressed storage filtered in the
 * compressed domain): every data brick, at its code slot, nothing decoded. */
static int pool_is_codes(const vxl_storage_state *st) { return st->mode == VXL_STORAGE_COMPRESSED && st->compressed_domain; }

/* Builds the pool from the bricks of `level` marked in need[] and uploads
 * the page table. Refuses, naming the budget, when they do not fit. */
static int upload_pool(vxl_storage_state *st, uint32_t level, const uint8_t *need)
{
    vxl_gl *gl = &st->gpu->gl;
    vxl_pages *pg = &st->levels[level];
    const uint64_t n = vxl_page_count(pg);
    const int coded = st->mode == VXL_STORAGE_COMPRESSED, in_codes = pool_is_codes(st);
    uint32_t count = 0, slots[3];
    for (uint64_t i = 0; i < n; i++) count += need[i];
    if (!pool_layout(st, pg, count, slots))
        return vxl_fail(&st->gpu->err, VXL_ERR_LIMIT, "%u bricks of %u^3 voxels do not fit a pool texture within the 3D texture limit of %d",
                        count, vxl_page_edge(pg), st->gpu->info.max_3d_texture_size);
    const uint64_t bytes = (in_codes ? 0 : pool_bytes_for(pg, slots)) + page_table_bytes(pg) + st->code_bytes;
    const int over = vxl_budget_ask(st->gpu->budget, NULL, VXL_HOLD_STORAGE, bytes, &st->gpu->err,
                                    st->mode == VXL_STORAGE_BRICKED ? " (sparse storage keeps only visible bricks)" : NULL,
                                    "%u resident bricks", count);
    if (over) return over;
    const uint32_t e = vxl_page_edge(pg), bpv = pg->bytes_per_voxel;
    const size_t brick_bytes = (size_t)e * e * e * pg->bytes_per_voxel;
    int32_t *source = coded ? malloc((count ? count : 1) * sizeof *source) : NULL;
    if (coded && !source) return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the decode list");
    gl->GetError();
    if (in_codes) {
        st->pool_tex = st->code_tex;
        memcpy(slots, st->code_slots, sizeof slots);
    } else {
        if (st->pool_tex) gl->DeleteTextures(1, &st->pool_tex);
        st->pool_tex = vxl_texture_new(st->gpu, GL_TEXTURE_3D, GL_LINEAR);
        gl->TexImage3D(GL_TEXTURE_3D, 0, (GLint)vxl_texel_internal_format(bpv), (GLsizei)(slots[0] * e), (GLsizei)(slots[1] * e),
                       (GLsizei)(slots[2] * e), 0, GL_RED, vxl_texel_type(bpv), NULL);
    }
    for (int a = 0; a < 3; a++) st->pool_dims[a] = slots[a] * e;
    uint32_t k = 0, constant = 0;
    for (uint64_t i = 0; i < n; i++) {
        float *pe = st->page_entries + 4 * i;
        st->resident[i] = need[i];
        if (!need[i]) { /* constant, or invisible: its value (the minimum) classifies as transparent */
            pe[0] = pe[1] = pe[2] = 0;
            pe[3] = pg->low[i];
            constant += pg->data_index[i] < 0;
            continue;
        }
        const uint32_t slot = in_codes ? (uint32_t)pg->data_index[i] : k;
        uint32_t o[3];
        vxl_slot_origin(slot, slots, e, o);
        if (coded)
            source[k] = pg->data_index[i];
        else
            gl->TexSubImage3D(GL_TEXTURE_3D, 0, (GLint)o[0], (GLint)o[1], (GLint)o[2], (GLsizei)e, (GLsizei)e,
                              (GLsizei)e, GL_RED, vxl_texel_type(bpv), pg->data + (size_t)pg->data_index[i] * brick_bytes);
        for (int a = 0; a < 3; a++) pe[a] = (float)(o[a] + VXL_PAGE_GHOST);
        pe[3] = -1;
        k++;
    }
    vxl_page_table_upload(st, &st->page_tex, pg, st->page_entries);
    int rc = vxl_gl_check(st->gpu, "uploading the brick pool");
    if (!rc && coded && !in_codes) rc = vxl_compressed_decode(st, source, count, slots);
    free(source);
    if (rc) return rc;
    st->pages_resident = count;
    st->pages_constant = constant;
    st->pool_generation++;
    st->pool_bytes = bytes;
    st->level = level;
    return VXL_OK;
}

/* Bytes of the pool holding n bricks plus the page table; UINT64_MAX when
 * the pool cannot fit the texture limit. */
static uint64_t resident_bytes_for(const vxl_storage_state *st, const vxl_pages *pg, uint32_t n)
{
    uint32_t slots[3];
    return pool_layout(st, pg, n, slots) ? pool_bytes_for(pg, slots) + page_table_bytes(pg) : UINT64_MAX;
}

/* Sparse storage keeps coarser levels for the LOD fallback: each a 2x
 * downsampled copy, cut into bricks the same way. */
static int plan_levels(vxl_storage_state *st, const vxl_volume *v, uint32_t brick, vxl_storage_plan *out)
{
    const vxl_volume *src = v;
    vxl_volume *coarse = NULL;
    int rc = VXL_OK;
    for (uint32_t k = 1; k < VXL_LOD_LEVELS && !rc; k++) {
        vxl_volume *next = NULL;
        if ((rc = vxl_volume_downsample2(src, &next, &st->gpu->err))) break;
        vxl_volume_destroy(coarse);
        coarse = next;
        src = coarse;
        rc = vxl_pages_build(&out->levels[k], coarse, brick, &st->gpu->err);
        memcpy(out->level_dims[k], coarse->dims, sizeof out->level_dims[k]);
        if (!rc) out->n_levels = k + 1;
    }
    vxl_volume_destroy(coarse);
    return rc;
}

int vxl_paged_plan(vxl_storage_state *st, const vxl_volume *v, uint32_t storage, vxl_storage_plan *out)
{
    memset(out, 0, sizeof *out);
    uint32_t brick = st->page_brick_request ? st->page_brick_request : VXL_DEFAULT_PAGE_BRICK;
    vxl_pages *pg = &out->levels[0];
    int rc = vxl_pages_build(pg, v, brick, &st->gpu->err);
    if (!rc) rc = vxl_bricks_minmax_cpu(&out->bricks, v, vxl_skip_brick_size(), &st->gpu->err);
    memcpy(out->level_dims[0], v->dims, sizeof out->level_dims[0]);
    out->n_levels = 1;
    if (rc) {
        vxl_storage_plan_free(out);
        return rc;
    }
    uint64_t all = resident_bytes_for(st, pg, pg->n_data), none = resident_bytes_for(st, pg, 0);
    /* AUTO, dense did not fit: every brick when they fit the budget, else
     * only the visible ones (sparse), with its coarser levels to fall back
     * on; the stats, the CLI and the panel say which. */
    if (storage == VXL_STORAGE_AUTO)
        storage = vxl_budget_fits(st->gpu->budget, NULL, VXL_HOLD_STORAGE, all) ? VXL_STORAGE_BRICKED : VXL_STORAGE_SPARSE;
    out->mode = storage;
    if (storage == VXL_STORAGE_SPARSE && (rc = plan_levels(st, v, brick, out))) {
        vxl_storage_plan_free(out);
        return rc;
    }
    uint64_t need = storage == VXL_STORAGE_BRICKED ? all : none;
    if (storage == VXL_STORAGE_COMPRESSED) { /* every brick's codes, and a cache that follows the classification */
        uint64_t codes = vxl_code_bytes_for(st, pg), rest = st->compressed_domain ? page_table_bytes(pg) : none;
        need = codes == UINT64_MAX || rest == UINT64_MAX ? UINT64_MAX : codes + rest;
    }
    out->bytes = need;
    if (!vxl_budget_fits(st->gpu->budget, NULL, VXL_HOLD_STORAGE, need)) {
        const char *hint = storage == VXL_STORAGE_BRICKED ? "; sparse storage keeps only the visible bricks" : "";
        rc = need == UINT64_MAX
                 ? vxl_fail(&st->gpu->err, VXL_ERR_LIMIT, "%u bricks of %u^3 voxels do not fit a pool texture within the 3D texture limit of %d%s",
                            pg->n_data, vxl_page_edge(pg), st->gpu->info.max_3d_texture_size, hint)
                 : vxl_budget_ask(st->gpu->budget, NULL, VXL_HOLD_STORAGE, need, &st->gpu->err, hint, "%s storage of %ux%ux%u",
                                  vxl_storage_name(storage), v->dims[0], v->dims[1], v->dims[2]);
        vxl_storage_plan_free(out);
    }
    return rc;
}

int vxl_paged_adopt(vxl_storage_state *st, const vxl_volume *v, vxl_storage_plan *pv)
{
    (void)v; /* the plan holds the bricks */
    memcpy(st->levels, pv->levels, sizeof st->levels);
    memcpy(st->level_dims, pv->level_dims, sizeof st->level_dims);
    st->n_levels = pv->n_levels;
    st->level = 0;
    st->mode = pv->mode;
    const vxl_bricks grid = pv->bricks; /* stays in the plan: the caller hands it to skipping */
    memset(pv, 0, sizeof *pv);
    pv->bricks = grid;
    const uint64_t n = vxl_page_count(&st->levels[0]); /* the finest level has the most bricks */
    st->resident = calloc(n, 1);
    st->page_entries = malloc(n * 4 * sizeof(float));
    st->volume_bytes = 0;
    if (!st->resident || !st->page_entries) return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the page table");
    return VXL_OK;
}

int vxl_paged_upload_all(vxl_storage_state *st)
{
    const uint64_t n = vxl_page_count(&st->levels[0]);
    uint8_t *need = malloc(n);
    if (!need) return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the page table");
    for (uint64_t i = 0; i < n; i++) need[i] = st->levels[0].data_index[i] >= 0;
    int rc = upload_pool(st, 0, need);
    free(need);
    free(st->levels[0].data); /* on the GL side now; BRICKED never uploads again */
    st->levels[0].data = NULL;
    if (!rc) st->volume_bytes = st->pool_bytes;
    return rc;
}

/* Voxels from a visible sample at which a frame reads values: gradient taps
 * sample_distance away plus the trilinear footprint, and the front of a
 * pre-integrated segment one step back. */
static uint32_t visible_reach(const vxl_frame *f)
{
    uint32_t reach = (uint32_t)ceilf(f->sample_distance) + 1;
    if (f->classify == VXL_CLASSIFY_PREINT) reach += (uint32_t)ceilf(f->step);
    return reach;
}

/* Sparse: the finest level whose visible bricks fit the budget. Falls back
 * to coarser levels (reported in the stats) and fails naming the budget
 * only when even the coarsest does not fit. */
void vxl_paged_see(vxl_storage_state *st, const vxl_frame *f, int every)
{
    st->decode_ms = 0;
    /* what derived pools (gradients, coefficients) must cover */
    st->visible_reach = f ? visible_reach(f) : 0;
    /* a projection or iso-surface reads every brick, not only the table's visible ones */
    st->visible_all = !f || f->gopacity == VXL_GOPACITY_ISO || f->mode != VXL_MODE_DVR || every;
}

int vxl_paged_make_resident(vxl_storage_state *st, const vxl_frame *f)
{
    uint32_t reach = st->visible_reach;
    /* a derived volume computed from the pool (precomputed gradients) read
     * near a visible sample is derived from the values around them */
    const int which = f ? vxl_derived_for_filter(vxl_frame_filter(f)) : -1;
    const vxl_derived *d = which < 0 ? NULL : &st->derived[which];
    if (d && d->reads_pool) reach = (reach > d->read_reach ? reach : d->read_reach) + d->support;
    const int all = st->visible_all;
    const uint64_t n0 = vxl_page_count(&st->levels[0]);
    uint8_t *need = malloc(2 * n0), *scratch = need + n0;
    if (!need) return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the page table");
    uint64_t wanted = 0, bytes = UINT64_MAX;
    uint32_t level = 0;
    for (; level < st->n_levels; level++) { /* f == NULL (probes): full resolution only */
        uint32_t count = vxl_pages_needed(&st->levels[level], st->grid, reach, 1u << level, all, NULL, need);
        bytes = resident_bytes_for(st, &st->levels[level], count);
        if (bytes != UINT64_MAX) {
            uint64_t d = vxl_paged_derived_bytes(st, f, level, bytes - page_table_bytes(&st->levels[level]), scratch);
            bytes = d == UINT64_MAX ? d : bytes + st->code_bytes + d;
        }
        if (level == 0) wanted = bytes;
        if (vxl_budget_fits(st->gpu->budget, NULL, VXL_HOLD_STORAGE, bytes) || !f) break;
    }
    if (level == st->n_levels && st->n_levels == 1) { /* compressed storage has no coarser levels */
        free(need);
        return vxl_budget_ask(st->gpu->budget, NULL, VXL_HOLD_STORAGE, wanted, &st->gpu->err, NULL,
                              "the visible bricks (codes, decode cache and what the frame derives from them)");
    }
    if (level == st->n_levels) {
        free(need);
        return vxl_budget_ask(st->gpu->budget, NULL, VXL_HOLD_STORAGE, bytes, &st->gpu->err, NULL,
                              "the visible bricks (and what the frame derives from them) at %ux coarser, %.1f MiB at full resolution",
                              1u << (st->n_levels - 1), wanted / 1048576.0);
    }
    const uint64_t n = vxl_page_count(&st->levels[level]);
    int grow = !st->pool_tex || level != st->level;
    for (uint64_t i = 0; i < n && !grow; i++) grow = need[i] && !st->resident[i];
    int rc = grow ? upload_pool(st, level, need) : VXL_OK;
    if (!rc) st->lod_wanted_bytes = level ? wanted : 0;
    free(need);
    return rc;
}
