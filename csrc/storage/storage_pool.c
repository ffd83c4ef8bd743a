/* storage_pool.c - what every pool of bricks shares, whichever storage mode
 * or derived volume fills it: the slot layout within the texture limit, the
 * page-table upload, the dispatch of a per-brick compute pass, the current
 * level's bricks on the CPU, and which bricks a pool derived from the data
 * must hold; and the filter check of the modes that serve every filter.
 * Storage and the derived volumes (gradients, coefficients) call it; it
 * calls neither. */
#include <stdlib.h>
#include <string.h>

#include "storage.h"


/* Slots per axis for n bricks of edge e within the texture limit; 0 if they cannot fit. */
int vxl_pool_layout(const vxl_storage_state *st, uint32_t n, uint32_t e, uint32_t slots[3])
{
    const uint32_t m = (uint32_t)st->gpu->info.max_3d_texture_size / e;
    if (m == 0) return 0;
    n = n ? n : 1;
    slots[0] = n < m ? n : m;
    uint32_t rows = (n + slots[0] - 1) / slots[0];
    slots[1] = rows < m ? rows : m;
    slots[2] = (rows + slots[1] - 1) / slots[1];
    /* the fewest slots per row and rows per layer that still hold n: the
     * last row and layer are then nearly full (128 bricks of 34 under a
     * limit of 2048 take 43 x 3 slots, not 60 x 3, which left 52 empty) */
    slots[1] = (rows + slots[2] - 1) / slots[2];
    slots[0] = (n + slots[1] * slots[2] - 1) / (slots[1] * slots[2]);
    return slots[2] <= m;
}

void vxl_page_table_upload(vxl_storage_state *st, GLuint *tex, const vxl_pages *pg, const float *entries)
{
    vxl_gl *gl = &st->gpu->gl;
    if (!*tex) *tex = vxl_texture_new(st->gpu, GL_TEXTURE_3D, GL_NEAREST);
    gl->BindTexture(GL_TEXTURE_3D, *tex);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA32F, (GLsizei)pg->grid[0], (GLsizei)pg->grid[1], (GLsizei)pg->grid[2], 0,
                   GL_RGBA, GL_FLOAT, entries);
}

static GLuint groups(uint32_t n) { return (n + 3) / 4; }

void vxl_dispatch_bricks(vxl_storage_state *st, GLuint prog, uint32_t first, uint32_t count, uint32_t e)
{
    const uint32_t per = 65535u * 4u / e; /* bricks per dispatch: z groups <= 65535 */
    for (uint32_t k = first; k < first + count; k += per) {
        uint32_t n = first + count - k < per ? first + count - k : per;
        vxl_uniform_i(st->gpu, prog, "u_first", (int)k);
        st->gpu->gl.DispatchCompute(groups(e), groups(e), groups(n * e));
    }
}

int vxl_paged_brick_store(vxl_storage_state *st, vxl_brick_store *s, uint8_t **owned)
{
    const vxl_pages *pg = &st->levels[st->level];
    *owned = NULL;
    if (pg->data || !pg->n_data) { /* no data bricks: every brick is its constant */
        *s = vxl_pages_store(pg);
        return VXL_OK;
    }
    /* bricked storage dropped its CPU bricks at upload: every data brick is
     * in the pool, slot = data index, so the pool read back is the store */
    if (st->mode != VXL_STORAGE_BRICKED || st->level != 0)
        return vxl_fail(&st->gpu->err, VXL_ERR_STATE, "the bricks' values are not kept on the CPU for %s storage",
                        vxl_storage_name(st->mode));
    static const GLenum types[] = {GL_UNSIGNED_BYTE, GL_UNSIGNED_SHORT, 0, GL_FLOAT};
    const uint64_t bytes = (uint64_t)st->pool_dims[0] * st->pool_dims[1] * st->pool_dims[2] * pg->bytes_per_voxel;
    uint8_t *buf = malloc(bytes ? bytes : 1);
    if (!buf) return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory reading back %.1f MiB of bricks", bytes / 1048576.0);
    vxl_gl *gl = &st->gpu->gl;
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, st->pool_tex);
    gl->GetTexImage(GL_TEXTURE_3D, 0, GL_RED, types[pg->bytes_per_voxel - 1], buf);
    int rc = vxl_gl_check(st->gpu, "reading back the brick pool");
    if (rc) {
        free(buf);
        return rc;
    }
    const uint32_t e = vxl_page_edge(pg);
    *s = (vxl_brick_store){buf, {st->pool_dims[0] / e, st->pool_dims[1] / e}, e, pg->bytes_per_voxel};
    *owned = buf;
    return VXL_OK;
}

uint32_t vxl_paged_derived_want(const vxl_storage_state *st, uint32_t level, uint32_t support, uint32_t read_reach,
                                uint8_t *want)
{
    const vxl_pages *pg = &st->levels[level];
    const uint64_t n = vxl_page_count(pg);
    for (uint64_t i = 0; i < n; i++) want[i] = !vxl_pages_flat_around(pg, i, support);
    const uint32_t reach = st->visible_reach > read_reach ? st->visible_reach : read_reach;
    return vxl_pages_needed(pg, st->grid, reach, 1u << level, st->visible_all, want, want);
}

int vxl_paged_derived_current(const vxl_storage_state *st, const uint8_t *covered, uint32_t level, const uint8_t *want)
{
    if (!covered || level != st->level) return 0;
    const uint64_t n = vxl_page_count(&st->levels[st->level]);
    for (uint64_t i = 0; i < n; i++)
        if (want[i] && !covered[i]) return 0;
    return 1;
}

int vxl_storage_serves_all(vxl_storage_state *st, uint32_t filter, uint32_t classify)
{
    (void)st;
    (void)filter;
    (void)classify;
    return VXL_OK;
}
