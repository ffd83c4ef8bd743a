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

#include "bspline_bricks.h"
#include "renderer_internal.h"

static const GLenum internal_formats[] = {GL_R8, GL_R16, 0, GL_R32F};
static const GLenum texel_types[] = {GL_UNSIGNED_BYTE, GL_UNSIGNED_SHORT, 0, GL_FLOAT};

void vxl_paged_release(vxl_renderer *r)
{
    vxl_compressed_release(r);
    if (r->pool_tex) r->gl.DeleteTextures(1, &r->pool_tex);
    if (r->page_tex) r->gl.DeleteTextures(1, &r->page_tex);
    r->pool_tex = r->page_tex = 0;
    for (int k = 0; k < VXL_LOD_LEVELS; k++) vxl_pages_free(&r->levels[k]);
    memset(r->level_dims, 0, sizeof r->level_dims);
    r->n_levels = r->level = 0;
    r->lod_wanted_bytes = 0;
    free(r->resident);
    free(r->page_entries);
    r->resident = NULL;
    r->page_entries = NULL;
    r->pages_resident = r->pages_constant = 0;
    r->pool_bytes = 0;
    memset(r->pool_dims, 0, sizeof r->pool_dims);
}

static uint64_t page_table_bytes(const vxl_pages *pg) { return vxl_page_count(pg) * 16; }

static int pool_layout(const vxl_renderer *r, const vxl_pages *pg, uint32_t n, uint32_t slots[3])
{
    return vxl_pool_layout(r, n, vxl_page_edge(pg), slots);
}

/* Slots per axis for n bricks of edge e within the texture limit; 0 if they cannot fit. */
int vxl_pool_layout(const vxl_renderer *r, uint32_t n, uint32_t e, uint32_t slots[3])
{
    const uint32_t m = (uint32_t)r->info.max_3d_texture_size / e;
    if (m == 0) return 0;
    n = n ? n : 1;
    slots[0] = n < m ? n : m;
    uint32_t rows = (n + slots[0] - 1) / slots[0];
    slots[1] = rows < m ? rows : m;
    slots[2] = (rows + slots[1] - 1) / slots[1];
    return slots[2] <= m;
}

static uint64_t pool_bytes_for(const vxl_pages *pg, const uint32_t slots[3])
{
    const uint64_t e = vxl_page_edge(pg);
    return slots[0] * e * slots[1] * e * slots[2] * e * pg->bytes_per_voxel;
}

/* Whether the pool is the code pool (compressed storage filtered in the
 * compressed domain): every data brick, at its code slot, nothing decoded. */
static int pool_is_codes(const vxl_renderer *r) { return r->storage == VXL_STORAGE_COMPRESSED && r->compressed_domain; }

/* Builds the pool from the bricks of `level` marked in need[] and uploads
 * the page table. Refuses, naming the budget, when they do not fit. */
