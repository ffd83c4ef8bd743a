/* path.c - the GL side of the PATH shading model (path.h). The majorant is
 * per skipping brick: the min-max grid bounds one texture's trilinear
 * samples, apron included; storage that samples a coarser level or a lossy
 * palette (bricked, sparse, compressed) is bounded by the whole table's
 * largest opacity instead, correct there but with more null collisions. */
#include "path.h"

#include <stdlib.h>

#include "gl_bindings.h"
#include "hash.h"
#include "holdings.h"
#include "majorant.h"

void vxl_path_init(vxl_path_state *s, vxl_gpu *g, const vxl_skipping_state *sk, const vxl_storage_state *st)
{
    s->gpu = g;
    s->skipping = sk;
    s->storage = st;
    vxl_holding_register(g, VXL_HOLD_PATH_MAJORANT, vxl_holding_counter, &s->bytes);
}

void vxl_path_release(vxl_path_state *s)
{
    if (s->majorant_tex) s->gpu->gl.DeleteTextures(1, &s->majorant_tex);
    s->majorant_tex = 0;
    s->minmax_src = NULL;
    s->key = 0;
    s->bytes = 0;
}

static int upload_majorant(vxl_path_state *s, const vxl_frame *f, int whole_table)
{
    const vxl_bricks *b = &s->skipping->bricks;
    uint64_t key = vxl_fnv(vxl_classification_key(f), &whole_table, sizeof whole_table);
    if (s->majorant_tex && s->minmax_src == b->minmax && s->key == key) return VXL_OK;
    size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    uint64_t bytes = (uint64_t)n * sizeof(float);
    if (s->minmax_src != b->minmax || !s->majorant_tex) {
        vxl_path_release(s);
        int rc = vxl_holdings_ask(s->gpu, VXL_HOLD_PATH_MAJORANT, bytes, NULL,
                                  "the path tracer's majorant grid of %ux%ux%u bricks", b->dims[0], b->dims[1], b->dims[2]);
        if (rc) return rc;
    }
    float *sigma = malloc(n * sizeof *sigma);
    if (!sigma) return vxl_fail(&s->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the majorant grid");
    vxl_bricks_majorant(b, vxl_frame_occupancy_rule(f, &(vxl_occupancy_rule){0}), whole_table, sigma);
    vxl_gl *gl = &s->gpu->gl;
    gl->GetError();
    if (!s->majorant_tex) s->majorant_tex = vxl_texture_new(s->gpu, GL_TEXTURE_3D, GL_NEAREST);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_MAJORANT_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, s->majorant_tex);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)b->dims[0], (GLsizei)b->dims[1], (GLsizei)b->dims[2], 0, GL_RED,
                   GL_FLOAT, sigma);
    free(sigma);
    int rc = vxl_gl_check(s->gpu, "uploading the majorant grid");
    if (rc) {
        vxl_path_release(s);
        return rc;
    }
    s->minmax_src = b->minmax;
    s->key = key;
    s->bytes = bytes;
    return VXL_OK;
}

int vxl_path_bind(vxl_path_state *s, const vxl_frame *f, GLuint prog)
{
    if (!s->skipping->bricks.minmax)
        return vxl_fail(&s->gpu->err, VXL_ERR_STATE, "the path tracer needs the brick grid, which is not built");
    int rc = upload_majorant(s, f, !s->storage->ops->one_texture);
    if (rc) return rc;
    vxl_gl *gl = &s->gpu->gl;
    gl->ActiveTexture(GL_TEXTURE0 + VXL_MAJORANT_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, s->majorant_tex);
    const vxl_bricks *b = &s->skipping->bricks;
    vxl_uniform_i(s->gpu, prog, "u_majorant", VXL_MAJORANT_UNIT);
    vxl_uniform_i(s->gpu, prog, "u_path_brick", (int)b->size);
    gl->Uniform1ui(gl->GetUniformLocation(prog, "u_path_first"), f->path_offset);
    gl->Uniform1ui(gl->GetUniformLocation(prog, "u_path_samples"), f->path_samples);
    gl->Uniform1ui(gl->GetUniformLocation(prog, "u_path_seed"), f->path_seed);
    vxl_uniform_i(s->gpu, prog, "u_path_bounces", (int)f->path_bounces);
    vxl_uniform_f(s->gpu, prog, "u_path_max_sigma", (float)VXL_MAX_VOXEL_EXTINCTION);
    return VXL_OK;
}
