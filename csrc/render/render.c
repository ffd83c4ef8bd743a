/* render.c - one frame of the ray caster: resolve parameters, bind state,
 * draw a full-screen triangle into a float framebuffer, read it back. */
#include <math.h>
#include <string.h>

#include "frame.h"
#include "illumination.h"
#include "mat4.h"
#include "path.h"
#include "renderer_internal.h"
#include "slices.h"

static void geom_of(const vxl_renderer *r, vxl_volume_geom *g)
{
    memcpy(g->dims, r->storage.geom.dims, sizeof g->dims);
    memcpy(g->affine, r->storage.geom.affine, sizeof g->affine);
    g->tex_lo = r->storage.geom.tex_lo;
    g->tex_hi = r->storage.geom.tex_hi;
    g->value_min = r->storage.geom.value_min;
    g->value_max = r->storage.geom.value_max;
}

/* (Re)allocates the colour + depth-out attachments when the size changes. */
static int ensure_framebuffer(vxl_renderer *r, uint32_t w, uint32_t h)
{
    vxl_gl *gl = &r->gpu.gl;
    if (r->color_tex && r->fb_w == w && r->fb_h == h) return VXL_OK;
    if (r->color_tex) gl->DeleteTextures(1, &r->color_tex);
    if (r->depth_tex) gl->DeleteTextures(1, &r->depth_tex);
    r->color_tex = vxl_texture_new(&r->gpu, GL_TEXTURE_2D, GL_NEAREST);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, (GLsizei)w, (GLsizei)h, 0, GL_RGBA, GL_FLOAT, NULL);
    r->depth_tex = vxl_texture_new(&r->gpu, GL_TEXTURE_2D, GL_NEAREST);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, (GLsizei)w, (GLsizei)h, 0, GL_RED, GL_FLOAT, NULL);
    gl->BindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, r->color_tex, 0);
    gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, r->depth_tex, 0);
    int rc = vxl_gl_check(&r->gpu, "allocating the framebuffer");
    if (!rc && gl->CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        rc = vxl_fail(&r->gpu.err, VXL_ERR_GL, "the %ux%u float framebuffer is incomplete", w, h);
    if (rc) {
        gl->DeleteTextures(1, &r->color_tex);
        gl->DeleteTextures(1, &r->depth_tex);
        r->color_tex = r->depth_tex = 0;
        r->fb_w = r->fb_h = 0;
        return rc;
    }
    r->fb_w = w;
    r->fb_h = h;
    return VXL_OK;
}

int vxl_bind_volume_textures(vxl_renderer *r, GLuint prog, uint32_t filter, int store)
{
    vxl_gl *gl = &r->gpu.gl;
    const vxl_storage_ops *ops = r->storage.ops;
    if (filter == VXL_FILTER_PRECOMPUTED) {
        if (store < 0 || store > VXL_GRADIENT_STORE_32F)
            return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "unknown gradient_store %d", store);
        int rc = ops->derive(&r->storage, VXL_DERIVED_GRADIENTS, store);
        if (rc) return rc;
        gl->ActiveTexture(GL_TEXTURE0 + VXL_DERIVED_UNIT);
        gl->BindTexture(GL_TEXTURE_3D, r->gradients.tex);
    } else if (filter == VXL_FILTER_CUBIC) {
        int rc = ops->derive(&r->storage, VXL_DERIVED_BSPLINE, 0);
        if (rc) return rc;
        gl->ActiveTexture(GL_TEXTURE0 + VXL_DERIVED_UNIT);
        gl->BindTexture(GL_TEXTURE_3D, r->bspline.tex);
    }
    vxl_storage_bind_sampling(&r->storage, prog);
    vxl_uniform_i(&r->gpu, prog, "u_gradient", VXL_DERIVED_UNIT);
    vxl_uniform_i(&r->gpu, prog, "u_bspline", VXL_DERIVED_UNIT);
    if (filter == VXL_FILTER_PRECOMPUTED) vxl_uniform_f(&r->gpu, prog, "u_gradient_scale", r->gradients.max);
    return VXL_OK;
}