static int upload_pool(vxl_renderer *r, uint32_t level, const uint8_t *need)
{
    vxl_gl *gl = &r->gl;
    vxl_pages *pg = &r->levels[level];
    const uint64_t n = vxl_page_count(pg);
    const int coded = r->storage == VXL_STORAGE_COMPRESSED, in_codes = pool_is_codes(r);
    uint32_t count = 0, slots[3];
    for (uint64_t i = 0; i < n; i++) count += need[i];
    if (!pool_layout(r, pg, count, slots))
        return vxl_fail(&r->err, VXL_ERR_LIMIT, "%u bricks of %u^3 voxels do not fit a pool texture within the 3D texture limit of %d",
                        count, vxl_page_edge(pg), r->info.max_3d_texture_size);
    const uint64_t bytes = (in_codes ? 0 : pool_bytes_for(pg, slots)) + page_table_bytes(pg) + r->code_bytes;
    if (bytes > r->budget)
        return vxl_fail(&r->err, VXL_ERR_LIMIT,
                        "%u resident bricks need %.1f MiB, over the renderer's memory budget of %.1f MiB%s", count,
                        bytes / 1048576.0, r->budget / 1048576.0,
                        r->storage == VXL_STORAGE_BRICKED ? " (sparse storage keeps only visible bricks)" : "");
    const uint32_t e = vxl_page_edge(pg), fi = pg->bytes_per_voxel - 1;
    const size_t brick_bytes = (size_t)e * e * e * pg->bytes_per_voxel;
    int32_t *source = coded ? malloc((count ? count : 1) * sizeof *source) : NULL;
    if (coded && !source) return vxl_fail(&r->err, VXL_ERR_NO_MEMORY, "out of memory for the decode list");
    gl->GetError();
    if (in_codes) {
        r->pool_tex = r->code_tex;
        memcpy(slots, r->code_slots, sizeof slots);
    } else {
        if (r->pool_tex) gl->DeleteTextures(1, &r->pool_tex);
        r->pool_tex = vxl_texture_new(r, GL_TEXTURE_3D, GL_LINEAR);
        gl->TexImage3D(GL_TEXTURE_3D, 0, (GLint)internal_formats[fi], (GLsizei)(slots[0] * e), (GLsizei)(slots[1] * e),
                       (GLsizei)(slots[2] * e), 0, GL_RED, texel_types[fi], NULL);
    }
    for (int a = 0; a < 3; a++) r->pool_dims[a] = slots[a] * e;
    uint32_t k = 0, constant = 0;
    for (uint64_t i = 0; i < n; i++) {
        float *pe = r->page_entries + 4 * i;
        r->resident[i] = need[i];
        if (!need[i]) { /* constant, or invisible: its value (the minimum) classifies as transparent */
            pe[0] = pe[1] = pe[2] = 0;
            pe[3] = pg->low[i];
            constant += pg->data_index[i] < 0;
            continue;
        }
        const uint32_t slot = in_codes ? (uint32_t)pg->data_index[i] : k;
        const uint32_t o[3] = {slot % slots[0] * e, slot / slots[0] % slots[1] * e, slot / (slots[0] * slots[1]) * e};
        if (coded)
            source[k] = pg->data_index[i];
        else
            gl->TexSubImage3D(GL_TEXTURE_3D, 0, (GLint)o[0], (GLint)o[1], (GLint)o[2], (GLsizei)e, (GLsizei)e,
                              (GLsizei)e, GL_RED, texel_types[fi], pg->data + (size_t)pg->data_index[i] * brick_bytes);
        for (int a = 0; a < 3; a++) pe[a] = (float)(o[a] + VXL_PAGE_GHOST);
        pe[3] = -1;
        k++;
    }
    if (!r->page_tex) r->page_tex = vxl_texture_new(r, GL_TEXTURE_3D, GL_NEAREST);
    gl->BindTexture(GL_TEXTURE_3D, r->page_tex);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA32F, (GLsizei)pg->grid[0], (GLsizei)pg->grid[1], (GLsizei)pg->grid[2], 0,
                   GL_RGBA, GL_FLOAT, r->page_entries);
    int rc = vxl_gl_check(r, "uploading the brick pool");
    if (!rc && coded && !in_codes) rc = vxl_compressed_decode(r, source, count, slots);
    free(source);
    if (rc) return rc;
    r->pages_resident = count;
    r->pages_constant = constant;
    r->pool_generation++;
    r->pool_bytes = bytes;
    r->level = level;
    return VXL_OK;
}

/* Bytes of the pool holding n bricks plus the page table; UINT64_MAX when
 * the pool cannot fit the texture limit. */
static uint64_t resident_bytes_for(const vxl_renderer *r, const vxl_pages *pg, uint32_t n)
{
    uint32_t slots[3];
    return pool_layout(r, pg, n, slots) ? pool_bytes_for(pg, slots) + page_table_bytes(pg) : UINT64_MAX;
}

static void plan_free(vxl_paged_volume *pv)
{
    for (int k = 0; k < VXL_LOD_LEVELS; k++) vxl_pages_free(&pv->levels[k]);
    vxl_bricks_free(&pv->bricks);
}

/* Sparse storage keeps coarser levels for the LOD fallback: each a 2x
 * downsampled copy, cut into bricks the same way. */
static int plan_levels(vxl_renderer *r, const vxl_volume *v, uint32_t brick, vxl_paged_volume *out)
{
    const vxl_volume *src = v;
    vxl_volume *coarse = NULL;
    int rc = VXL_OK;
    for (uint32_t k = 1; k < VXL_LOD_LEVELS && !rc; k++) {
        vxl_volume *next = NULL;
        if ((rc = vxl_volume_downsample2(src, &next, &r->err))) break;
        vxl_volume_destroy(coarse);
        coarse = next;
        src = coarse;
        rc = vxl_pages_build(&out->levels[k], coarse, brick, &r->err);
        memcpy(out->level_dims[k], coarse->dims, sizeof out->level_dims[k]);
        if (!rc) out->n_levels = k + 1;
    }
    vxl_volume_destroy(coarse);
    return rc;
}

