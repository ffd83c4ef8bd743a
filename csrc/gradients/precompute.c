/* precompute.c - the `precomputed` gradient filter's texture: a [1,2,1]^3 blur
 * then a 26-neighbour Sobel, computed on the GL side once per volume. It
 * stores the raw gradient divided by the global maximum magnitude, so that
 * interpolation happens before normalisation (see measured-facts.md). */
#include <stdlib.h>

#include "bspline_bricks.h"
#include "gradients.h"
#include "holdings.h"

static const GLenum store_internal[] = {GL_RGBA8_SNORM, GL_RGBA16F, GL_RGBA32F};
static const uint32_t store_bytes[] = {4, 8, 16};

void vxl_gradients_release(vxl_gradient_state *gr)
{
    const GLuint tex[2] = {gr->tex, gr->page_tex}; /* the volume or pool, and a pool's page table */
    gr->gpu->gl.DeleteTextures(2, tex); /* 0 is ignored */
    gr->tex = gr->page_tex = 0;
    gr->bytes = 0;
    free(gr->covered);
    gr->covered = NULL;
}

void vxl_gradients_forget_volume(vxl_gradient_state *gr)
{
    vxl_gradients_release(gr);
    for (int k = 0; k < VXL_LOD_LEVELS; k++) gr->max_level[k] = -1; /* unknown */
}

static GLuint groups(uint32_t n) { return (n + 3) / 4; }

static void dispatch_volume(vxl_gradient_state *gr)
{
    gr->gpu->gl.DispatchCompute(groups(gr->storage->geom.dims[0]), groups(gr->storage->geom.dims[1]), groups(gr->storage->geom.dims[2]));
}

int vxl_gradient_programs(vxl_gradient_state *gr, int paged, int store, uint64_t need, GLuint progs[3])
{
    int rc = vxl_holdings_ask(gr->gpu, VXL_HOLD_GRADIENTS, need, "; use an on-the-fly filter or the 8-bit store",
                            "precomputed gradients%s", paged ? " of the bricked volume" : "");
    if (!rc) rc = vxl_program_get(gr->gpu, paged ? VXL_PROG_PAGED_BLUR : VXL_PROG_GRAD_BLUR, 0, 0, &progs[0]);
    progs[1] = 0; /* paged: the maximum comes from the CPU bricks (bspline_bricks.c) */
    if (!rc && !paged) rc = vxl_program_get(gr->gpu, VXL_PROG_GRAD_MAX, 0, 0, &progs[1]);
    if (!rc) rc = vxl_program_get(gr->gpu, paged ? VXL_PROG_PAGED_GRAD_STORE : VXL_PROG_GRAD_STORE, 0, (uint32_t)store, &progs[2]);
    return rc;
}

