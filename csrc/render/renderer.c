/* renderer.c - renderer lifecycle and volume upload. Every GL call runs on
 * the renderer's thread through vxl_gl_thread_call. */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"
#include "volume.h"

typedef struct open_job {
    vxl_renderer *r;
    uint32_t backend;
} open_job;

static vxl_gl_proc get_proc(void *user, const char *name)
{
    vxl_context *c = user;
    return (vxl_gl_proc)c->get_proc(c, name);
}

static void copy_gl_string(vxl_renderer *r, GLenum what, char *dst, size_t n)
{
    const GLubyte *s = r->gpu.gl.GetString(what);
    strncpy(dst, s ? (const char *)s : "", n - 1);
    dst[n - 1] = '\0';
}

static int job_open(void *p)
{
    open_job *j = p;
    vxl_renderer *r = j->r;
    int rc = vxl_context_open(&r->ctx, j->backend, &r->gpu.err);
    if (rc) return rc;
    const char *missing = vxl_gl_load(&r->gpu.gl, get_proc, &r->ctx);
    if (missing) {
        vxl_context_close(&r->ctx);
        return vxl_fail(&r->gpu.err, VXL_ERR_BACKEND, "%s: OpenGL entry point %s is missing", r->ctx.name, missing);
    }
    r->gpu.info.struct_size = sizeof r->gpu.info;
    r->gpu.info.backend = r->ctx.backend;
    snprintf(r->gpu.info.backend_name, sizeof r->gpu.info.backend_name, "%s", r->ctx.name);
    copy_gl_string(r, GL_RENDERER, r->gpu.info.gl_renderer, sizeof r->gpu.info.gl_renderer);
    /* before any call that maps a resource: llvmpipe contexts of one screen take turns */
    vxl_gl_thread_hold(&r->thread, vxl_context_screen_lock(vxl_context_screen_kind(r->ctx.name, r->gpu.info.gl_renderer)));
    copy_gl_string(r, GL_VERSION, r->gpu.info.gl_version, sizeof r->gpu.info.gl_version);
    r->gpu.gl.GetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &r->gpu.info.max_3d_texture_size);
    r->gpu.gl.GenVertexArrays(1, &r->vao);
    r->gpu.gl.GenFramebuffers(1, &r->fbo);
    r->gpu.gl.GenBuffers(3, r->gpu.ssbo);
    r->gpu.gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    r->gpu.gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    return vxl_gl_check(&r->gpu, "creating the renderer");
}

static void delete_texture(vxl_renderer *r, GLuint *t)
{
    if (*t) r->gpu.gl.DeleteTextures(1, t);
    *t = 0;
}

/* Everything derived from the volume, and the volume itself, goes. */
static void release_volume(vxl_renderer *r)
{
    vxl_gradients_forget_volume(&r->gradients);
    vxl_bspline_release(&r->bspline);
    vxl_skipping_release(&r->skipping);
    vxl_classification_release(&r->classification);
    vxl_illumination_release(&r->illumination);
    vxl_modes_release(&r->modes);
    vxl_path_release(&r->path);
    vxl_colour_release(&r->colour);
    vxl_channels_release(&r->channels);
    if (r->storage.ops) r->storage.ops->release(&r->storage);
    r->storage.ops = NULL;
    r->storage.mode = 0;
}

static int job_close(void *p)
{
    vxl_renderer *r = p;
    if (r->ctx.close) {
        release_volume(r);
        delete_texture(r, &r->color_tex);
        delete_texture(r, &r->depth_tex);
        delete_texture(r, &r->scene_depth_tex);
        delete_texture(r, &r->tf_tex);
        vxl_matcap_release(&r->matcap);
        vxl_cut_release(&r->cut); /* the cutter layers */
        vxl_labels_release(&r->labels);
        vxl_overlays_release(&r->overlays);
        vxl_programs_delete(&r->gpu);
        r->gpu.gl.DeleteFramebuffers(1, &r->fbo);
        r->gpu.gl.DeleteVertexArrays(1, &r->vao);
        r->gpu.gl.DeleteBuffers(3, r->gpu.ssbo);
        r->gpu.gl.Finish();
    }
    vxl_context_close(&r->ctx);
    return VXL_OK;
}

