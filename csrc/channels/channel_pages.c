/* channel_pages.c - a multi-channel volume's groups cut into the storage's
 * page bricks, one pool per group behind one page table (channel_pages.h). */
#include "channel_pages.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "channel_volume.h"
#include "hash.h"

void vxl_channel_pages_free(vxl_channel_pages *cp)
{
    vxl_pages_free(&cp->layout);
    free(cp->constants);
    free(cp->varies);
    free(cp->low);
    memset(cp, 0, sizeof *cp);
}

/* Per brick, whether any channel varies over it (ghost included), and each
 * channel's constant code: every channel cut on its own by vxl_pages_build,
 * the one definition of a constant brick the scalar's pages use too. */
static int find_constants(const vxl_pages *layout, const vxl_volume *v, uint8_t *varies, uint16_t *codes, vxl_err *e)
{
    const uint64_t n = vxl_page_count(layout);
    const uint32_t nc = v->channel_count;
    memset(varies, 0, n);
    for (uint32_t c = 0; c < nc; c++) {
        vxl_volume one;
        vxl_pages pc;
        int rc = vxl_channel_alone(v, c, &one, e);
        if (!rc) rc = vxl_pages_build(&pc, &one, layout->brick, e);
        free(one.texels);
        if (rc) return rc;
        for (uint64_t i = 0; i < n; i++) {
            varies[i] |= pc.data_index[i] >= 0;
            /* low is code / 65535 rounded to float once: 24 bits give the code back exactly */
            codes[i * nc + c] = (uint16_t)lrint(pc.low[i] * 65535.0);
        }
        vxl_pages_free(&pc);
    }
    return VXL_OK;
}

/* Slots: the bricks marked in own[] first, in brick order, then one per
 * distinct tuple of the others' minima (an open-addressed table of the
 * first brick of each): a constant brick's minima are its constants. */
static int assign_slots(vxl_channel_pages *cp, uint32_t nc, const uint8_t *own, vxl_err *e)
{
    const uint64_t n = vxl_page_count(&cp->layout);
    const uint16_t *codes = cp->low;
    int32_t *slot = cp->layout.data_index;
    uint32_t varying = 0, distinct = 0;
    free(cp->constants);
    for (uint64_t i = 0; i < n; i++)
        if (own[i]) slot[i] = (int32_t)varying++;
    uint64_t cap = 16;
    while (cap < 2 * (n - varying)) cap *= 2;
    int64_t *first = malloc(cap * sizeof *first);
    cp->constants = malloc((n - varying + 1) * nc * sizeof *cp->constants);
    if (!first || !cp->constants) {
        free(first);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the channels' page table");
    }
    for (uint64_t k = 0; k < cap; k++) first[k] = -1;
    const size_t tuple = nc * sizeof *codes;
    for (uint64_t i = 0; i < n; i++) {
        if (own[i]) continue;
        const uint16_t *t = codes + i * nc;
        uint64_t h = vxl_fnv(0xcbf29ce484222325ull, t, tuple) & (cap - 1);
        while (first[h] >= 0 && memcmp(codes + (uint64_t)first[h] * nc, t, tuple)) h = (h + 1) & (cap - 1);
        if (first[h] >= 0) {
            slot[i] = slot[first[h]];
            continue;
        }
        first[h] = (int64_t)i;
        memcpy(cp->constants + (size_t)distinct * nc, t, tuple);
        slot[i] = (int32_t)(varying + distinct++);
    }
    free(first);
    cp->varying = varying;
    cp->layout.n_data = varying + distinct;
    return VXL_OK;
}

/* Slots for the bricks marked in own[] and the shared constant slots, laid
 * out within st's texture limit, and their bytes. */
static int lay_out(vxl_channel_pages *cp, uint32_t nc, const uint8_t *own, const vxl_storage_state *st)
{
    vxl_err *e = &st->gpu->err;
    const vxl_pages *pg = &cp->layout;
    int rc = assign_slots(cp, nc, own, e);
    const uint64_t edge = vxl_page_edge(pg);
    if (!rc && !vxl_pool_layout(st, pg->n_data, (uint32_t)edge, cp->slots))
        rc = vxl_fail(e, VXL_ERR_LIMIT,
                      "the channels' %u bricks of %u^3 voxels do not fit a pool texture within the 3D texture "
                      "limit of %d",
                      pg->n_data, (uint32_t)edge, st->gpu->info.max_3d_texture_size);
    if (rc) return rc;
    const uint64_t texels = (uint64_t)cp->slots[0] * cp->slots[1] * cp->slots[2] * edge * edge * edge;
    cp->bytes = texels * nc * VXL_CHANNEL_BYTES + vxl_page_count(pg) * 4 * sizeof(float);
    return VXL_OK;
}

int vxl_channel_pages_plan(vxl_channel_pages *cp, const vxl_volume *v, uint32_t brick, int sparse,
                           const vxl_storage_state *st)
{
    vxl_err *e = &st->gpu->err;
    memset(cp, 0, sizeof *cp);
    vxl_pages *pg = &cp->layout;
    pg->brick = brick;
    pg->bytes_per_voxel = VXL_CHANNEL_BYTES;
    for (int a = 0; a < 3; a++) pg->grid[a] = (v->dims[a] + brick - 1) / brick;
    const uint64_t n = vxl_page_count(pg);
    const uint32_t nc = v->channel_count;
    pg->data_index = malloc(n * sizeof *pg->data_index);
    cp->varies = malloc(n);
    cp->low = malloc(n * nc * sizeof *cp->low);
    uint8_t *none = calloc(n, 1);
    int rc = VXL_OK;
    if (!pg->data_index || !cp->varies || !cp->low || !none)
        rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the channels' page table");
    if (!rc) rc = find_constants(pg, v, cp->varies, cp->low, e);
    /* sparse: nothing of its own until a frame says what it can see */
    if (!rc) rc = lay_out(cp, nc, sparse ? none : cp->varies, st);
    free(none);
    if (rc) vxl_channel_pages_free(cp);
    return rc;
}

