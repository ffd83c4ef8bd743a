/* modes.c - the GL side of the render modes (modes.h).
 *
 * Min-max skipping is on for MIP, MinIP and ISO when empty-space skipping
 * is (f->skip) and the storage samples one texture at full resolution (the
 * grid bounds that texture's trilinear samples, apron included). Bricked,
 * sparse and compressed storage sample a pool that may be a coarser level
 * or a lossy palette, which the full-resolution grid does not bound, so they
 * march every sample: the same image, without the leaps. */
#include "modes.h"

#include "holdings.h"

void vxl_modes_init(vxl_modes_state *s, vxl_gpu *g, const vxl_skipping_state *sk, const vxl_storage_state *st)
{
    s->gpu = g;
    s->skipping = sk;
    s->storage = st;
    vxl_holding_register(g, VXL_HOLD_MODE_BRICKS, vxl_holding_counter, &s->bytes);
}

void vxl_modes_release(vxl_modes_state *s)
{
    if (s->minmax_tex) s->gpu->gl.DeleteTextures(1, &s->minmax_tex);
    s->minmax_tex = 0;
    s->minmax_src = NULL;
    s->bytes = 0;
}

uint32_t vxl_modes_flags(const vxl_frame *f, uint32_t flags)
{
    return flags | (f->mode << VXL_FLAG_MODE_SHIFT) | (f->matcap_rgba ? VXL_FLAG_MATCAP : 0u);
}

/* The skipping grid's min-max as an RG32F texture, uploaded once per grid. */
static int upload_minmax(vxl_modes_state *s)
{
    const vxl_bricks *b = &s->skipping->bricks;
    if (s->minmax_tex && s->minmax_src == b->minmax) return VXL_OK;
    vxl_modes_release(s);
    uint64_t bytes = (uint64_t)b->dims[0] * b->dims[1] * b->dims[2] * 2 * sizeof(float);
    int rc = vxl_holdings_ask(s->gpu, VXL_HOLD_MODE_BRICKS, bytes, NULL, "the brick min-max grid of %ux%ux%u bricks",
                              b->dims[0], b->dims[1], b->dims[2]);
    if (rc) return rc;
    vxl_gl *gl = &s->gpu->gl;
    gl->GetError();
    s->minmax_tex = vxl_texture_new(s->gpu, GL_TEXTURE_3D, GL_NEAREST);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_RG32F, (GLsizei)b->dims[0], (GLsizei)b->dims[1], (GLsizei)b->dims[2], 0, GL_RG,
                   GL_FLOAT, b->minmax);
    rc = vxl_gl_check(s->gpu, "uploading the brick min-max grid");
    if (rc) {
        vxl_modes_release(s);
        return rc;
    }
    s->minmax_src = b->minmax;
    s->bytes = bytes;
    return VXL_OK;
}

int vxl_modes_bind(vxl_modes_state *s, const vxl_frame *f, GLuint prog)
{
    if (f->mode == VXL_MODE_DVR) return VXL_OK;
    int skip = f->skip && f->mode != VXL_MODE_AVERAGE && s->storage->ops->one_texture && s->skipping->bricks.minmax;
    if (skip) {
        int rc = upload_minmax(s);
        if (rc) return rc;
        s->gpu->gl.ActiveTexture(GL_TEXTURE0 + VXL_BRICK_MINMAX_UNIT);
        s->gpu->gl.BindTexture(GL_TEXTURE_3D, s->minmax_tex);
    }
    vxl_uniform_i(s->gpu, prog, "u_mode_skip", skip);
    vxl_uniform_i(s->gpu, prog, "u_brick_minmax", VXL_BRICK_MINMAX_UNIT);
    vxl_uniform_f(s->gpu, prog, "u_iso", f->iso_pos);
    vxl_uniform_f(s->gpu, prog, "u_minip_floor", f->minip_floor_on ? f->minip_floor_pos : -1e30f);
    return VXL_OK;
}