int vxl_paged_plan(vxl_renderer *r, const vxl_volume *v, uint32_t storage, vxl_paged_volume *out)
{
    memset(out, 0, sizeof *out);
    uint32_t brick = r->page_brick_request ? r->page_brick_request : VXL_DEFAULT_PAGE_BRICK;
    vxl_pages *pg = &out->levels[0];
    int rc = vxl_pages_build(pg, v, brick, &r->err);
    if (!rc) rc = vxl_bricks_minmax_cpu(&out->bricks, v, vxl_skip_brick_size(), &r->err);
    memcpy(out->level_dims[0], v->dims, sizeof out->level_dims[0]);
    out->n_levels = 1;
    if (rc) {
        plan_free(out);
        return rc;
    }
    uint64_t all = resident_bytes_for(r, pg, pg->n_data), none = resident_bytes_for(r, pg, 0);
    /* AUTO, dense did not fit: every brick when they fit the budget, else
     * only the visible ones (sparse), with its coarser levels to fall back
     * on; the stats, the CLI and the panel say which. */
    if (storage == VXL_STORAGE_AUTO) storage = all > r->budget ? VXL_STORAGE_SPARSE : VXL_STORAGE_BRICKED;
    out->storage = storage;
    if (storage == VXL_STORAGE_SPARSE && (rc = plan_levels(r, v, brick, out))) {
        plan_free(out);
        return rc;
    }
    uint64_t need = storage == VXL_STORAGE_BRICKED ? all : none;
    if (storage == VXL_STORAGE_COMPRESSED) { /* every brick's codes, and a cache that follows the classification */
        uint64_t codes = vxl_code_bytes_for(r, pg), rest = r->compressed_domain ? page_table_bytes(pg) : none;
        need = codes == UINT64_MAX || rest == UINT64_MAX ? UINT64_MAX : codes + rest;
    }
    if (need > r->budget) {
        const char *hint = storage == VXL_STORAGE_BRICKED ? "; sparse storage keeps only the visible bricks" : "";
        rc = need == UINT64_MAX
                 ? vxl_fail(&r->err, VXL_ERR_LIMIT, "%u bricks of %u^3 voxels do not fit a pool texture within the 3D texture limit of %d%s",
                            pg->n_data, vxl_page_edge(pg), r->info.max_3d_texture_size, hint)
                 : vxl_fail(&r->err, VXL_ERR_LIMIT,
                            "%s storage of %ux%ux%u needs %.1f MiB, over the renderer's memory budget of %.1f MiB%s",
                            vxl_storage_name(storage), v->dims[0], v->dims[1], v->dims[2], need / 1048576.0,
                            r->budget / 1048576.0, hint);
        plan_free(out);
    }
    return rc;
}

int vxl_paged_install(vxl_renderer *r, vxl_paged_volume *pv)
{
    memcpy(r->levels, pv->levels, sizeof r->levels);
    memcpy(r->level_dims, pv->level_dims, sizeof r->level_dims);
    r->n_levels = pv->n_levels;
    r->level = 0;
    for (int k = 0; k < VXL_LOD_LEVELS; k++) r->gradient_max_level[k] = -1;
    r->bricks = pv->bricks;
    r->storage = pv->storage;
    memset(pv, 0, sizeof *pv);
    const uint64_t n = vxl_page_count(&r->levels[0]); /* the finest level has the most bricks */
    r->resident = calloc(n, 1);
    r->page_entries = malloc(n * 4 * sizeof(float));
    if (!r->resident || !r->page_entries) return vxl_fail(&r->err, VXL_ERR_NO_MEMORY, "out of memory for the page table");
    if (r->storage == VXL_STORAGE_COMPRESSED) {
        int rc = vxl_compressed_upload(r);
        if (rc || !r->compressed_domain) return rc; /* the cache follows the first frame's classification */
    }
    if (r->storage == VXL_STORAGE_SPARSE) return VXL_OK; /* the pool follows the first frame's classification */
    uint8_t *need = malloc(n);
    if (!need) return vxl_fail(&r->err, VXL_ERR_NO_MEMORY, "out of memory for the page table");
    for (uint64_t i = 0; i < n; i++) need[i] = r->levels[0].data_index[i] >= 0;
    int rc = upload_pool(r, 0, need);
    free(need);
    free(r->levels[0].data); /* on the GL side now; BRICKED never uploads again */
    r->levels[0].data = NULL;
    return rc;
}