void vxl_upload_tf(vxl_renderer *r, const vxl_frame *f)
{
    vxl_gl *gl = &r->gpu.gl;
    if (!r->tf_tex) r->tf_tex = vxl_texture_new(&r->gpu, GL_TEXTURE_1D, GL_LINEAR);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_TF_UNIT);
    gl->BindTexture(GL_TEXTURE_1D, r->tf_tex);
    gl->TexImage1D(GL_TEXTURE_1D, 0, GL_RGBA32F, (GLsizei)f->tf_size, 0, GL_RGBA, GL_FLOAT, f->tf);
}

static void upload_scene_depth(vxl_renderer *r, const vxl_frame *f)
{
    vxl_gl *gl = &r->gpu.gl;
    if (!r->scene_depth_tex) r->scene_depth_tex = vxl_texture_new(&r->gpu, GL_TEXTURE_2D, GL_NEAREST);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCENE_DEPTH_UNIT);
    gl->BindTexture(GL_TEXTURE_2D, r->scene_depth_tex);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, (GLsizei)f->width, (GLsizei)f->height, 0, GL_RED, GL_FLOAT,
                   f->scene_depth);
}

static void set_frame_uniforms(vxl_renderer *r, GLuint prog, const vxl_frame *f)
{
    vxl_gl *gl = &r->gpu.gl;
#define LOC(name) gl->GetUniformLocation(prog, name)
    gl->UniformMatrix4fv(LOC("u_ray_near"), 1, GL_FALSE, f->ray_near);
    gl->UniformMatrix4fv(LOC("u_ray_far"), 1, GL_FALSE, f->ray_far);
    gl->UniformMatrix4fv(LOC("u_mv"), 1, GL_FALSE, f->mv);
    gl->UniformMatrix3fv(LOC("u_normal_matrix"), 1, GL_FALSE, f->normal);
    gl->Uniform2f(LOC("u_viewport"), (float)f->width, (float)f->height);
    gl->Uniform1f(LOC("u_step"), f->step);
    gl->Uniform1i(LOC("u_max_steps"), f->max_steps);
    gl->Uniform1ui(LOC("u_jitter_seed"), f->seed);
    gl->Uniform1i(LOC("u_jitter"), (int)f->jitter);
    gl->Uniform1f(LOC("u_early_termination"), f->early_termination);
    gl->Uniform1f(LOC("u_depth_threshold"), f->depth_threshold);
    gl->Uniform1i(LOC("u_has_scene_depth"), f->scene_depth != NULL);
    gl->Uniform1i(LOC("u_scene_depth"), VXL_SCENE_DEPTH_UNIT);
    gl->Uniform1i(LOC("u_tf"), VXL_TF_UNIT);
    gl->Uniform1f(LOC("u_tf_size"), (float)f->tf_size);
    gl->Uniform2f(LOC("u_window"), f->window_offset, f->window_scale);
    gl->Uniform1f(LOC("u_opacity_scale"), f->opacity_scale);
    gl->Uniform1f(LOC("u_sample_distance"), f->sample_distance);
    gl->Uniform4fv(LOC("u_material"), 1, f->material);
    gl->Uniform1i(LOC("u_linear"), f->color_space == VXL_COLOR_SPACE_LINEAR);
    gl->Uniform1i(LOC("u_light_count"), f->light_count);
    gl->Uniform4fv(LOC("u_light_pos"), VXL_MAX_LIGHTS, &f->light_pos[0][0]);
    gl->Uniform3fv(LOC("u_light_color"), VXL_MAX_LIGHTS, &f->light_color[0][0]);
#undef LOC
}

/* The pixel rectangle covering the projected volume box, so rays that miss
 * it are never started. Whole viewport when a corner is behind the eye. */
