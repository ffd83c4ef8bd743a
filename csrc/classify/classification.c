/* classification.c - GL resources of the pre- and pre-integrated modes,
 * rebuilt only when what they depend on changes: the pre-classified volume
 * on the classification (table, window, opacity scale), the pre-integration
 * table on the classification, the step and the table size. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "classification.h"
#include "holdings.h"
#include "preint.h"

void vxl_classification_release(vxl_classification_state *cl)
{
    if (cl->classified_tex) cl->gpu->gl.DeleteTextures(1, &cl->classified_tex);
    if (cl->preint_tex) cl->gpu->gl.DeleteTextures(1, &cl->preint_tex);
    cl->classified_tex = cl->preint_tex = 0;
    cl->classified_key = cl->preint_key = 0;
    cl->classified_bytes = 0;
}

/* The TF and window uniforms of classify.glsl, for the compute pass. */
static void set_classify_uniforms(vxl_classification_state *cl, GLuint prog, const vxl_frame *f)
{
    vxl_gl *gl = &cl->gpu->gl;
    vxl_uniform_i(cl->gpu, prog, "u_tf", VXL_TF_UNIT);
    vxl_uniform_f(cl->gpu, prog, "u_tf_size", (float)f->tf_size);
    gl->Uniform2f(gl->GetUniformLocation(prog, "u_window"), f->window_offset, f->window_scale);
    vxl_uniform_f(cl->gpu, prog, "u_opacity_scale", f->opacity_scale);
}

/* Pre-classification classifies texel for texel whatever holds the values:
 * the volume texture, or the brick pool (ghosts included, so a classified
 * brick filters as the dense classified volume does; a brick not in the pool
 * is classified in the shader, classify.glsl). A new pool is a new key. */
static int prepare_pre(vxl_classification_state *cl, const vxl_frame *f)
{
    vxl_gl *gl = &cl->gpu->gl;
    const uint32_t *dims;
    const GLuint texels = cl->storage->ops->texels(cl->storage, &dims);
    uint64_t key = (vxl_classification_key(f) ^ cl->storage->pool_generation) * 1099511628211ull;
    if (cl->classified_tex && cl->classified_key == key) goto bind;
    uint64_t n = (uint64_t)dims[0] * dims[1] * dims[2];
    if (cl->classified_tex && memcmp(cl->classified_dims, dims, sizeof cl->classified_dims)) {
        gl->DeleteTextures(1, &cl->classified_tex); /* the pool changed size */
        cl->classified_tex = 0;
        cl->classified_bytes = 0;
    }
    if (!cl->classified_tex) {
        int rc = vxl_holdings_ask(cl->gpu, VXL_HOLD_CLASSIFIED, n * 4, NULL, "the pre-classified volume");
        if (rc) return rc;
        cl->classified_tex = vxl_texture_new(cl->gpu, GL_TEXTURE_3D, GL_LINEAR);
        gl->TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA8, (GLsizei)dims[0], (GLsizei)dims[1], (GLsizei)dims[2], 0, GL_RGBA,
                       GL_UNSIGNED_BYTE, NULL);
        cl->classified_bytes = n * 4;
        memcpy(cl->classified_dims, dims, sizeof cl->classified_dims);
    }
    GLuint prog;
    int rc = vxl_program_get(cl->gpu, VXL_PROG_CLASSIFY_VOLUME, 0, 0, &prog);
    if (rc) return rc;
    gl->UseProgram(prog);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, texels);
    vxl_uniform_i(cl->gpu, prog, "u_volume", VXL_VOLUME_UNIT);
    set_classify_uniforms(cl, prog, f); /* the TF is already on unit 2 */
    gl->BindImageTexture(VXL_IMAGE_OUT, cl->classified_tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
    gl->DispatchCompute((dims[0] + 3) / 4, (dims[1] + 3) / 4, (dims[2] + 3) / 4);
    gl->MemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    gl->UseProgram(0);
    cl->classified_key = key;
bind:
    gl->ActiveTexture(GL_TEXTURE0 + VXL_CLASSIFIED_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, cl->classified_tex);
    return vxl_gl_check(cl->gpu, "pre-classifying the volume");
}

static int prepare_preint(vxl_classification_state *cl, const vxl_frame *f)
{
    vxl_gl *gl = &cl->gpu->gl;
    uint64_t key = vxl_classification_key(f) ^ ((uint64_t)f->preint_size << 40);
    double step = f->step;
    uint64_t bits;
    memcpy(&bits, &step, sizeof bits);
    key = (key ^ bits) * 1099511628211ull;
    if (!(cl->preint_tex && cl->preint_key == key)) {
        uint32_t n = f->preint_size;
        float *table = malloc((size_t)n * n * 4 * sizeof *table);
        if (!table) return vxl_fail(&cl->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for a %ux%u pre-integration table", n, n);
        if (vxl_preint_build(f->tf, f->tf_size, f->opacity_scale, f->step, n, table)) {
            free(table);
            return vxl_fail(&cl->gpu->err, VXL_ERR_NO_MEMORY, "cannot build the pre-integration table");
        }
        if (!cl->preint_tex) cl->preint_tex = vxl_texture_new(cl->gpu, GL_TEXTURE_2D, GL_LINEAR);
        else {
            gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
            gl->BindTexture(GL_TEXTURE_2D, cl->preint_tex);
        }
        gl->TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, (GLsizei)n, (GLsizei)n, 0, GL_RGBA, GL_FLOAT, table);
        free(table);
        cl->preint_key = key;
    }
    gl->ActiveTexture(GL_TEXTURE0 + VXL_PREINT_UNIT);
    gl->BindTexture(GL_TEXTURE_2D, cl->preint_tex);
    return vxl_gl_check(cl->gpu, "uploading the pre-integration table");
}

int vxl_classification_prepare(vxl_classification_state *cl, const vxl_frame *f)
{
    switch (f->classify) {
    case VXL_CLASSIFY_PRE: return prepare_pre(cl, f);
    case VXL_CLASSIFY_PREINT: return prepare_preint(cl, f);
    default: return VXL_OK;
    }
}

void vxl_classification_init(vxl_classification_state *cl, vxl_gpu *g, vxl_storage_state *st)
{
    cl->gpu = g;
    cl->storage = st;
    vxl_holding_register(g, VXL_HOLD_CLASSIFIED, vxl_holding_counter, &cl->classified_bytes);
}