int vxl_paged_check_filter(vxl_renderer *r, uint32_t filter, uint32_t classify)
{
    if (!r->storage || r->storage == VXL_STORAGE_DENSE) return VXL_OK;
    const int derived = filter == VXL_FILTER_PRECOMPUTED || filter == VXL_FILTER_CUBIC;
    const char *what = r->storage == VXL_STORAGE_COMPRESSED && r->compressed_domain && (derived || classify == VXL_CLASSIFY_PRE)
                           ? "filtering in the compressed domain (a comparison mode) with the precomputed or cubic filter or pre-classification"
                       : r->storage == VXL_STORAGE_COMPRESSED && derived
                           ? "the precomputed and cubic filters with compressed storage (their data is derived from every brick's values, which only the GL side keeps, as codes)"
                           : NULL;
    if (!what) return VXL_OK;
    return vxl_fail(&r->err, VXL_ERR_STATE,
                    "%s is not supported (volume %ux%ux%u); use bricked or sparse storage, or central, forward3, "
                    "sobel8, sobel14 or sobel26",
                    what, r->dims[0], r->dims[1], r->dims[2]);
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

/* Bytes a frame derives from the pool of `level` (pool_part bytes): the
 * derived filter's pool (cubic coefficients, precomputed gradients) and the
 * pre-classified pool, so the level chosen fits all of them. */
static uint64_t derived_bytes(const vxl_renderer *r, const vxl_frame *f, uint32_t level, uint64_t pool_part,
                              uint8_t *scratch)
{
    if (!f) return 0;
    const uint32_t filter = vxl_frame_filter(f);
    uint64_t b = filter == VXL_FILTER_CUBIC         ? vxl_paged_bspline_bytes(r, level, scratch, NULL)
                 : filter == VXL_FILTER_PRECOMPUTED ? vxl_paged_gradient_bytes(r, level, (int)f->store, scratch, NULL)
                                                    : 0;
    if (b != UINT64_MAX && f->classify == VXL_CLASSIFY_PRE) b += pool_part / r->levels[level].bytes_per_voxel * 4;
    return b;
}

/* Sparse: the finest level whose visible bricks fit the budget. Falls back
 * to coarser levels (reported in the stats) and fails naming the budget
 * only when even the coarsest does not fit. */
int vxl_paged_prepare(vxl_renderer *r, const vxl_frame *f)
{
    r->decode_ms = 0;
    /* what derived pools (gradients, coefficients) must cover */
    r->visible_reach = f ? visible_reach(f) : 0;
    r->visible_all = !f || f->gopacity == VXL_GOPACITY_ISO || r->storage == VXL_STORAGE_BRICKED;
    if (r->storage != VXL_STORAGE_SPARSE && (r->storage != VXL_STORAGE_COMPRESSED || pool_is_codes(r))) return VXL_OK;
    uint32_t reach = r->visible_reach;
    /* precomputed gradients read near a visible sample are derived from the
     * values around them */
    if (f && vxl_frame_filter(f) == VXL_FILTER_PRECOMPUTED)
        reach = (reach > VXL_GRADIENT_READ_REACH ? reach : VXL_GRADIENT_READ_REACH) + VXL_GRADIENT_SUPPORT;
    const int all = r->visible_all;
    const uint64_t n0 = vxl_page_count(&r->levels[0]);
    uint8_t *need = malloc(2 * n0), *scratch = need + n0;
    if (!need) return vxl_fail(&r->err, VXL_ERR_NO_MEMORY, "out of memory for the page table");
    uint64_t wanted = 0, bytes = UINT64_MAX;
    uint32_t level = 0;
    for (; level < r->n_levels; level++) { /* f == NULL (probes): full resolution only */
        uint32_t count = vxl_pages_needed(&r->levels[level], &r->bricks, reach, 1u << level, all, NULL, need);
        bytes = resident_bytes_for(r, &r->levels[level], count);
        if (bytes != UINT64_MAX) {
            uint64_t d = derived_bytes(r, f, level, bytes - page_table_bytes(&r->levels[level]), scratch);
            bytes = d == UINT64_MAX ? d : bytes + r->code_bytes + d;
        }
        if (level == 0) wanted = bytes;
        if (bytes <= r->budget || !f) break;
    }
    if (level == r->n_levels && r->n_levels == 1) { /* compressed storage has no coarser levels */
        free(need);
        return vxl_fail(&r->err, VXL_ERR_LIMIT,
                        "the visible bricks need %.1f MiB (codes, decode cache and what the frame derives from it), over the renderer's memory budget "
                        "of %.1f MiB",
                        wanted / 1048576.0, r->budget / 1048576.0);
    }
    if (level == r->n_levels) {
        free(need);
        return vxl_fail(&r->err, VXL_ERR_LIMIT,
                        "the visible bricks (and what the frame derives from them) need %.1f MiB at full resolution and still %.1f MiB at %ux coarser, over "
                        "the renderer's memory budget of %.1f MiB",
                        wanted / 1048576.0, bytes / 1048576.0, 1u << (r->n_levels - 1), r->budget / 1048576.0);
    }
    const uint64_t n = vxl_page_count(&r->levels[level]);
    int grow = !r->pool_tex || level != r->level;
    for (uint64_t i = 0; i < n && !grow; i++) grow = need[i] && !r->resident[i];
    int rc = grow ? upload_pool(r, level, need) : VXL_OK;
    if (!rc) r->lod_wanted_bytes = level ? wanted : 0;
    free(need);
    return rc;
}
