/* paged_bspline.c - the cubic filter with bricked and sparse storage: B-spline
 * coefficients brick by brick (bspline_bricks.c, on the CPU from the bricks'
 * values) in a coefficient pool with a one-voxel ghost and its own page
 * table, laid out like the data (shaders/lib/gradients.glsl, coeff()). Only the
 * bricks a frame can read are made: those within the cubic footprint of a
 * visible sample whose coefficients are not one constant. */
#include <stdlib.h>
#include <string.h>

#include "bspline_bricks.h"
#include "holdings.h"
#include "renderer_internal.h"

/* The cubic footprint: coefficients at floor(p) - 1 .. floor(p) + 2. A
 * brick's coefficients are one constant when everything within the margin
 * and the ghost is. */
#define CUBIC_READ_REACH 3
#define CUBIC_SUPPORT (VXL_BSPLINE_MARGIN + VXL_PAGE_GHOST)

uint64_t vxl_paged_bspline_bytes(const vxl_renderer *r, uint32_t level, uint8_t *want, uint32_t *count_out)
{
    const vxl_pages *pg = &r->storage.levels[level];
    const uint32_t count = vxl_paged_derived_want(r, level, CUBIC_SUPPORT, CUBIC_READ_REACH, want), e = vxl_page_edge(pg);
    uint32_t slots[3];
    if (count_out) *count_out = count;
    if (!vxl_pool_layout(r, count, e, slots)) return UINT64_MAX;
    return (uint64_t)slots[0] * slots[1] * slots[2] * e * e * e * 4 + vxl_page_count(pg) * 16;
}

int vxl_paged_bspline_ensure(vxl_renderer *r, void (*make_room)(vxl_renderer *r))
{
    const vxl_pages *pg = &r->storage.levels[r->storage.level];
    const uint64_t n = vxl_page_count(pg);
    uint8_t *want = malloc(n);
    if (!want) return vxl_fail(&r->err, VXL_ERR_NO_MEMORY, "out of memory for the coefficient page table");
    uint32_t count;
    const uint64_t bytes = vxl_paged_bspline_bytes(r, r->storage.level, want, &count);
    if (r->bspline.tex && vxl_paged_derived_current(r, r->bspline.covered, r->bspline.level, want)) {
        free(want);
        return VXL_OK;
    }
    vxl_bspline_release(r);
    if (make_room) make_room(r);
    const uint32_t e = vxl_page_edge(pg);
    uint32_t slots[3];
    if (bytes == UINT64_MAX || !vxl_pool_layout(r, count, e, slots)) {
        free(want);
        return vxl_fail(&r->err, VXL_ERR_LIMIT, "%u coefficient bricks do not fit a pool within the 3D texture limit of %d",
                        count, r->info.max_3d_texture_size);
    }
    if (vxl_holdings_ask(r, VXL_HOLD_BSPLINE, bytes, NULL, "cubic B-spline coefficients of %u bricks", count)) {
        free(want);
        return VXL_ERR_LIMIT;
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
        r->bspline.tex = vxl_texture_new(r, GL_TEXTURE_3D, GL_LINEAR);
        for (int a = 0; a < 3; a++) r->bspline.pool_dims[a] = slots[a] * e;
        gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)r->bspline.pool_dims[0], (GLsizei)r->bspline.pool_dims[1],
                       (GLsizei)r->bspline.pool_dims[2], 0, GL_RED, GL_FLOAT, NULL);
        uint32_t k = 0;
        for (uint64_t i = 0; i < n; i++) {
            float *pe = entries + 4 * i;
            if (!want[i]) { /* one constant coefficient (flat around), or never read */
                pe[0] = pe[1] = pe[2] = 0;
                pe[3] = pg->low[i];
                continue;
            }
            uint32_t o[3];
            vxl_slot_origin(k, slots, e, o);
            vxl_bspline_brick(pg, &store, r->storage.level_dims[r->storage.level], i, scratch, brick);
            gl->TexSubImage3D(GL_TEXTURE_3D, 0, (GLint)o[0], (GLint)o[1], (GLint)o[2], (GLsizei)e, (GLsizei)e,
                              (GLsizei)e, GL_RED, GL_FLOAT, brick);
            for (int a = 0; a < 3; a++) pe[a] = (float)(o[a] + VXL_PAGE_GHOST);
            pe[3] = -1;
            k++;
        }
        vxl_page_table_upload(r, &r->bspline.page_tex, pg, entries);
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
    r->bspline.covered = want;
    r->bspline.level = r->storage.level;
    r->bspline.bytes = bytes;
    return VXL_OK;
}
