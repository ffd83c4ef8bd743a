/* slice_plane.c - vxl_render_slice: the volume resampled on a
 * plane with the window and colour map, for multi-planar views. A compute
 * pass (shaders/compute/slice_plane.comp) writes one texel per output pixel;
 * it samples through the storage's own binding, so dense, bricked, sparse
 * and compressed volumes give the same image. Runs on the GL thread like
 * vxl_render. */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "frame.h"
#include "mat4.h"
#include "renderer_internal.h"

typedef struct slice_job {
    vxl_renderer *r;
    const vxl_render_params *p;
    vxl_slice_params s;
    float *rgba;
} slice_job;

/* Only what a slice reads of the caller's params (size, placement, window,
 * colour map): the camera, shading, mode and cutaways are not the slice's
 * business, so a value there that vxl_render would refuse does not fail it. */
static int slice_frame(vxl_frame *f, const vxl_render_params *in, const vxl_volume_geom *g, vxl_err *e)
{
    vxl_render_params p;
    int rc = vxl_render_params_read(&p, in, e);
    if (rc) return rc;
    if (p.has_model) {
        double m[16], inv[16];
        vxl_mat4_from_float(m, p.model);
        if (!vxl_mat4_invert(inv, m))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "the model matrix (voxel -> world) is singular or not finite");
    }
    vxl_render_params q = {.struct_size = sizeof q,
                           .width = p.width,
                           .height = p.height,
                           .has_model = p.has_model,
                           .preset = p.preset,
                           .tf_size = p.tf_size,
                           .tf_rgba = p.tf_rgba,
                           .has_window = p.has_window,
                           .window_low = p.window_low,
                           .window_high = p.window_high,
                           .color_source = p.color_source,
                           .color_space = p.color_space};
    memcpy(q.model, p.model, sizeof q.model);
    return vxl_frame_resolve(f, &q, g, e);
}

/* plane -> voxel space: the inverse of the volume's placement times the
 * plane's matrix, in double. The plane must be affine and its square must
 * have an area (its x and y axes neither zero nor parallel); its z axis is
 * not used (a plane flattened along z is fine). */
static int plane_to_voxel(const vxl_frame *f, const float plane_to_world[16], float out[16], vxl_err *e)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(plane_to_world[i]))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "slice plane_to_world[%d] is not finite", i);
    double pw[16], inv[16], pv[16];
    vxl_mat4_from_float(pw, plane_to_world);
    if (pw[3] != 0 || pw[7] != 0 || pw[11] != 0 || pw[15] != 1)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "slice plane_to_world is not affine: its last row is %g %g %g %g, not 0 0 0 1", pw[3], pw[7],
                        pw[11], pw[15]);
    const double *x = pw, *y = pw + 4;
    double c[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
    double area = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double lx = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), ly = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    if (!(area > 1e-9 * lx * ly) || !(area > 0))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "slice plane_to_world is singular: its x and y axes are zero or parallel, so the slice has no area");
    if (!vxl_mat4_invert(inv, f->model))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "the model matrix (voxel -> world) is singular or not finite");
    vxl_mat4_mul(pv, inv, pw);
    if (!vxl_mat4_is_finite(pv))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "slice plane_to_world maps outside float range in voxel space");
    vxl_mat4_to_float(out, pv);
    return VXL_OK;
}

/* The frame's straight-RGBA table as a 1D texture on the table's unit, which
 * the shader reads texel for texel. */
static GLuint table_texture(vxl_renderer *r, const vxl_frame *f)
{
    vxl_gl *gl = &r->gpu.gl;
    GLuint t = vxl_texture_new(&r->gpu, GL_TEXTURE_1D, GL_NEAREST);
    gl->TexImage1D(GL_TEXTURE_1D, 0, GL_RGBA32F, (GLsizei)f->tf_size, 0, GL_RGBA, GL_FLOAT, f->tf);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_TF_UNIT);
    gl->BindTexture(GL_TEXTURE_1D, t);
    return t;
}

