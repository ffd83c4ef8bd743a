/* paged_gradients.c - the precomputed gradient filter with bricked and sparse
 * storage: the same blur + Sobel + global-max scaling as precompute.c,
 * computed per brick into a gradient pool with its own page table (shaders/
 * gradients.comp with PAGED). A brick needs gradient data unless every voxel
 * within 2 of it holds one value (then its gradient is exactly zero: the
 * blur and the Sobel reach 2 voxels), and, sparse, only when a visible
 * sample can read it. The maximum that scales the stored gradients is the
 * whole volume's, as with one texture, found on the CPU from the bricks'
 * values (bspline_bricks.c). */
#include <stdlib.h>
#include <string.h>

#include "bspline_bricks.h"
#include "gradients.h"

static const GLenum store_internal[] = {GL_RGBA8_SNORM, GL_RGBA16F, GL_RGBA32F};
static const uint32_t store_bytes[] = {4, 8, 16};

/* Bricks blurred at once: their blurred copies (R32F, edge P+4) within 64
 * MiB, or a sixteenth of the budget when that is less. */
static uint32_t blur_chunk(const vxl_gradient_state *gr, uint32_t eb, uint32_t count)
{
    const uint64_t bytes = gr->gpu->budget / 16 < (64u << 20) ? gr->gpu->budget / 16 : (64u << 20);
    uint32_t chunk = (uint32_t)(bytes / ((uint64_t)eb * eb * eb * 4));
    chunk = chunk ? chunk : 1;
    return count && count < chunk ? count : chunk;
}

uint64_t vxl_paged_gradient_bytes(const vxl_gradient_state *gr, uint32_t level, int store, uint8_t *want, uint32_t *count_out)
{
    const vxl_pages *pg = &gr->storage->levels[level];
    const uint32_t count = vxl_paged_derived_want(gr->storage, level, VXL_GRADIENT_SUPPORT, VXL_GRADIENT_READ_REACH, want);
    const uint64_t eb = pg->brick + 4, eg = pg->brick + 2;
    uint32_t bslots[3], gslots[3];
    if (count_out) *count_out = count;
    if (!vxl_pool_layout(gr->storage, blur_chunk(gr, (uint32_t)eb, count), (uint32_t)eb, bslots) ||
        !vxl_pool_layout(gr->storage, count, (uint32_t)eg, gslots))
        return UINT64_MAX;
    /* the gradient pool, its page table and one chunk of blurred bricks */
    return (uint64_t)gslots[0] * gslots[1] * gslots[2] * eg * eg * eg * store_bytes[store] + vxl_page_count(pg) * 16 +
           (uint64_t)bslots[0] * bslots[1] * bslots[2] * eb * eb * eb * 4;
}

/* The wanted bricks as (x, y, z, 0) each, in slot order. */
static GLint *brick_list(const vxl_pages *pg, const uint8_t *want, uint32_t count)
{
    GLint *out = malloc((count ? count : 1) * 4 * sizeof *out);
    if (!out) return NULL;
    GLint *o = out;
    for (uint64_t i = 0; i < vxl_page_count(pg); i++) {
        if (!want[i]) continue;
        o[0] = (GLint)(i % pg->grid[0]);
        o[1] = (GLint)(i / pg->grid[0] % pg->grid[1]);
        o[2] = (GLint)(i / ((uint64_t)pg->grid[0] * pg->grid[1]));
        o[3] = 0;
        o += 4;
    }
    return out;
}

/* The whole level's largest |gradient|, from the CPU bricks; kept per level. */
static int cpu_gradient_max(vxl_gradient_state *gr, float *out)
{
    if (gr->max_level[gr->storage->level] >= 0) {
        *out = gr->max_level[gr->storage->level];
        return VXL_OK;
    }
    vxl_brick_store s;
    uint8_t *owned;
    int rc = vxl_paged_brick_store(gr->storage, &s, &owned);
    if (rc) return rc;
    float m = vxl_pages_gradient_max(&gr->storage->levels[gr->storage->level], &s, gr->storage->level_dims[gr->storage->level]);
    free(owned);
    if (m < 0) return vxl_fail(&gr->gpu->err, VXL_ERR_NO_MEMORY, "out of memory finding the largest gradient");
    *out = gr->max_level[gr->storage->level] = m;
    return VXL_OK;
}