/* The label volume on an illumination program (light/ may not include
 * labels/): its extinction then leaves hidden labels out. */
static int bind_labels_for_shadows(void *ctx, const vxl_frame *f, GLuint prog)
{
    vxl_renderer *r = ctx;
    return vxl_labels_prepare(&r->labels, f, prog, r->storage.geom.affine);
}

int vxl_renderer_create(const vxl_renderer_options *opt, vxl_renderer **out)
{
    if (!out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    vxl_renderer *r = calloc(1, sizeof *r);
    if (!r) return vxl_fail(NULL, VXL_ERR_NO_MEMORY, "out of memory for the renderer");
    /* each subsystem gets the GL services and the storage it derives from */
    vxl_storage_init(&r->storage, &r->gpu);
    vxl_gradients_init(&r->gradients, &r->gpu, &r->storage);
    vxl_bspline_init(&r->bspline, &r->gpu, &r->storage);
    vxl_skipping_init(&r->skipping, &r->gpu, &r->storage);
    vxl_classification_init(&r->classification, &r->gpu, &r->storage);
    vxl_illumination_init(&r->illumination, &r->gpu, &r->storage);
    vxl_cut_init(&r->cut, &r->gpu); /* cutaways */
    vxl_modes_init(&r->modes, &r->gpu, &r->skipping, &r->storage);
    vxl_path_init(&r->path, &r->gpu, &r->skipping, &r->storage);
    vxl_matcap_init(&r->matcap, &r->gpu);
    vxl_labels_init(&r->labels, &r->gpu); /* label maps */
    r->illumination.bind_labels = bind_labels_for_shadows; /* hidden labels cast no shadow */
    r->illumination.labels_ctx = r;
    vxl_overlays_init(&r->overlays, &r->gpu); /* overlays */
    vxl_colour_init(&r->colour, &r->gpu); /* colour volumes */
    vxl_channels_init(&r->channels, &r->gpu, &r->storage); /* multi-channel volumes */
    r->gpu.budget = (opt && opt->memory_budget_bytes) ? opt->memory_budget_bytes : VXL_DEFAULT_BUDGET;
    if (opt && opt->struct_size >= offsetof(vxl_renderer_options, page_brick) + sizeof opt->page_brick) {
        if (opt->storage >= VXL_STORAGE_COUNT) {
            free(r);
            return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "unknown storage %u", opt->storage);
        }
        r->storage.request = opt->storage;
        r->storage.page_brick_request = opt->page_brick;
    }
    if (opt && opt->struct_size >= offsetof(vxl_renderer_options, compressed_domain) + sizeof opt->compressed_domain)
        r->storage.compressed_domain = opt->compressed_domain != 0;
    const char *dir = (opt && opt->shader_dir) ? opt->shader_dir : getenv("VOXLIGHT_SHADER_DIR");
    if (dir && *dir && !(r->gpu.shader_dir = strdup(dir))) {
        free(r);
        return vxl_fail(NULL, VXL_ERR_NO_MEMORY, "out of memory");
    }
    if (vxl_gl_thread_start(&r->thread)) {
        free(r->gpu.shader_dir);
        free(r);
        return vxl_fail(NULL, VXL_ERR_NO_MEMORY, "cannot start the renderer's GL thread");
    }
    open_job j = {r, opt ? opt->backend : VXL_BACKEND_AUTO};
    int rc = vxl_gl_thread_call(&r->thread, job_open, &j);
    if (rc) {
        vxl_err copy = r->gpu.err;
        vxl_gl_thread_stop(&r->thread, job_close, r);
        free(r->gpu.shader_dir);
        free(r);
        return vxl_fail(NULL, rc, "%s", copy.msg);
    }
    *out = r;
    return VXL_OK;
}

void vxl_renderer_destroy(vxl_renderer *r)
{
    if (!r) return;
    vxl_gl_thread_stop(&r->thread, job_close, r);
    free(r->gpu.shader_dir);
    free(r);
}