static void screen_bounds(const vxl_renderer *r, const vxl_frame *f, GLint rect[4])
{
    double mv[16], mvp[16];
    vxl_mat4_mul(mv, f->view, f->model);
    vxl_mat4_mul(mvp, f->proj, mv);
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    rect[0] = rect[1] = 0;
    rect[2] = (GLint)f->width;
    rect[3] = (GLint)f->height;
    for (int c = 0; c < 8; c++) {
        double v[4] = {(c & 1) ? r->storage.geom.dims[0] - 0.5 : -0.5, (c & 2) ? r->storage.geom.dims[1] - 0.5 : -0.5,
                       (c & 4) ? r->storage.geom.dims[2] - 0.5 : -0.5, 1}, clip[4];
        vxl_mat4_transform(mvp, v, clip);
        if (!(clip[3] > 1e-12)) return;
        for (int a = 0; a < 2; a++) {
            double ndc = clip[a] / clip[3];
            lo[a] = ndc < lo[a] ? ndc : lo[a];
            hi[a] = ndc > hi[a] ? ndc : hi[a];
        }
    }
    const double size[2] = {f->width, f->height};
    for (int a = 0; a < 2; a++) {
        double p0 = floor((lo[a] * 0.5 + 0.5) * size[a]) - 1, p1 = ceil((hi[a] * 0.5 + 0.5) * size[a]) + 1;
        p0 = p0 < 0 ? 0 : p0 > size[a] ? size[a] : p0;
        p1 = p1 < 0 ? 0 : p1 > size[a] ? size[a] : p1;
        rect[a] = (GLint)p0;
        rect[2 + a] = (GLint)(p1 - p0);
    }
}

typedef struct render_job {
    vxl_renderer *r;
    const vxl_render_params *p;
    float *rgba, *depth;
} render_job;

