/* skipping.c - the GL side of empty-space skipping: builds the brick min-max
 * grid once per volume, uploads the distance map when the classification
 * changes (the grid's brick edge: vxl_skip_brick_size in bricks.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "paging.h"
#include "skipping.h"


void vxl_skipping_release(vxl_skipping_state *sk)
{
    if (sk->brick_tex) sk->gpu->gl.DeleteTextures(1, &sk->brick_tex);
    sk->brick_tex = 0;
    vxl_bricks_free(&sk->bricks);
}

void vxl_skipping_adopt(vxl_skipping_state *sk, vxl_bricks *grid, uint32_t texture_bits)
{
    vxl_bricks_free(&sk->bricks);
    sk->texture_bits = texture_bits;
    sk->bricks = *grid;
    memset(grid, 0, sizeof *grid);
}

/* One per-brick pass of brick_minmax.comp into out (2 floats per brick):
 * the min-max grid, or (apron > 0) the gradient bound in out[2 * i]. */
static int brick_pass(vxl_skipping_state *sk, uint32_t apron, float *out)
{
    vxl_gl *gl = &sk->gpu->gl;
    vxl_bricks *b = &sk->bricks;
    GLuint prog;
    int rc = vxl_program_get(sk->gpu, VXL_PROG_BRICK_MINMAX, 0, apron ? 1 : 0, &prog);
    if (rc) return rc;
    gl->GetError();
    GLuint tex = vxl_texture_new(sk->gpu, GL_TEXTURE_3D, GL_NEAREST);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_RG32F, (GLsizei)b->dims[0], (GLsizei)b->dims[1], (GLsizei)b->dims[2], 0, GL_RG,
                   GL_FLOAT, NULL);
    gl->UseProgram(prog);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    const uint32_t *dims;
    gl->BindTexture(GL_TEXTURE_3D, sk->storage->ops->texels(sk->storage, &dims));
    vxl_uniform_i(sk->gpu, prog, "u_volume", VXL_VOLUME_UNIT);
    vxl_uniform_i(sk->gpu, prog, "u_brick", (int)b->size);
    if (apron) vxl_uniform_i(sk->gpu, prog, "u_apron", (int)apron);
    gl->BindImageTexture(VXL_IMAGE_OUT, tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RG32F);
    gl->DispatchCompute((b->dims[0] + 3) / 4, (b->dims[1] + 3) / 4, (b->dims[2] + 3) / 4);
    gl->MemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    gl->BindTexture(GL_TEXTURE_3D, tex);
    gl->GetTexImage(GL_TEXTURE_3D, 0, GL_RG, GL_FLOAT, out);
    gl->DeleteTextures(1, &tex);
    gl->UseProgram(0);
    return vxl_gl_check(sk->gpu, apron ? "bounding the gradient per brick" : "building the brick min-max grid");
}

static int build_minmax(vxl_skipping_state *sk)
{
    vxl_bricks *b = &sk->bricks;
    b->size = vxl_skip_brick_size_for(sk->storage->geom.dims);
    for (int a = 0; a < 3; a++) b->dims[a] = (sk->storage->geom.dims[a] + b->size - 1) / b->size;
    size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    b->minmax = malloc(n * 2 * sizeof(float));
    if (!b->minmax) return vxl_fail(&sk->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the brick grid");
    int rc = brick_pass(sk, 0, b->minmax);
    if (rc || (sk->texture_bits != 8 && sk->texture_bits != 16)) return rc; /* float texels are exact */
    /* The pass picks each brick's extreme texels; an integer texel's float is
     * the driver's rounding of code / (2^bits - 1), which GL lets differ in
     * the last bit. Recovering the code (off by far under 0.5) and taking
     * paging.h's value makes this grid bit for bit the CPU's (bricked). The
     * occupancy rules widen [min, max] by far more than that ulp (bricks.c),
     * so skipping stays conservative for the samples the driver rounds. */
    const double top = (double)((1u << sk->texture_bits) - 1);
    for (size_t i = 0; i < 2 * n; i++)
        b->minmax[i] = (float)vxl_unorm_value((uint32_t)lrint(b->minmax[i] * top), sk->texture_bits);
    return VXL_OK;
}

/* Iso-surface skipping needs a gradient bound over the taps' reach; built on
 * first use and rebuilt only for a wider reach. Reaches beyond a brick's edge
 * are not bounded (the pass would read (3 bricks)^3 per brick): no leaps.
 * Nor is bricked storage (the pass reads the one volume texture): there
 * every brick counts as occupied in iso mode. */
static int ensure_gradient_bound(vxl_skipping_state *sk, const vxl_frame *f)
{
    vxl_bricks *b = &sk->bricks;
    uint32_t need = vxl_bricks_gradient_apron(f->filter, f->sample_distance);
    if (f->gopacity != VXL_GOPACITY_ISO || !need || need > b->size || !sk->storage->ops->one_texture ||
        (b->gbound && b->gbound_apron >= need))
        return VXL_OK;
    size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    float *tmp = malloc(n * 2 * sizeof *tmp);
    if (!tmp) return vxl_fail(&sk->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the brick gradient bound");
    int rc = brick_pass(sk, need, tmp);
    if (!rc) { /* keep one float per brick */
        for (size_t i = 0; i < n; i++) tmp[i] = tmp[2 * i];
        free(b->gbound);
        b->gbound = tmp;
        b->gbound_apron = need;
    } else {
        free(tmp);
    }
    return rc;
}

int vxl_skipping_prepare(vxl_skipping_state *sk, const vxl_frame *f)
{
    vxl_gl *gl = &sk->gpu->gl;
    if (!sk->bricks.minmax) {
        int rc = build_minmax(sk);
        if (rc) {
            vxl_skipping_release(sk);
            return rc;
        }
    }
    int rc = ensure_gradient_bound(sk, f);
    if (rc) return rc;
    int changed = vxl_bricks_classify(&sk->bricks, vxl_frame_occupancy_rule(f, &(vxl_occupancy_rule){0}));
    if (changed < 0) return vxl_fail(&sk->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the brick occupancy");
    if (!sk->brick_tex) {
        sk->brick_tex = vxl_texture_new(sk->gpu, GL_TEXTURE_3D, GL_NEAREST);
        changed = 1;
    }
    gl->ActiveTexture(GL_TEXTURE0 + VXL_DISTANCE_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, sk->brick_tex);
    if (changed)
        gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R8UI, (GLsizei)sk->bricks.dims[0], (GLsizei)sk->bricks.dims[1],
                       (GLsizei)sk->bricks.dims[2], 0, GL_RED_INTEGER, GL_UNSIGNED_BYTE, sk->bricks.distance);
    return VXL_OK;
}

void vxl_skipping_init(vxl_skipping_state *sk, vxl_gpu *g, vxl_storage_state *st)
{
    sk->gpu = g;
    sk->storage = st;
    st->grid = &sk->bricks;
}
