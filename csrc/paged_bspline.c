/* paged_bspline.c - the cubic filter with bricked and sparse storage: B-spline
 * coefficients brick by brick (bspline_bricks.c, on the CPU from the bricks'
 * values) in a coefficient pool with a one-voxel ghost and its own page
 * table, laid out like the data (shaders/gradients.glsl, coeff()). Only the
 * bricks a frame can read are made: those within the cubic footprint of a
 * visible sample whose coefficients are not one constant. */
#include <stdlib.h>
#include <string.h>

#include "bspline_bricks.h"
#include "renderer_internal.h"

/* The cubic footprint: coefficients at floor(p) - 1 .. floor(p) + 2. A
 * brick's coefficients are one constant when everything within the margin
 * and the ghost is. */
#define CUBIC_READ_REACH 3
#define CUBIC_SUPPORT (VXL_BSPLINE_MARGIN + VXL_PAGE_GHOST)

int vxl_paged_brick_store(vxl_renderer *r, vxl_brick_store *s, uint8_t **owned)
{
    const vxl_pages *pg = &r->levels[r->level];
    *owned = NULL;
    if (pg->data || !pg->n_data) { /* no data bricks: every brick is its constant */
        *s = vxl_pages_store(pg);
        return VXL_OK;
    }
    /* bricked storage dropped its CPU bricks at upload: every data brick is
     * in the pool, slot = data index, so the pool read back is the store */
    if (r->storage != VXL_STORAGE_BRICKED || r->level != 0)
        return vxl_fail(&r->err, VXL_ERR_STATE, "the bricks' values are not kept on the CPU for %s storage",
                        vxl_storage_name(r->storage));
    static const GLenum types[] = {GL_UNSIGNED_BYTE, GL_UNSIGNED_SHORT, 0, GL_FLOAT};
    const uint64_t bytes = (uint64_t)r->pool_dims[0] * r->pool_dims[1] * r->pool_dims[2] * pg->bytes_per_voxel;
    uint8_t *buf = malloc(bytes ? bytes : 1);
    if (!buf) return vxl_fail(&r->err, VXL_ERR_NO_MEMORY, "out of memory reading back %.1f MiB of bricks", bytes / 1048576.0);
    vxl_gl *gl = &r->gl;
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, r->pool_tex);
    gl->GetTexImage(GL_TEXTURE_3D, 0, GL_RED, types[pg->bytes_per_voxel - 1], buf);
    int rc = vxl_gl_check(r, "reading back the brick pool");
    if (rc) {
        free(buf);
        return rc;
    }
    const uint32_t e = vxl_page_edge(pg);
    *s = (vxl_brick_store){buf, {r->pool_dims[0] / e, r->pool_dims[1] / e}, e, pg->bytes_per_voxel};
    *owned = buf;
    return VXL_OK;
}

uint32_t vxl_paged_derived_want(const vxl_renderer *r, uint32_t level, uint32_t support, uint32_t read_reach,
                                uint8_t *want)
{
    const vxl_pages *pg = &r->levels[level];
    const uint64_t n = vxl_page_count(pg);
    for (uint64_t i = 0; i < n; i++) want[i] = !vxl_pages_flat_around(pg, i, support);
    const uint32_t reach = r->visible_reach > read_reach ? r->visible_reach : read_reach;
    return vxl_pages_needed(pg, &r->bricks, reach, 1u << level, r->visible_all, want, want);
}

uint64_t vxl_paged_bspline_bytes(const vxl_renderer *r, uint32_t level, uint8_t *want, uint32_t *count_out)
{
    const vxl_pages *pg = &r->levels[level];
    const uint32_t count = vxl_paged_derived_want(r, level, CUBIC_SUPPORT, CUBIC_READ_REACH, want), e = vxl_page_edge(pg);
    uint32_t slots[3];
    if (count_out) *count_out = count;
    if (!vxl_pool_layout(r, count, e, slots)) return UINT64_MAX;
    return (uint64_t)slots[0] * slots[1] * slots[2] * e * e * e * 4 + vxl_page_count(pg) * 16;
}

int vxl_paged_derived_current(const vxl_renderer *r, const uint8_t *covered, uint32_t level, const uint8_t *want)
{
    if (!covered || level != r->level) return 0;
    const uint64_t n = vxl_page_count(&r->levels[r->level]);
    for (uint64_t i = 0; i < n; i++)
        if (want[i] && !covered[i]) return 0;
    return 1;
}