static int draw(vxl_renderer *r, const vxl_frame *f, float *rgba, float *depth)
{
    vxl_gl *gl = &r->gpu.gl;
    GLuint prog;
    uint32_t flags = (f->shading ? 1u : 0u) | (f->shading && f->reuse ? 2u : 0u) | (f->classify << 2) |
                     (f->gopacity << 4) | r->storage.ops->sample_flags(&r->storage) | (f->shading ? f->shading_model << 8 : 0);
    flags = vxl_modes_flags(f, flags); /* the mode and the MatCap */
    flags |= vxl_cut_flags(f);         /* clip planes, crop box, cutters */
    flags |= vxl_labels_flags(f);      /* the label mode */
    flags |= vxl_overlays_flags(f);    /* the overlay count */
    uint32_t colour_flags;
    int rc = vxl_colour_flags(&r->colour, f, &colour_flags); /* a colour volume's own colour */
    if (rc) return rc;
    flags |= colour_flags;
    uint32_t channel_flags;
    if ((rc = vxl_channels_flags(&r->channels, f, &channel_flags))) return rc; /* a multi-channel volume's channels */
    flags |= channel_flags;
    if (f->shading && f->env.on) flags |= VXL_FLAG_ENVIRONMENT; /* the World's light */
    uint32_t filter = vxl_frame_filter(f);
    const int path = f->shading && f->shading_model == VXL_SHADING_PATH; /* render/path.c's tracer */
    rc = vxl_frame_path_check(f, &r->gpu.err);
    if (!rc) rc = r->storage.ops->check_filter(&r->storage, filter, f->classify);
    if (!rc && f->technique != VXL_TECHNIQUE_RAYCAST) rc = vxl_slices_check(r, f);
    if (!rc)
        rc = vxl_program_get(&r->gpu, path ? VXL_PROG_PATH : f->technique ? VXL_PROG_SLICES : VXL_PROG_RAYCAST, filter,
                             flags, &prog);
    if (!rc) rc = ensure_framebuffer(r, f->width, f->height);
    if (rc) return rc;
    gl->GetError();
    vxl_upload_tf(r, f);
    if (f->scene_depth) upload_scene_depth(r, f);
    /* bricked storage derives its resident set from the skipping grid */
    /* drawn channels skip by their own union map (channels.c), not the scalar's */
    if (((f->skip && !f->channels.on) || path || r->storage.ops->needs_occupancy) &&
        (rc = vxl_skipping_prepare(&r->skipping, f)))
        return rc;
    if ((rc = r->storage.ops->prepare(&r->storage, f))) return rc;
    if ((rc = vxl_classification_prepare(&r->classification, f))) return rc;
    if ((rc = vxl_illumination_prepare(&r->illumination, f))) return rc; /* shadows, occlusion */
    if ((rc = vxl_cut_prepare(&r->cut, f))) return rc; /* the cutter meshes peeled */
    rc = vxl_bind_volume_textures(r, prog, filter, (int)f->store);
    if (rc) return rc;
    set_frame_uniforms(r, prog, f);
    vxl_illumination_bind(&r->illumination, prog, f);
    vxl_cut_bind(&r->cut, prog, f);
    vxl_colour_bind(&r->colour, flags, prog);
    if (path && (rc = vxl_path_bind(&r->path, f, prog))) return rc;
    if ((rc = vxl_labels_prepare(&r->labels, f, prog, r->storage.geom.affine))) return rc;
    if ((rc = vxl_overlays_prepare(&r->overlays, f, prog))) return rc;
    if ((rc = vxl_channels_prepare(&r->channels, f, prog))) return rc;
    if ((rc = vxl_modes_bind(&r->modes, f, prog)) || (rc = vxl_matcap_prepare(&r->matcap, f, prog))) return rc;
    vxl_uniform_i(&r->gpu, prog, "u_skip", f->skip);
    vxl_uniform_i(&r->gpu, prog, "u_brick_size", (int)(r->skipping.bricks.size ? r->skipping.bricks.size : VXL_DEFAULT_BRICK));
    vxl_uniform_i(&r->gpu, prog, "u_brick_distance", VXL_DISTANCE_UNIT);
    vxl_uniform_i(&r->gpu, prog, "u_classified", VXL_CLASSIFIED_UNIT);
    vxl_uniform_i(&r->gpu, prog, "u_preint", VXL_PREINT_UNIT);
    vxl_uniform_f(&r->gpu, prog, "u_preint_size", (float)f->preint_size);
    if (f->gopacity == VXL_GOPACITY_BOUNDARY)
        gl->Uniform2f(gl->GetUniformLocation(prog, "u_gopacity_param"), f->gradient_ref, f->gradient_exp);
    else if (f->gopacity == VXL_GOPACITY_ISO)
        gl->Uniform2f(gl->GetUniformLocation(prog, "u_gopacity_param"), f->iso_pos, f->iso_thickness);
    const GLuint zeros[4] = {0, 0, 0, 0};
    gl->BindBuffer(GL_SHADER_STORAGE_BUFFER, r->gpu.ssbo[2]);
    gl->BufferData(GL_SHADER_STORAGE_BUFFER, sizeof zeros, zeros, GL_DYNAMIC_READ);
    gl->BindBufferBase(GL_SHADER_STORAGE_BUFFER, VXL_SSBO_STATS, r->gpu.ssbo[2]);
    gl->BindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    gl->DrawBuffers(2, bufs);
    gl->Viewport(0, 0, (GLsizei)f->width, (GLsizei)f->height);
    gl->Disable(GL_DEPTH_TEST);
    gl->Disable(GL_BLEND);
    gl->Disable(GL_SCISSOR_TEST);
    const float clear_color[4] = {0, 0, 0, 0}, clear_depth[4] = {INFINITY, 0, 0, 0};
    gl->ClearBufferfv(GL_COLOR, 0, clear_color);
    gl->ClearBufferfv(GL_COLOR, 1, clear_depth);
    GLint rect[4] = {0, 0, (GLint)f->width, (GLint)f->height};
    if (f->skip && !f->overlays.count) screen_bounds(r, f, rect); /* overlays: rays test the union of the boxes */
    gl->Enable(GL_SCISSOR_TEST);
    gl->Scissor(rect[0], rect[1], rect[2], rect[3]);
    gl->BindVertexArray(r->vao);
    if (f->technique == VXL_TECHNIQUE_RAYCAST)
        gl->DrawArrays(GL_TRIANGLES, 0, 3);
    else
        rc = vxl_slices_draw(r, f, prog); /* the same state, proxy polygons instead of one triangle */
    gl->Disable(GL_SCISSOR_TEST);
    if (rc) return rc;
    gl->ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl->ReadPixels(0, 0, (GLsizei)f->width, (GLsizei)f->height, GL_RGBA, GL_FLOAT, rgba);
    if (depth) {
        gl->ReadBuffer(GL_COLOR_ATTACHMENT1);
        gl->ReadPixels(0, 0, (GLsizei)f->width, (GLsizei)f->height, GL_RED, GL_FLOAT, depth);
    }
    gl->BindVertexArray(0);
    gl->UseProgram(0);
    GLuint counts[4];
    gl->MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    gl->GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof counts, counts);
    int rc2 = vxl_gl_check(&r->gpu, "rendering");
    if (rc2) return rc2;
    memset(&r->stats, 0, sizeof r->stats);
    r->stats.struct_size = sizeof r->stats;
    r->stats.sample_bound = (uint32_t)f->max_steps;
    r->stats.samples = (uint64_t)counts[1] << 32 | counts[0];
    r->stats.max_ray_samples = counts[2];
    r->stats.rays = counts[3];
    r->stats.effective_step = f->step;
    if (f->skip) {
        r->stats.bricks_total = r->skipping.bricks.dims[0] * r->skipping.bricks.dims[1] * r->skipping.bricks.dims[2];
        r->stats.bricks_occupied = r->skipping.bricks.occupied;
        r->stats.brick_size = r->skipping.bricks.size;
        if (f->channels.on) { /* the drawn channels' union */
            r->stats.bricks_total = r->channels.bricks_total;
            r->stats.bricks_occupied = r->channels.occupied;
            r->stats.brick_size = r->channels.bricks[0].size;
        }
    }
    r->stats.storage = r->storage.mode;
    r->stats.resident_bytes = r->storage.ops->resident_bytes(&r->storage);
    r->stats.channel_bytes = r->channels.volume_bytes;
    r->storage.ops->report(&r->storage, &r->stats);
    vxl_illumination_report(&r->illumination, &r->stats);
    return VXL_OK;
}