static void set_common(vxl_gradient_state *gr, GLuint prog, uint32_t count, const uint32_t slots[3])
{
    vxl_gl *gl = &gr->gpu->gl;
    gl->UseProgram(prog);
    const uint32_t *ld = gr->storage->level_dims[gr->storage->level];
    vxl_uniform_i(gr->gpu, prog, "u_brick", (int)gr->storage->levels[gr->storage->level].brick);
    vxl_uniform_f(gr->gpu, prog, "u_page_brick", (float)gr->storage->levels[gr->storage->level].brick);
    vxl_uniform_i(gr->gpu, prog, "u_count", (int)count);
    float dims[3] = {(float)ld[0], (float)ld[1], (float)ld[2]};
    gl->Uniform3fv(gl->GetUniformLocation(prog, "u_dims"), 1, dims);
    gl->Uniform3i(gl->GetUniformLocation(prog, "u_slots"), (GLint)slots[0], (GLint)slots[1], (GLint)slots[2]);
}

int vxl_paged_gradients_ensure(vxl_gradient_state *gr, int store, void (*make_room)(void *room), void *room)
{
    const vxl_pages *pg = &gr->storage->levels[gr->storage->level];
    const uint64_t n = vxl_page_count(pg);
    uint8_t *want = malloc(n);
    if (!want) return vxl_fail(&gr->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the gradient bricks");
    uint32_t count;
    const uint64_t all_bytes = vxl_paged_gradient_bytes(gr, gr->storage->level, store, want, &count);
    if (gr->tex && gr->store == store &&
        vxl_paged_derived_current(gr->storage, gr->covered, gr->level, want)) {
        free(want);
        return VXL_OK;
    }
    vxl_gradients_release(gr);
    if (make_room) make_room(room);
    vxl_gl *gl = &gr->gpu->gl;
    const uint32_t pb = pg->brick, eb = pb + 4, eg = pb + 2;
    uint32_t bslots[3], gslots[3];
    GLint *list = brick_list(pg, want, count);
    if (!list) {
        free(want);
        return vxl_fail(&gr->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the gradient bricks");
    }
    /* the whole volume's maximum, from the CPU bricks (sparse keeps them,
     * bricked reads its pool back): a separable CPU blur and Sobel beat the
     * same 27-tap passes through the page table on the GL side, and sparse
     * storage has only the visible bricks there */
    float max_mag = 0;
    int rc = cpu_gradient_max(gr, &max_mag);
    if (rc) {
        free(list);
        free(want);
        return rc;
    }
    const uint32_t chunk = blur_chunk(gr, eb, count);
    if (all_bytes == UINT64_MAX || !vxl_pool_layout(gr->storage, chunk, eb, bslots) || !vxl_pool_layout(gr->storage, count, eg, gslots)) {
        free(list);
        free(want);
        return vxl_fail(&gr->gpu->err, VXL_ERR_LIMIT, "%u gradient bricks do not fit a pool within the 3D texture limit of %d",
                        count, gr->gpu->info.max_3d_texture_size);
    }
    const uint64_t gbytes = (uint64_t)gslots[0] * gslots[1] * gslots[2] * eg * eg * eg * store_bytes[store],
                   need = all_bytes;
    GLuint progs[3];
    rc = vxl_gradient_programs(gr, 1, store, need, progs);
    if (rc) {
        free(list);
        free(want);
        return rc;
    }
    const GLuint blur_prog = progs[0], store_prog = progs[2];
    gl->GetError();
    gl->BindBuffer(GL_SHADER_STORAGE_BUFFER, gr->gpu->ssbo[1]);
    gl->BufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(count ? count : 1) * 4 * (GLsizeiptr)sizeof(GLint), list,
                   GL_STATIC_DRAW);
    gl->BindBufferBase(GL_SHADER_STORAGE_BUFFER, VXL_SSBO_BRICK_LIST, gr->gpu->ssbo[1]);
    /* The bricks go through in chunks whose blurred copies fit one small
     * texture: the blurred copy of every brick at once would double the
     * memory. Pass 1 blurs a chunk, pass 2 stores its scaled gradients. */
    GLuint blur = vxl_texture_new(gr->gpu, GL_TEXTURE_3D, GL_NEAREST);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)(bslots[0] * eb), (GLsizei)(bslots[1] * eb),
                   (GLsizei)(bslots[2] * eb), 0, GL_RED, GL_FLOAT, NULL);
    gr->tex = vxl_texture_new(gr->gpu, GL_TEXTURE_3D, GL_LINEAR);
    for (int a = 0; a < 3; a++) gr->pool_dims[a] = gslots[a] * eg;
    gl->TexImage3D(GL_TEXTURE_3D, 0, (GLint)store_internal[store], (GLsizei)gr->pool_dims[0], (GLsizei)gr->pool_dims[1],
                   (GLsizei)gr->pool_dims[2], 0, GL_RGBA, GL_FLOAT, NULL);
    for (uint32_t first = 0; first < count; first += chunk) {
        const uint32_t n_chunk = count - first < chunk ? count - first : chunk;
        /* pass 1: blur the chunk's bricks plus a 2-voxel border, through the data pool */
        set_common(gr, blur_prog, first + n_chunk, bslots); /* u_count: this chunk ends the list */
        vxl_uniform_i(gr->gpu, blur_prog, "u_blur_first", (int)first);
        gl->ActiveTexture(GL_TEXTURE0 + VXL_PAGE_UNIT);
        gl->BindTexture(GL_TEXTURE_3D, gr->storage->page_tex);
        gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
        gl->BindTexture(GL_TEXTURE_3D, gr->storage->pool_tex);
        vxl_uniform_i(gr->gpu, blur_prog, "u_volume", VXL_VOLUME_UNIT);
        vxl_uniform_i(gr->gpu, blur_prog, "u_page", VXL_PAGE_UNIT);
        gl->BindImageTexture(VXL_IMAGE_OUT, blur, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
        vxl_dispatch_bricks(gr->storage, blur_prog, first, n_chunk, eb);
        gl->MemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        /* pass 2: the Sobel of the blurred chunk, divided by the maximum, into the gradient pool */
        set_common(gr, store_prog, first + n_chunk, gslots);
        vxl_uniform_i(gr->gpu, store_prog, "u_blur_first", (int)first);
        gl->Uniform3i(gl->GetUniformLocation(store_prog, "u_blur_slots"), (GLint)bslots[0], (GLint)bslots[1],
                      (GLint)bslots[2]);
        gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
        gl->BindTexture(GL_TEXTURE_3D, blur);
        vxl_uniform_i(gr->gpu, store_prog, "u_blur", VXL_VOLUME_UNIT);
        vxl_uniform_f(gr->gpu, store_prog, "u_inv_max", max_mag > 0 ? 1.0f / max_mag : 0.0f);
        gl->BindImageTexture(VXL_IMAGE_OUT, gr->tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, store_internal[store]);
        vxl_dispatch_bricks(gr->storage, store_prog, first, n_chunk, eg);
        gl->MemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    }
    gr->max = max_mag; /* the shader scales back to value per voxel */
    gl->DeleteTextures(1, &blur);
    /* the gradient page table: slot origins + ghost, or zero gradient */
    float *entries = calloc(n * 4, sizeof *entries);
    if (!entries) rc = vxl_fail(&gr->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the gradient page table");
    for (uint64_t i = 0; i < n && entries; i++) entries[4 * i + 3] = 0; /* zero gradient */
    for (uint32_t k = 0; k < count && entries; k++) {
        const GLint *c = list + 4 * (size_t)k;
        float *e = entries + 4 * ((size_t)c[0] + pg->grid[0] * ((size_t)c[1] + (size_t)pg->grid[1] * c[2]));
        uint32_t o[3];
        vxl_slot_origin(k, gslots, eg, o);
        for (int a = 0; a < 3; a++) e[a] = (float)(o[a] + 1);
        e[3] = -1;
    }
    if (entries) vxl_page_table_upload(gr->storage, &gr->page_tex, pg, entries);
    free(entries);
    free(list);
    gl->UseProgram(0);
    if (!rc) rc = vxl_gl_check(gr->gpu, "precomputing gradients of the bricked volume");
    if (rc) {
        free(want);
        vxl_gradients_release(gr);
        return rc;
    }
    gr->covered = want;
    gr->level = gr->storage->level;
    gr->store = store;
    gr->bytes = gbytes + n * 16;
    return VXL_OK;
}