int vxl_paged_bspline_ensure(vxl_renderer *r)
{
    const vxl_pages *pg = &r->levels[r->level];
    const uint64_t n = vxl_page_count(pg);
    uint8_t *want = malloc(n);
    if (!want) return vxl_fail(&r->err, VXL_ERR_NO_MEMORY, "out of memory for the coefficient page table");
    uint32_t count;
    const uint64_t bytes = vxl_paged_bspline_bytes(r, r->level, want, &count);
    if (r->bspline_tex && vxl_paged_derived_current(r, r->bspline_covered, r->bspline_level, want)) {
        free(want);
        return VXL_OK;
    }
    vxl_bspline_release(r);
    vxl_gradients_release(r); /* one derived pool at a time: storage that pages is short of memory */
    const uint32_t e = vxl_page_edge(pg);
    uint32_t slots[3];
    if (bytes == UINT64_MAX || !vxl_pool_layout(r, count, e, slots)) {
        free(want);
        return vxl_fail(&r->err, VXL_ERR_LIMIT, "%u coefficient bricks do not fit a pool within the 3D texture limit of %d",
                        count, r->info.max_3d_texture_size);
    }
    const uint64_t need = r->pool_bytes + r->classified_bytes + bytes;
    if (need > r->budget) {
        free(want);
        return vxl_fail(&r->err, VXL_ERR_LIMIT,
                        "cubic B-spline coefficients of %u bricks need %.1f MiB in all, over the memory budget of %.1f MiB",
                        count, need / 1048576.0, r->budget / 1048576.0);
    }
    vxl_brick_store store;
    uint8_t *owned = NULL;
    float *scratch = malloc(vxl_bspline_scratch_floats(pg) * sizeof *scratch), *brick = malloc((size_t)e * e * e * sizeof *brick);
    float *entries = malloc(n * 4 * sizeof *entries);
    int rc = !scratch || !brick || !entries ? vxl_fail(&r->err, VXL_ERR_NO_MEMORY, "out of memory for the coefficient bricks")
                                            : vxl_paged_brick_store(r, &store, &owned);
    vxl_gl *gl = &r->gl;
    if (!rc) {
        gl->GetError();
        r->bspline_tex = vxl_texture_new(r, GL_TEXTURE_3D, GL_LINEAR);
        for (int a = 0; a < 3; a++) r->cpool_dims[a] = slots[a] * e;
        gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)r->cpool_dims[0], (GLsizei)r->cpool_dims[1],
                       (GLsizei)r->cpool_dims[2], 0, GL_RED, GL_FLOAT, NULL);
        uint32_t k = 0;
        for (uint64_t i = 0; i < n; i++) {
            float *pe = entries + 4 * i;
            if (!want[i]) { /* one constant coefficient (flat around), or never read */
                pe[0] = pe[1] = pe[2] = 0;
                pe[3] = pg->low[i];
                continue;
            }
            const uint32_t o[3] = {k % slots[0] * e, k / slots[0] % slots[1] * e, k / (slots[0] * slots[1]) * e};
            vxl_bspline_brick(pg, &store, r->level_dims[r->level], i, scratch, brick);
            gl->TexSubImage3D(GL_TEXTURE_3D, 0, (GLint)o[0], (GLint)o[1], (GLint)o[2], (GLsizei)e, (GLsizei)e,
                              (GLsizei)e, GL_RED, GL_FLOAT, brick);
            for (int a = 0; a < 3; a++) pe[a] = (float)(o[a] + VXL_PAGE_GHOST);
            pe[3] = -1;
            k++;
        }
        if (!r->cpage_tex) r->cpage_tex = vxl_texture_new(r, GL_TEXTURE_3D, GL_NEAREST);
        gl->BindTexture(GL_TEXTURE_3D, r->cpage_tex);
        gl->TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA32F, (GLsizei)pg->grid[0], (GLsizei)pg->grid[1], (GLsizei)pg->grid[2],
                       0, GL_RGBA, GL_FLOAT, entries);
        rc = vxl_gl_check(r, "uploading cubic B-spline coefficient bricks");
    }
    free(owned);
    free(scratch);
    free(brick);
    free(entries);
    if (rc) {
        free(want);
        vxl_bspline_release(r);
        return rc;
    }
    r->bspline_covered = want;
    r->bspline_level = r->level;
    r->bspline_bytes = bytes;
    return VXL_OK;
}