static int job_render(void *p)
{
    render_job *j = p;
    vxl_renderer *r = j->r;
    if (!r->storage.has_volume) return vxl_fail(&r->gpu.err, VXL_ERR_STATE, "no volume: call vxl_renderer_set_volume first");
    vxl_volume_geom g;
    geom_of(r, &g);
    vxl_frame f;
    int rc = vxl_frame_resolve(&f, j->p, &g, &r->gpu.err);
    if (rc) return rc;
    const vxl_volume_geom *ov_geoms[VXL_MAX_OVERLAYS];
    vxl_overlays_geoms(&r->overlays, ov_geoms);
    rc = vxl_frame_resolve_overlays(&f, j->p, ov_geoms, &g, &r->gpu.err);
    if (!rc) rc = vxl_frame_resolve_channels(&f, j->p, r->channels.geom, r->channels.count, &r->gpu.err);
    if (!rc) rc = draw(r, &f, j->rgba, j->depth);
    vxl_frame_free(&f);
    return rc;
}

int vxl_render(vxl_renderer *r, const vxl_render_params *p, float *rgba, float *depth)
{
    if (!r) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer is NULL");
    if (!rgba) return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "rgba output buffer is NULL");
    render_job j = {r, p, rgba, depth};
    int rc = vxl_gl_thread_call(&r->thread, job_render, &j);
    if (rc) vxl_publish_error(&r->gpu.err);
    return rc;
}

typedef struct camera_job {
    vxl_renderer *r;
    const vxl_render_params *p;
    float *view, *proj;
} camera_job;

static int job_camera(void *p)
{
    camera_job *j = p;
    vxl_renderer *r = j->r;
    if (!r->storage.has_volume) return vxl_fail(&r->gpu.err, VXL_ERR_STATE, "no volume: call vxl_renderer_set_volume first");
    vxl_volume_geom g;
    geom_of(r, &g);
    vxl_render_params q; /* read up to the caller's struct_size, never past */
    int rc = vxl_render_params_read(&q, j->p, &r->gpu.err);
    if (rc) return rc;
    q.struct_size = sizeof q;
    q.has_camera = 0;
    vxl_frame f;
    rc = vxl_frame_resolve(&f, &q, &g, &r->gpu.err);
    if (rc) return rc;
    for (int i = 0; i < 16; i++) {
        j->view[i] = (float)f.view[i];
        j->proj[i] = (float)f.proj[i];
    }
    vxl_frame_free(&f);
    return VXL_OK;
}

int vxl_default_camera(vxl_renderer *r, const vxl_render_params *p, float view[16], float proj[16])
{
    if (!r || !view || !proj) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer or matrix is NULL");
    camera_job j = {r, p, view, proj};
    int rc = vxl_gl_thread_call(&r->thread, job_camera, &j);
    if (rc) vxl_publish_error(&r->gpu.err);
    return rc;
}