static int resample(vxl_renderer *r, const vxl_frame *f, uint32_t interp, const float m[16], float *rgba)
{
    vxl_gl *gl = &r->gpu.gl;
    const uint32_t filter = interp == VXL_INTERP_CUBIC ? VXL_FILTER_CUBIC : VXL_FILTER_CENTRAL;
    GLuint prog;
    uint32_t colour_flags; /* a colour volume's own colour, as the ray caster shows it */
    int rc = vxl_colour_flags(&r->colour, f, &colour_flags);
    if (!rc) rc = r->storage.ops->check_filter(&r->storage, filter, VXL_CLASSIFY_POST);
    if (!rc) rc = r->storage.ops->prepare(&r->storage, NULL); /* every brick: a plane may cross any */
    if (!rc)
        rc = vxl_program_get(&r->gpu, VXL_PROG_SLICE_PLANE, filter,
                             interp | r->storage.ops->sample_flags(&r->storage) | colour_flags, &prog);
    if (rc) return rc;
    gl->GetError();
    rc = vxl_bind_volume_textures(r, prog, filter, VXL_GRADIENT_STORE_8BIT);
    if (rc) return rc;
    GLuint out = vxl_texture_new(&r->gpu, GL_TEXTURE_2D, GL_NEAREST);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, (GLsizei)f->width, (GLsizei)f->height, 0, GL_RGBA, GL_FLOAT, NULL);
    GLuint table = table_texture(r, f);
    gl->UseProgram(prog);
    gl->BindImageTexture(VXL_IMAGE_OUT, out, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    gl->UniformMatrix4fv(gl->GetUniformLocation(prog, "u_plane_to_voxel"), 1, GL_FALSE, m);
    vxl_uniform_i(&r->gpu, prog, "u_tf", VXL_TF_UNIT);
    vxl_uniform_i(&r->gpu, prog, "u_tf_size", (int)f->tf_size);
    gl->Uniform2f(gl->GetUniformLocation(prog, "u_window"), f->window_offset, f->window_scale);
    vxl_uniform_i(&r->gpu, prog, "u_linear", f->color_space == VXL_COLOR_SPACE_LINEAR);
    vxl_colour_bind(&r->colour, colour_flags, prog);
    gl->DispatchCompute((f->width + 7) / 8, (f->height + 7) / 8, 1);
    gl->MemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    gl->BindTexture(GL_TEXTURE_2D, out);
    gl->PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl->GetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, rgba);
    gl->BindImageTexture(VXL_IMAGE_OUT, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    gl->UseProgram(0);
    gl->DeleteTextures(1, &out);
    gl->DeleteTextures(1, &table);
    return vxl_gl_check(&r->gpu, "resampling the volume on a slice plane");
}

static int job_slice(void *arg)
{
    slice_job *j = arg;
    vxl_renderer *r = j->r;
    if (!r->storage.has_volume) return vxl_fail(&r->gpu.err, VXL_ERR_STATE, "no volume: call vxl_renderer_set_volume first");
    vxl_frame f;
    int rc = slice_frame(&f, j->p, &r->storage.geom, &r->gpu.err);
    if (rc) return rc;
    float m[16];
    rc = plane_to_voxel(&f, j->s.plane_to_world, m, &r->gpu.err);
    if (!rc) rc = resample(r, &f, j->s.interpolation, m, j->rgba);
    vxl_frame_free(&f);
    return rc;
}

int vxl_render_slice(vxl_renderer *r, const vxl_render_params *p, const vxl_slice_params *s, float *rgba)
{
    if (!r) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer is NULL");
    if (!s || !rgba) return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "slice params or rgba output buffer is NULL");
    slice_job j = {r, p, {0}, rgba};
    /* an older caller's struct ends early: only its bytes are read, the rest stays zero */
    size_t n = s->struct_size == 0 || s->struct_size > sizeof j.s ? sizeof j.s : s->struct_size;
    if (n < offsetof(vxl_slice_params, plane_to_world) + sizeof s->plane_to_world) {
        int rc = vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "slice params struct_size %u is too small (%zu bytes)",
                          s->struct_size, sizeof j.s);
        vxl_publish_error(&r->gpu.err);
        return rc;
    }
    memcpy(&j.s, s, n);
    if (j.s.interpolation >= VXL_INTERP_COUNT) {
        int rc = vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "unknown slice interpolation %u (nearest 0, linear 1, cubic 2)",
                          j.s.interpolation);
        vxl_publish_error(&r->gpu.err);
        return rc;
    }
    int rc = vxl_gl_thread_call(&r->thread, job_slice, &j);
    if (rc) vxl_publish_error(&r->gpu.err);
    return rc;
}
