/* storage_dense.c - dense storage: the volume in one 3D texture, sampled
 * directly; its derived volumes are computed over the whole texture by the
 * kernels their subsystems register (precompute.c, bspline.c). */
#include <string.h>

#include "budget.h"
#include "storage.h"


static int plan(vxl_storage_state *st, const vxl_volume *v, uint32_t asked, vxl_storage_plan *out)
{
    (void)asked;
    memset(out, 0, sizeof *out);
    out->mode = VXL_STORAGE_DENSE;
    for (int a = 0; a < 3; a++)
        if (v->dims[a] > (uint32_t)st->gpu->info.max_3d_texture_size)
            return vxl_fail(&st->gpu->err, VXL_ERR_LIMIT,
                            "volume %ux%ux%u exceeds this backend's 3D texture limit of %d per axis (bricked "
                            "storage has no such limit)",
                            v->dims[0], v->dims[1], v->dims[2], st->gpu->info.max_3d_texture_size);
    out->bytes = v->storage_bytes;
    return vxl_budget_ask(st->gpu->budget, NULL, VXL_HOLD_STORAGE, v->storage_bytes, &st->gpu->err, NULL,
                          "the volume %ux%ux%u (dense storage)", v->dims[0], v->dims[1], v->dims[2]);
}

static void release(vxl_storage_state *st)
{
    if (st->volume_tex) st->gpu->gl.DeleteTextures(1, &st->volume_tex);
    st->volume_tex = 0;
}

static int install(vxl_storage_state *st, const vxl_volume *v, vxl_storage_plan *pl)
{
    (void)pl; /* nothing planned beyond the checks */
    const uint32_t bpv = v->texture_bits / 8;
    st->gpu->gl.GetError();
    st->volume_tex = vxl_texture_new(st->gpu, GL_TEXTURE_3D, GL_LINEAR);
    st->gpu->gl.TexImage3D(GL_TEXTURE_3D, 0, (GLint)vxl_texel_internal_format(bpv), (GLsizei)v->dims[0], (GLsizei)v->dims[1],
                     (GLsizei)v->dims[2], 0, GL_RED, vxl_texel_type(bpv), v->texels);
    int rc = vxl_gl_check(st->gpu, "uploading the volume");
    if (rc) release(st);
    st->mode = VXL_STORAGE_DENSE;
    st->volume_bytes = v->storage_bytes;
    return rc;
}

static int prepare(vxl_storage_state *st, const vxl_frame *f)
{
    (void)st;
    (void)f;
    return VXL_OK; /* everything is resident */
}

static uint32_t sample_flags(const vxl_storage_state *st)
{
    (void)st;
    return 0;
}

static void bind(vxl_storage_state *st, GLuint prog)
{
    (void)prog;
    st->gpu->gl.ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    st->gpu->gl.BindTexture(GL_TEXTURE_3D, st->volume_tex);
}

static GLuint texels(const vxl_storage_state *st, const uint32_t **dims)
{
    *dims = st->geom.dims;
    return st->volume_tex;
}

static uint64_t resident_bytes(const vxl_storage_state *st) { return st->volume_bytes; }

static void report(const vxl_storage_state *st, vxl_render_stats *s)
{
    (void)st;
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
    .derive = vxl_whole_derive,
    .needs_occupancy = 0,
    .one_texture = 1,
    .release = release,
};
