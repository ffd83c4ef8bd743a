/* precompute.c - the `precomputed` gradient filter's texture: a [1,2,1]^3 blur
 * then a 26-neighbour Sobel, computed on the GL side once per volume. It
 * stores the raw gradient divided by the global maximum magnitude, so that
 * interpolation happens before normalisation (see measured-facts.md). */
#include <stdlib.h>

#include "holdings.h"
#include "renderer_internal.h"

static const GLenum store_internal[] = {GL_RGBA8_SNORM, GL_RGBA16F, GL_RGBA32F};
static const uint32_t store_bytes[] = {4, 8, 16};

void vxl_gradients_release(vxl_renderer *r)
{
    const GLuint tex[2] = {r->gradients.tex, r->gradients.page_tex}; /* the volume or pool, and a pool's page table */
    r->gl.DeleteTextures(2, tex); /* 0 is ignored */
    r->gradients.tex = r->gradients.page_tex = 0;
    r->gradients.bytes = 0;
    free(r->gradients.covered);
    r->gradients.covered = NULL;
}

void vxl_gradients_forget_volume(vxl_renderer *r)
{
    vxl_gradients_release(r);
    for (int k = 0; k < VXL_LOD_LEVELS; k++) r->gradients.max_level[k] = -1; /* unknown */
}

static GLuint groups(uint32_t n) { return (n + 3) / 4; }

static void dispatch_volume(vxl_renderer *r)
{
    r->gl.DispatchCompute(groups(r->dims[0]), groups(r->dims[1]), groups(r->dims[2]));
}

int vxl_gradient_programs(vxl_renderer *r, int paged, int store, uint64_t need, GLuint progs[3])
{
    int rc = vxl_holdings_ask(r, VXL_HOLD_GRADIENTS, need, "; use an on-the-fly filter or the 8-bit store",
                            "precomputed gradients%s", paged ? " of the bricked volume" : "");
    if (!rc) rc = vxl_program_get(r, paged ? VXL_PROG_PAGED_BLUR : VXL_PROG_GRAD_BLUR, 0, 0, &progs[0]);
    progs[1] = 0; /* paged: the maximum comes from the CPU bricks (bspline_bricks.c) */
    if (!rc && !paged) rc = vxl_program_get(r, VXL_PROG_GRAD_MAX, 0, 0, &progs[1]);
    if (!rc) rc = vxl_program_get(r, paged ? VXL_PROG_PAGED_GRAD_STORE : VXL_PROG_GRAD_STORE, 0, (uint32_t)store, &progs[2]);
    return rc;
}

int vxl_gradients_ensure(vxl_renderer *r, int store)
{
    if (store < 0 || store > VXL_GRADIENT_STORE_32F)
        return vxl_fail(&r->err, VXL_ERR_INVALID_ARGUMENT, "unknown gradient_store %d", store);
    if (r->gradients.tex && r->gradients.store == store) return VXL_OK;
    vxl_gradients_release(r);
    vxl_gl *gl = &r->gl;
    uint64_t n = (uint64_t)r->dims[0] * r->dims[1] * r->dims[2];
    uint64_t need = n * store_bytes[store] + n * 4 /* transient blur */;
    GLuint progs[3];
    int rc = vxl_gradient_programs(r, 0, store, need, progs);
    if (rc) return rc;
    const GLuint blur_prog = progs[0], max_prog = progs[1], store_prog = progs[2];
    gl->GetError();

    /* pass 1: blur into a transient float texture */
    GLuint blur = vxl_texture_new(r, GL_TEXTURE_3D, GL_NEAREST);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)r->dims[0], (GLsizei)r->dims[1], (GLsizei)r->dims[2], 0,
                   GL_RED, GL_FLOAT, NULL);
    gl->UseProgram(blur_prog);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, r->storage.volume_tex);
    vxl_uniform_i(r, blur_prog, "u_src", VXL_VOLUME_UNIT);
    gl->BindImageTexture(VXL_IMAGE_OUT, blur, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    dispatch_volume(r);
    gl->MemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);

    /* pass 2: global maximum magnitude */
    const GLuint zero = 0;
    gl->BindBuffer(GL_SHADER_STORAGE_BUFFER, r->ssbo[0]);
    gl->BufferData(GL_SHADER_STORAGE_BUFFER, sizeof zero, &zero, GL_DYNAMIC_READ);
    gl->BindBufferBase(GL_SHADER_STORAGE_BUFFER, VXL_SSBO_GRADIENT_MAX, r->ssbo[0]);
    gl->UseProgram(max_prog);
    gl->BindTexture(GL_TEXTURE_3D, blur);
    vxl_uniform_i(r, max_prog, "u_src", VXL_VOLUME_UNIT);
    dispatch_volume(r);
    gl->MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    union { GLuint u; float f; } max_mag = {0};
    gl->GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof max_mag.u, &max_mag.u);

    /* pass 3: scaled raw gradient into the stored format */
    r->gradients.tex = vxl_texture_new(r, GL_TEXTURE_3D, GL_LINEAR);
    gl->TexImage3D(GL_TEXTURE_3D, 0, (GLint)store_internal[store], (GLsizei)r->dims[0], (GLsizei)r->dims[1],
                   (GLsizei)r->dims[2], 0, GL_RGBA, GL_FLOAT, NULL);
    gl->UseProgram(store_prog);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, blur);
    vxl_uniform_i(r, store_prog, "u_src", VXL_VOLUME_UNIT);
    vxl_uniform_f(r, store_prog, "u_inv_max", max_mag.f > 0 ? 1.0f / max_mag.f : 0.0f);
    gl->BindImageTexture(VXL_IMAGE_OUT, r->gradients.tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, store_internal[store]);
    dispatch_volume(r);
    gl->MemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    gl->DeleteTextures(1, &blur);
    gl->UseProgram(0);
    rc = vxl_gl_check(r, "precomputing gradients");
    if (rc) {
        vxl_gradients_release(r);
        return rc;
    }
    r->gradients.store = store;
    r->gradients.max = max_mag.f;
    r->gradients.bytes = n * store_bytes[store];
    return VXL_OK;
}
