/* colour.c - a colour volume's own colour on the GL side (colour.h). */
#include "colour.h"

#include "colour_volume.h"
#include "holdings.h"

void vxl_colour_init(vxl_colour_state *s, vxl_gpu *g)
{
    s->gpu = g;
    vxl_holding_register(g, VXL_HOLD_COLOUR, vxl_holding_counter, &s->bytes);
}

void vxl_colour_release(vxl_colour_state *s)
{
    if (s->tex) s->gpu->gl.DeleteTextures(1, &s->tex);
    s->tex = 0;
    s->bytes = 0;
}

int vxl_colour_plan(vxl_colour_state *s, const vxl_volume *v, uint64_t storage_bytes)
{
    if (!v->colour) return VXL_OK;
    vxl_gpu *g = s->gpu;
    for (int a = 0; a < 3; a++)
        if (v->dims[a] > (uint32_t)g->info.max_3d_texture_size)
            return vxl_fail(&g->err, VXL_ERR_LIMIT,
                            "the colour of a %ux%ux%u volume is one 3D texture and exceeds this backend's limit of %d "
                            "per axis (load it with opacity source and colour source tf, or crop it)",
                            v->dims[0], v->dims[1], v->dims[2], g->info.max_3d_texture_size);
    /* a new volume releases everything derived from the old one: only what
     * it keeps (labels, overlays, the MatCap, cutters, shadow maps) stays */
    uint64_t held[VXL_HOLD_COUNT];
    vxl_holdings(g, held);
    held[VXL_HOLD_GRADIENTS] = held[VXL_HOLD_BSPLINE] = held[VXL_HOLD_CLASSIFIED] = 0;
    held[VXL_HOLD_ILLUMINATION] = held[VXL_HOLD_MODE_BRICKS] = 0;
    const uint64_t bytes = vxl_volume_colour_bytes(v);
    return vxl_budget_ask(g->budget, held, VXL_HOLD_COLOUR, bytes + storage_bytes, &g->err,
                          " (a colour volume's colour is stored densely, 3 bytes a voxel, beside its scalar)",
                          "the %ux%ux%u colour volume", v->dims[0], v->dims[1], v->dims[2]);
}

int vxl_colour_set(vxl_colour_state *s, const vxl_volume *v)
{
    vxl_colour_release(s);
    if (!v || !v->colour) return VXL_OK;
    vxl_gpu *g = s->gpu;
    vxl_gl *gl = &g->gl;
    gl->GetError();
    /* filtered as the scalar is: trilinear between voxel centres */
    s->tex = vxl_texture_new(g, GL_TEXTURE_3D, GL_LINEAR);
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_RGB8, (GLsizei)v->dims[0], (GLsizei)v->dims[1], (GLsizei)v->dims[2], 0, GL_RGB,
                   GL_UNSIGNED_BYTE, v->colour);
    int rc = vxl_gl_check(g, "uploading the colour volume's colour");
    if (rc) {
        vxl_colour_release(s);
        return rc;
    }
    s->bytes = vxl_volume_colour_bytes(v);
    s->uploads++;
    return VXL_OK;
}

int vxl_colour_flags(const vxl_colour_state *s, const vxl_frame *f, uint32_t *flags)
{
    *flags = 0;
    if (f->color_source == VXL_COLOR_SOURCE_TF) return VXL_OK;
    if (!s->tex) {
        if (f->color_source == VXL_COLOR_SOURCE_DATA)
            return vxl_fail(&s->gpu->err, VXL_ERR_STATE,
                            "color_source data, but the volume has no colour of its own (it is grey)");
        return VXL_OK;
    }
    *flags = VXL_FLAG_DATA_COLOUR;
    return VXL_OK;
}

void vxl_colour_bind(vxl_colour_state *s, uint32_t flags, GLuint prog)
{
    if (!(flags & VXL_FLAG_DATA_COLOUR)) return;
    vxl_gl *gl = &s->gpu->gl;
    gl->ActiveTexture(GL_TEXTURE0 + VXL_COLOUR_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, s->tex);
    vxl_uniform_i(s->gpu, prog, "u_colour", VXL_COLOUR_UNIT);
}