int vxl_channel_pages_resident(vxl_channel_pages *cp, uint32_t channels, const uint8_t *need,
                               const vxl_storage_state *st, int force, int *changed)
{
    const uint64_t n = vxl_page_count(&cp->layout);
    *changed = force;
    for (uint64_t i = 0; i < n && !*changed; i++)
        *changed = need[i] && cp->layout.data_index[i] >= (int32_t)cp->varying;
    return *changed ? lay_out(cp, channels, need, st) : VXL_OK;
}

/* Writes one brick of w channels into slot k of the pool bound on the scratch unit. */
static void put_slot(vxl_gl *gl, const vxl_channel_pages *cp, uint32_t k, uint32_t w, const uint16_t *texels)
{
    const uint32_t e = vxl_page_edge(&cp->layout);
    uint32_t o[3];
    vxl_slot_origin(k, cp->slots, e, o);
    gl->TexSubImage3D(GL_TEXTURE_3D, 0, (GLint)o[0], (GLint)o[1], (GLint)o[2], (GLsizei)e, (GLsizei)e, (GLsizei)e,
                      vxl_channel_group_layout(w), GL_UNSIGNED_SHORT, texels);
}

/* Group grp's pool: every varying brick copied from the group's texels with
 * its ghost, every constant slot filled with its codes. */
static void fill_pool(const vxl_channel_pages *cp, const vxl_volume *v, vxl_gl *gl, uint32_t grp, uint16_t *scratch)
{
    const vxl_pages *pg = &cp->layout;
    const uint32_t w = vxl_channel_group_width(v, grp), e = vxl_page_edge(pg);
    const uint64_t n = vxl_page_count(pg);
    for (uint64_t i = 0; i < n; i++) {
        if (pg->data_index[i] >= (int32_t)cp->varying) continue;
        const uint32_t b[3] = {(uint32_t)(i % pg->grid[0]), (uint32_t)(i / pg->grid[0] % pg->grid[1]),
                               (uint32_t)(i / ((uint64_t)pg->grid[0] * pg->grid[1]))};
        vxl_pages_copy_brick(vxl_channel_group(v, grp), v->dims, w * VXL_CHANNEL_BYTES, pg->brick, b,
                             (uint8_t *)scratch);
        put_slot(gl, cp, (uint32_t)pg->data_index[i], w, scratch);
    }
    const size_t voxels = (size_t)e * e * e;
    for (uint32_t k = cp->varying; k < pg->n_data; k++) {
        const uint16_t *t = cp->constants + (size_t)(k - cp->varying) * v->channel_count + grp * VXL_CHANNELS_PER_GROUP;
        for (size_t j = 0; j < voxels; j++) memcpy(scratch + j * w, t, w * sizeof *t);
        put_slot(gl, cp, k, w, scratch);
    }
}

int vxl_channel_pages_upload(const vxl_channel_pages *cp, const vxl_volume *v, vxl_storage_state *st, GLuint *pools,
                             GLuint *page_tex)
{
    vxl_gpu *g = st->gpu;
    vxl_gl *gl = &g->gl;
    const vxl_pages *pg = &cp->layout;
    const uint32_t e = vxl_page_edge(pg);
    const uint64_t n = vxl_page_count(pg);
    uint16_t *scratch = malloc((size_t)e * e * e * VXL_CHANNELS_PER_GROUP * sizeof *scratch);
    float *entries = malloc(n * 4 * sizeof *entries);
    if (!scratch || !entries) {
        free(scratch);
        free(entries);
        return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the channels' pools");
    }
    gl->GetError();
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (uint32_t grp = 0; grp < vxl_channel_groups(v); grp++) {
        const uint32_t w = vxl_channel_group_width(v, grp);
        pools[grp] = vxl_texture_new(g, GL_TEXTURE_3D, GL_LINEAR); /* bound on the scratch unit */
        gl->TexImage3D(GL_TEXTURE_3D, 0, (GLint)vxl_channel_group_format(w), (GLsizei)(cp->slots[0] * e),
                       (GLsizei)(cp->slots[1] * e), (GLsizei)(cp->slots[2] * e), 0, vxl_channel_group_layout(w),
                       GL_UNSIGNED_SHORT, NULL);
        fill_pool(cp, v, gl, grp, scratch);
    }
    for (uint64_t i = 0; i < n; i++) { /* every brick resident: w -1, as the scalar's resident entries */
        uint32_t o[3];
        vxl_slot_origin((uint32_t)pg->data_index[i], cp->slots, e, o);
        for (int a = 0; a < 3; a++) entries[4 * i + (uint64_t)a] = (float)(o[a] + VXL_PAGE_GHOST);
        entries[4 * i + 3] = -1;
    }
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    vxl_page_table_upload(st, page_tex, pg, entries);
    free(scratch);
    free(entries);
    return vxl_gl_check(g, "uploading a multi-channel volume's channel pools");
}