int vxl_gradients_ensure(vxl_gradient_state *gr, int store)
{
    if (store < 0 || store > VXL_GRADIENT_STORE_32F)
        return vxl_fail(&gr->gpu->err, VXL_ERR_INVALID_ARGUMENT, "unknown gradient_store %d", store);
    if (gr->tex && gr->store == store) return VXL_OK;
    vxl_gradients_release(gr);
    vxl_gl *gl = &gr->gpu->gl;
    uint64_t n = (uint64_t)gr->storage->geom.dims[0] * gr->storage->geom.dims[1] * gr->storage->geom.dims[2];
    uint64_t need = n * store_bytes[store] + n * 4 /* transient blur */;
    GLuint progs[3];
    int rc = vxl_gradient_programs(gr, 0, store, need, progs);
    if (rc) return rc;
    const GLuint blur_prog = progs[0], max_prog = progs[1], store_prog = progs[2];
    gl->GetError();

    /* pass 1: blur into a transient float texture */
    GLuint blur = vxl_texture_new(gr->gpu, GL_TEXTURE_3D, GL_NEAREST);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)gr->storage->geom.dims[0], (GLsizei)gr->storage->geom.dims[1], (GLsizei)gr->storage->geom.dims[2], 0,
                   GL_RED, GL_FLOAT, NULL);
    gl->UseProgram(blur_prog);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, gr->storage->volume_tex);
    vxl_uniform_i(gr->gpu, blur_prog, "u_src", VXL_VOLUME_UNIT);
    gl->BindImageTexture(VXL_IMAGE_OUT, blur, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    dispatch_volume(gr);
    gl->MemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);

    /* pass 2: global maximum magnitude */
    const GLuint zero = 0;
    gl->BindBuffer(GL_SHADER_STORAGE_BUFFER, gr->gpu->ssbo[0]);
    gl->BufferData(GL_SHADER_STORAGE_BUFFER, sizeof zero, &zero, GL_DYNAMIC_READ);
    gl->BindBufferBase(GL_SHADER_STORAGE_BUFFER, VXL_SSBO_GRADIENT_MAX, gr->gpu->ssbo[0]);
    gl->UseProgram(max_prog);
    gl->BindTexture(GL_TEXTURE_3D, blur);
    vxl_uniform_i(gr->gpu, max_prog, "u_src", VXL_VOLUME_UNIT);
    dispatch_volume(gr);
    gl->MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    union { GLuint u; float f; } max_mag = {0};
    gl->GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof max_mag.u, &max_mag.u);

    /* pass 3: scaled raw gradient into the stored format */
    gr->tex = vxl_texture_new(gr->gpu, GL_TEXTURE_3D, GL_LINEAR);
    gl->TexImage3D(GL_TEXTURE_3D, 0, (GLint)store_internal[store], (GLsizei)gr->storage->geom.dims[0], (GLsizei)gr->storage->geom.dims[1],
                   (GLsizei)gr->storage->geom.dims[2], 0, GL_RGBA, GL_FLOAT, NULL);
    gl->UseProgram(store_prog);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, blur);
    vxl_uniform_i(gr->gpu, store_prog, "u_src", VXL_VOLUME_UNIT);
    vxl_uniform_f(gr->gpu, store_prog, "u_inv_max", max_mag.f > 0 ? 1.0f / max_mag.f : 0.0f);
    gl->BindImageTexture(VXL_IMAGE_OUT, gr->tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, store_internal[store]);
    dispatch_volume(gr);
    gl->MemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    gl->DeleteTextures(1, &blur);
    gl->UseProgram(0);
    rc = vxl_gl_check(gr->gpu, "precomputing gradients");
    if (rc) {
        vxl_gradients_release(gr);
        return rc;
    }
    gr->store = store;
    gr->max = max_mag.f;
    gr->bytes = n * store_bytes[store];
    return VXL_OK;
}

/* As the storage (storage.h, vxl_derived) and the budget (holdings.h) call it. */
static int whole(void *state, int store) { return vxl_gradients_ensure(state, store); }
static int per_brick(void *state, int store, void (*make_room)(void *room), void *room)
{
    return vxl_paged_gradients_ensure(state, store, make_room, room);
}
static void release(void *state) { vxl_gradients_release(state); }
static uint64_t pool_bytes(const void *state, uint32_t level, int store, uint8_t *want, uint32_t *count)
{
    return vxl_paged_gradient_bytes(state, level, store, want, count);
}
void vxl_gradients_init(vxl_gradient_state *gr, vxl_gpu *g, vxl_storage_state *st)
{
    gr->gpu = g;
    gr->storage = st;
    st->derived[VXL_DERIVED_GRADIENTS] = (vxl_derived){
        .state = gr, .whole = whole, .per_brick = per_brick, .release = release, .pool_bytes = pool_bytes,
        .page_tex = &gr->page_tex, .pool_dims = gr->pool_dims, .page_unit = VXL_GPAGE_UNIT,
        .page_name = "u_gpage", .dims_name = "u_gpool_dims",
        /* computed on the GL side from the pool: the blur and the Sobel reach 2 voxels each */
        .reads_pool = 1, .support = VXL_GRADIENT_SUPPORT, .read_reach = VXL_GRADIENT_READ_REACH};
    vxl_holding_register(g, VXL_HOLD_GRADIENTS, vxl_holding_counter, &gr->bytes);
}
