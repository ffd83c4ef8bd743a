/* paged_bspline.c - the cubic filter with bricked and sparse storage: B-spline
 * coefficients brick by brick (bspline_bricks.c, on the CPU from the bricks'
 * values) in a coefficient pool with a one-voxel ghost and its own page
 * table, laid out like the data (shaders/lib/gradients.glsl, coeff()). Only the
 * bricks a frame can read are made: those within the cubic footprint of a
 * visible sample whose coefficients are not one constant. */
#include <stdlib.h>
#include <string.h>

#include "bspline_bricks.h"
#include "gradients.h"
#include "holdings.h"

/* The cubic footprint: coefficients at floor(p) - 1 .. floor(p) + 2. A
 * brick's coefficients are one constant when everything within the margin
 * and the ghost is. */
#define CUBIC_READ_REACH 3
#define CUBIC_SUPPORT (VXL_BSPLINE_MARGIN + VXL_PAGE_GHOST)

uint64_t vxl_paged_bspline_bytes(const vxl_bspline_state *bs, uint32_t level, uint8_t *want, uint32_t *count_out)
{
    const vxl_pages *pg = &bs->storage->levels[level];
    const uint32_t count = vxl_paged_derived_want(bs->storage, level, CUBIC_SUPPORT, CUBIC_READ_REACH, want), e = vxl_page_edge(pg);
    uint32_t slots[3];
    if (count_out) *count_out = count;
    if (!vxl_pool_layout(bs->storage, count, e, slots)) return UINT64_MAX;
    return (uint64_t)slots[0] * slots[1] * slots[2] * e * e * e * 4 + vxl_page_count(pg) * 16;
}

int vxl_paged_bspline_ensure(vxl_bspline_state *bs, void (*make_room)(void *room), void *room)
{
    const vxl_pages *pg = &bs->storage->levels[bs->storage->level];
    const uint64_t n = vxl_page_count(pg);
    uint8_t *want = malloc(n);
    if (!want) return vxl_fail(&bs->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the coefficient page table");
    uint32_t count;
    const uint64_t bytes = vxl_paged_bspline_bytes(bs, bs->storage->level, want, &count);
    if (bs->tex && vxl_paged_derived_current(bs->storage, bs->covered, bs->level, want)) {
        free(want);
        return VXL_OK;
    }
    vxl_bspline_release(bs);
    if (make_room) make_room(room);
    const uint32_t e = vxl_page_edge(pg);
    uint32_t slots[3];
    if (bytes == UINT64_MAX || !vxl_pool_layout(bs->storage, count, e, slots)) {
        free(want);
        return vxl_fail(&bs->gpu->err, VXL_ERR_LIMIT, "%u coefficient bricks do not fit a pool within the 3D texture limit of %d",
                        count, bs->gpu->info.max_3d_texture_size);
    }
    if (vxl_holdings_ask(bs->gpu, VXL_HOLD_BSPLINE, bytes, NULL, "cubic B-spline coefficients of %u bricks", count)) {
        free(want);
        return VXL_ERR_LIMIT;
    }
    vxl_brick_store store;
    uint8_t *owned = NULL;
    float *scratch = malloc(vxl_bspline_scratch_floats(pg) * sizeof *scratch), *brick = malloc((size_t)e * e * e * sizeof *brick);
    float *entries = malloc(n * 4 * sizeof *entries);
    int rc = !scratch || !brick || !entries ? vxl_fail(&bs->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the coefficient bricks")
                                            : vxl_paged_brick_store(bs->storage, &store, &owned);
    vxl_gl *gl = &bs->gpu->gl;
    if (!rc) {
        gl->GetError();
        bs->tex = vxl_texture_new(bs->gpu, GL_TEXTURE_3D, GL_LINEAR);
        for (int a = 0; a < 3; a++) bs->pool_dims[a] = slots[a] * e;
        gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)bs->pool_dims[0], (GLsizei)bs->pool_dims[1],
                       (GLsizei)bs->pool_dims[2], 0, GL_RED, GL_FLOAT, NULL);
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
            vxl_bspline_brick(pg, &store, bs->storage->level_dims[bs->storage->level], i, scratch, brick);
            gl->TexSubImage3D(GL_TEXTURE_3D, 0, (GLint)o[0], (GLint)o[1], (GLint)o[2], (GLsizei)e, (GLsizei)e,
                              (GLsizei)e, GL_RED, GL_FLOAT, brick);
            for (int a = 0; a < 3; a++) pe[a] = (float)(o[a] + VXL_PAGE_GHOST);
            pe[3] = -1;
            k++;
        }
        vxl_page_table_upload(bs->storage, &bs->page_tex, pg, entries);
        rc = vxl_gl_check(bs->gpu, "uploading cubic B-spline coefficient bricks");
    }
    free(owned);
    free(scratch);
    free(brick);
    free(entries);
    if (rc) {
        free(want);
        vxl_bspline_release(bs);
        return rc;
    }
    bs->covered = want;
    bs->level = bs->storage->level;
    bs->bytes = bytes;
    return VXL_OK;
}
