/* storage_dense.c - dense storage: the volume in one 3D texture, sampled
 * directly; its derived volumes are computed over the whole texture
 * (precompute.c, bspline.c). */
#include <string.h>

#include "budget.h"
#include "renderer_internal.h"

static const GLenum internal_formats[] = {GL_R8, GL_R16, GL_R32F};
static const GLenum texel_types[] = {GL_UNSIGNED_BYTE, GL_UNSIGNED_SHORT, GL_FLOAT};

static int plan(vxl_renderer *r, const vxl_volume *v, uint32_t asked, vxl_storage_plan *out)
{
    (void)asked;
    memset(out, 0, sizeof *out);
    out->mode = VXL_STORAGE_DENSE;
    for (int a = 0; a < 3; a++)
        if (v->dims[a] > (uint32_t)r->info.max_3d_texture_size)
            return vxl_fail(&r->err, VXL_ERR_LIMIT,
                            "volume %ux%ux%u exceeds this backend's 3D texture limit of %d per axis (bricked "
                            "storage has no such limit)",
                            v->dims[0], v->dims[1], v->dims[2], r->info.max_3d_texture_size);
    return vxl_budget_ask(r->budget, NULL, VXL_HOLD_STORAGE, v->storage_bytes, &r->err, NULL,
                          "the volume %ux%ux%u (dense storage)", v->dims[0], v->dims[1], v->dims[2]);
}

static void release(vxl_renderer *r)
{
    if (r->storage.volume_tex) r->gl.DeleteTextures(1, &r->storage.volume_tex);
    r->storage.volume_tex = 0;
}

static int install(vxl_renderer *r, const vxl_volume *v, vxl_storage_plan *pl)
{
    (void)pl; /* nothing planned beyond the checks */
    int fi = v->texture_bits == 8 ? 0 : v->texture_bits == 16 ? 1 : 2;
    r->gl.GetError();
    r->storage.volume_tex = vxl_texture_new(r, GL_TEXTURE_3D, GL_LINEAR);
    r->gl.TexImage3D(GL_TEXTURE_3D, 0, (GLint)internal_formats[fi], (GLsizei)v->dims[0], (GLsizei)v->dims[1],
                     (GLsizei)v->dims[2], 0, GL_RED, texel_types[fi], v->texels);
    int rc = vxl_gl_check(r, "uploading the volume");
    if (rc) release(r);
    r->storage.mode = VXL_STORAGE_DENSE;
    r->storage.volume_bytes = v->storage_bytes;
    return rc;
}

static int prepare(vxl_renderer *r, const vxl_frame *f)
{
    (void)r;
    (void)f;
    return VXL_OK; /* everything is resident */
}

static uint32_t sample_flags(const vxl_renderer *r)
{
    (void)r;
    return 0;
}

static void bind(vxl_renderer *r, GLuint prog)
{
    (void)prog;
    r->gl.ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    r->gl.BindTexture(GL_TEXTURE_3D, r->storage.volume_tex);
}

static GLuint texels(const vxl_renderer *r, const uint32_t **dims)
{
    *dims = r->dims;
    return r->storage.volume_tex;
}

static uint64_t resident_bytes(const vxl_renderer *r) { return r->storage.volume_bytes; }

static void report(const vxl_renderer *r, vxl_render_stats *s)
{
    (void)r;
    (void)s; /* no pages to report */
}

const vxl_storage_ops vxl_storage_dense = {
    .plan = plan,
    .install = install,
    .check_filter = vxl_storage_serves_all,
    .prepare = prepare,
    .sample_flags = sample_flags,
    .bind = bind,
    .texels = texels,
    .resident_bytes = resident_bytes,
    .report = report,
    .gradients = vxl_gradients_ensure,
    .bspline = vxl_bspline_ensure,
    .needs_occupancy = 0,
    .one_texture = 1,
    .release = release,
};