typedef struct stats_job {
    vxl_renderer *r;
    vxl_render_stats *out;
} stats_job;

/* Copies an output struct (src, size bytes, struct_size first) to the
 * caller's: one built against an older header is shorter, so only what its
 * struct_size covers is written (0: the whole of this header's). */
static void copy_to_caller(void *out, const void *src, size_t size)
{
    uint32_t asked;
    memcpy(&asked, out, sizeof asked);
    memcpy(out, src, asked && asked < size ? asked : size);
    if (asked) memcpy(out, &asked, sizeof asked);
}

static int job_stats(void *p)
{
    stats_job *j = p;
    copy_to_caller(j->out, &j->r->stats, sizeof j->r->stats);
    return VXL_OK;
}

int vxl_renderer_get_stats(vxl_renderer *r, vxl_render_stats *out)
{
    if (!r || !out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer or stats is NULL");
    stats_job j = {r, out};
    return vxl_gl_thread_call(&r->thread, job_stats, &j);
}

const char *vxl_renderer_error(const vxl_renderer *r) { return r ? r->gpu.err.msg : ""; }

int vxl_renderer_get_info(vxl_renderer *r, vxl_renderer_info *out)
{
    if (!r || !out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer or info is NULL");
    copy_to_caller(out, &r->gpu.info, sizeof r->gpu.info); /* written once by job_open, read-only afterwards */
    return VXL_OK;
}

typedef struct volume_job {
    vxl_renderer *r;
    const vxl_volume *v;
} volume_job;

static int job_set_volume(void *p)
{
    volume_job *j = p;
    vxl_renderer *r = j->r;
    const vxl_volume *v = j->v;
    const uint32_t asked = vxl_storage_choose(&r->storage, v);
    vxl_storage_plan plan;
    /* refuse before anything is released: a failed set_volume loses nothing.
     * A colour volume's colour is charged with the texture dense storage
     * would take (the paged modes ask for their pools themselves). */
    const int dense = !v->source && (asked == VXL_STORAGE_DENSE || asked == VXL_STORAGE_AUTO);
    int rc = vxl_colour_plan(&r->colour, v, dense ? v->storage_bytes : 0);
    if (rc) return rc;
    rc = vxl_storage_ops_for_volume(v, asked)->plan(&r->storage, v, asked, &plan);
    if (rc) return rc;
    /* a multi-channel volume's channels, stored as the plan stores the scalar, within the budget */
    vxl_channel_plan channel_plan;
    if ((rc = vxl_channels_plan(&r->channels, v, &plan, &channel_plan))) {
        vxl_storage_plan_free(&plan);
        return rc;
    }
    const vxl_storage_ops *ops = vxl_storage_ops_for_volume(v, plan.mode);
    release_volume(r); /* the data changed */
    r->storage.has_volume = 0;
    r->storage.ops = ops;
    rc = ops->install(&r->storage, v, &plan);
    if (!rc) rc = vxl_colour_set(&r->colour, v);
    if (!rc) rc = vxl_channels_set(&r->channels, v, &channel_plan);
    vxl_channel_plan_free(&channel_plan);
    if (rc) {
        vxl_bricks_free(&plan.bricks);
        ops->release(&r->storage);
        r->storage.ops = NULL;
        r->storage.mode = 0;
        return rc;
    }
    vxl_skipping_adopt(&r->skipping, &plan.bricks, v->texture_bits); /* the min-max grid the plan computed, if any */
    r->storage.geom = vxl_volume_geom_of(v);
    r->storage.has_volume = 1;
    return VXL_OK;
}

int vxl_renderer_set_volume(vxl_renderer *r, const vxl_volume *v)
{
    if (!r || !v) return vxl_fail(r ? &r->gpu.err : NULL, VXL_ERR_INVALID_ARGUMENT, "renderer or volume is NULL");
    volume_job j = {r, v};
    int rc = vxl_gl_thread_call(&r->thread, job_set_volume, &j);
    if (rc) vxl_publish_error(&r->gpu.err);
    return rc;
}
