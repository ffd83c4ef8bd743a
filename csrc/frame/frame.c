/* frame.c - resolves vxl_render_params into a vxl_frame. */
#include "frame.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hash.h"
#include "mat4.h"
#include "srgb.h"
#include "volume.h"

#define DEFAULT_STEP 0.5f
#define DEFAULT_SAMPLE_DISTANCE 1.0f
#define MAX_STEP 1000.0f
#define MAX_SAMPLES_PER_RAY 16384
#define MAX_TF_SIZE 4096

static const float default_material[4] = {0.3f, 0.7f, 0.3f, 24.0f};

vxl_volume_geom vxl_volume_geom_of(const vxl_volume *v)
{
    vxl_volume_geom g;
    memcpy(g.dims, v->dims, sizeof g.dims);
    memcpy(g.affine, v->affine, sizeof g.affine);
    g.tex_lo = v->tex_lo;
    g.tex_hi = v->tex_hi;
    g.value_min = v->value_min;
    g.value_max = v->value_max;
    return g;
}

void vxl_frame_classify(const vxl_frame *f, double vn, double out[4])
{
    double x = (vn - f->window_offset) * f->window_scale;
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    double u = x * (f->tf_size - 1);
    uint32_t i0 = (uint32_t)floor(u);
    if (i0 > f->tf_size - 1) i0 = f->tf_size - 1;
    uint32_t i1 = i0 + 1 < f->tf_size ? i0 + 1 : i0;
    double w = u - i0;
    for (int k = 0; k < 4; k++) out[k] = f->tf[4 * i0 + k] * (1 - w) + f->tf[4 * i1 + k] * w;
    double a = out[3] * f->opacity_scale;
    out[3] = a < 0 ? 0 : a > 1 ? 1 : a;
}

static void world_bounds(const vxl_volume_geom *g, double center[3], double *radius)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int c = 0; c < 8; c++) {
        double v[4] = {(c & 1) ? g->dims[0] - 0.5 : -0.5, (c & 2) ? g->dims[1] - 0.5 : -0.5,
                       (c & 4) ? g->dims[2] - 0.5 : -0.5, 1.0}, w[4];
        vxl_mat4_transform(g->affine, v, w);
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], w[a]);
            hi[a] = fmax(hi[a], w[a]);
        }
    }
    double r2 = 0;
    for (int a = 0; a < 3; a++) {
        center[a] = 0.5 * (lo[a] + hi[a]);
        r2 += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    *radius = sqrt(r2) > 0 ? sqrt(r2) : 1.0;
}

void vxl_frame_default_camera(const vxl_volume_geom *g, uint32_t w, uint32_t h, double az_deg, double el_deg,
                              double view[16], double proj[16])
{
    double c[3], radius;
    world_bounds(g, c, &radius);
    const double fovy = 30.0 * M_PI / 180.0;
    double aspect = (double)w / (double)h;
    /* fit the bounding sphere in the narrower of the two fields of view */
    double half = fovy / 2;
    if (aspect < 1) half = atan(tan(half) * aspect);
    double dist = radius / sin(half) * 1.02;
    double az = az_deg * M_PI / 180.0, el = el_deg * M_PI / 180.0;
    /* azimuth 0, elevation 0 looks from +Y (anterior in RAS) towards -Y */
    double eye[3] = {c[0] - dist * cos(el) * sin(az), c[1] + dist * cos(el) * cos(az), c[2] + dist * sin(el)};
    double up[3] = {0, 0, 1};
    if (fabs(cos(el)) < 1e-6) {
        up[1] = -sin(el) * cos(az);
        up[0] = sin(el) * sin(az);
        up[2] = 0;
    }
    vxl_mat4_look_at(view, eye, c, up);
    vxl_mat4_perspective(proj, fovy, aspect, fmax(dist - radius * 1.5, dist * 1e-3), dist + radius * 1.5);
}

static int check_float(vxl_err *e, const char *name, float v, float lo, float hi)
{
    if (!(v >= lo && v <= hi))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "%s = %g is out of range [%g, %g]", name, v, lo, hi);
    return VXL_OK;
}

int vxl_frame_resolve_tf(vxl_frame *f, const vxl_render_params *p, const vxl_volume_geom *g, vxl_err *e)
{
    uint32_t preset = vxl_preset_resolve(p->preset, g->value_min, g->value_max);
    if (p->tf_rgba) {
        if (p->tf_size < 2 || p->tf_size > 65536)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "tf_size %u must be in [2, 65536]", p->tf_size);
        /* 1D textures are limited (16384 on llvmpipe): longer tables are
         * resampled, exactly as GL_LINEAR would read them, to MAX_TF_SIZE. */
        uint32_t n = p->tf_size > MAX_TF_SIZE ? MAX_TF_SIZE : p->tf_size;
        f->tf_copy = malloc((size_t)n * 4 * sizeof(float));
        if (!f->tf_copy) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the transfer function");
        for (uint32_t i = 0; i < n; i++) {
            double u = n == p->tf_size ? i : i * (double)(p->tf_size - 1) / (n - 1);
            uint32_t i0 = (uint32_t)u, i1 = i0 + 1 < p->tf_size ? i0 + 1 : i0;
            double w = u - i0;
            for (int c = 0; c < 4; c++) {
                double v = p->tf_rgba[4 * i0 + c] * (1 - w) + p->tf_rgba[4 * i1 + c] * w;
                f->tf_copy[4 * i + c] = v > 0 ? (float)(v < 1 ? v : 1) : 0.0f; /* also maps NaN to 0 */
            }
        }
        f->tf = f->tf_copy;
        f->tf_size = n;
    } else {
        if (!vxl_preset_table(preset, f->preset_tf))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown preset %u", p->preset);
        /* the presets' colours are display-referred */
        if (p->color_space == VXL_COLOR_SPACE_LINEAR)
            for (uint32_t i = 0; i < VXL_PRESET_TABLE_SIZE; i++)
                for (int c = 0; c < 3; c++)
                    f->preset_tf[4 * i + c] = (float)vxl_srgb_to_linear(f->preset_tf[4 * i + c]);
        f->tf = f->preset_tf;
        f->tf_size = VXL_PRESET_TABLE_SIZE;
    }
    double lo, hi;
    if (p->has_window) {
        lo = p->window_low;
        hi = p->window_high;
        if (!isfinite(lo) || !isfinite(hi))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "window [%g, %g] is not finite", lo, hi);
    } else {
        vxl_preset_window(preset, g->value_min, g->value_max, &lo, &hi);
    }
    /* an empty window becomes a step at lo instead of a division by zero */
    /* relative, so denormal-scaled data keeps its own window */
    double w = hi - lo, eps = fmax(fabs(lo), fabs(hi)) * 1e-6;
    if (!(eps > 0)) eps = 1e-300;
    if (fabs(w) < eps) w = eps;
    double span = g->tex_hi - g->tex_lo;
    if (span == 0) span = 1;
    /* extreme windows over denormal-scaled data must stay finite in float */
    double offset = (lo - g->tex_lo) / span;
    f->window_offset = (float)(fabs(offset) < 1e30 ? offset : copysign(1e30, offset));
    double scale = span / w;
    f->window_scale = (float)(fabs(scale) < 1e30 ? scale : copysign(1e30, scale));
    float os = p->opacity_scale == 0 ? 1.0f : p->opacity_scale;
    int rc = check_float(e, "opacity_scale", os, 0, 1e6);
    f->opacity_scale = os;
    return rc;
}

int vxl_frame_resolve_table(vxl_frame_table *t, const vxl_render_params *q, const vxl_volume_geom *g, const char *what,
                            uint32_t index, vxl_err *e)
{
    vxl_frame *tmp = calloc(1, sizeof *tmp);
    if (!tmp) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory resolving %s %u", what, index);
    int rc = vxl_frame_resolve_tf(tmp, q, g, e);
    if (rc) {
        vxl_frame_free(tmp);
        free(tmp);
        char why[VXL_MSG_MAX];
        snprintf(why, sizeof why, "%s", e ? e->msg : "");
        return vxl_fail(e, rc, "%s[%u]: %s", what, index, why);
    }
    t->tf_size = tmp->tf_size;
    if (tmp->tf_copy) {
        t->tf_copy = tmp->tf_copy; /* ownership moves to the side volume's table */
        tmp->tf_copy = NULL;
        t->tf = t->tf_copy;
    } else {
        memcpy(t->preset_tf, tmp->preset_tf, sizeof t->preset_tf);
        t->tf = t->preset_tf;
    }
    t->window_offset = tmp->window_offset;
    t->window_scale = tmp->window_scale;
    t->opacity_scale = tmp->opacity_scale;
    tmp->tf = t->tf; /* the key reads the table where the side volume keeps it */
    t->key = vxl_classification_key(tmp);
    free(tmp);
    return VXL_OK;
}

static int resolve_lights(vxl_frame *f, const vxl_render_params *p, vxl_err *e)
{
    if (p->has_material) {
        int rc = check_float(e, "ambient", p->ambient, 0, 100);
        if (!rc) rc = check_float(e, "diffuse", p->diffuse, 0, 100);
        if (!rc) rc = check_float(e, "specular", p->specular, 0, 100);
        if (!rc) rc = check_float(e, "shininess", p->shininess, 0, 1e4);
        if (rc) return rc;
        f->material[0] = p->ambient;
        f->material[1] = p->diffuse;
        f->material[2] = p->specular;
        f->material[3] = p->shininess < 1 ? 1 : p->shininess; /* pow(0, 0) is undefined */
    } else {
        memcpy(f->material, default_material, sizeof f->material);
    }
    if (p->light_count > VXL_MAX_LIGHTS)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light_count %u exceeds %d", p->light_count, VXL_MAX_LIGHTS);
    if (p->light_count == 0 && f->env.on) return VXL_OK; /* the World lights it alone: no lamps */
    if (p->light_count == 0) { /* headlight: from the eye, in view space */
        f->light_count = 1;
        f->light_pos[0][2] = 1;
        f->light_color[0][0] = f->light_color[0][1] = f->light_color[0][2] = 1;
        return VXL_OK;
    }
    f->light_count = (int)p->light_count;
    for (uint32_t i = 0; i < p->light_count; i++) {
        const vxl_light *l = &p->lights[i];
        double in[4] = {l->position[0], l->position[1], l->position[2], l->position[3] != 0 ? 1.0 : 0.0}, v[4];
        for (int k = 0; k < 4; k++)
            if (!isfinite(in[k])) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light %u position is not finite", i);
        vxl_mat4_transform(f->view, in, v);
        if (in[3] == 0) {
            double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (!(n > 0)) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light %u direction is zero", i);
            for (int k = 0; k < 3; k++) v[k] /= n;
        }
        for (int k = 0; k < 3; k++) f->light_pos[i][k] = (float)v[k];
        f->light_pos[i][3] = (float)in[3];
        int white = l->color[0] == 0 && l->color[1] == 0 && l->color[2] == 0;
        float inten = l->intensity == 0 ? 1.0f : l->intensity;
        int rc = check_float(e, "light intensity", inten, 0, 1e6);
        if (rc) return rc;
        for (int k = 0; k < 3; k++) {
            float c = white ? 1.0f : l->color[k];
            if (!(c >= 0 && c <= 1e6)) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light %u colour is invalid", i);
            f->light_color[i][k] = c * inten;
        }
    }
    return VXL_OK;
}

static int resolve_matrices(vxl_frame *f, const vxl_render_params *p, const vxl_volume_geom *g, vxl_err *e)
{
    if (p->has_model) vxl_mat4_from_float(f->model, p->model);
    else memcpy(f->model, g->affine, sizeof f->model);
    if (p->has_camera) {
        vxl_mat4_from_float(f->view, p->view);
        vxl_mat4_from_float(f->proj, p->proj);
    } else {
        if (!isfinite(p->azimuth_deg) || !isfinite(p->elevation_deg))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "azimuth/elevation are not finite");
        vxl_volume_geom gm = *g;
        memcpy(gm.affine, f->model, sizeof gm.affine);
        vxl_frame_default_camera(&gm, f->width, f->height, p->azimuth_deg, p->elevation_deg, f->view, f->proj);
    }
    double mv[16], mvp[16], inv[16];
    vxl_mat4_mul(mv, f->view, f->model);
    vxl_mat4_mul(mvp, f->proj, mv);
    if (!vxl_mat4_is_finite(mv) || !vxl_mat4_invert(inv, mvp))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "the camera and model matrices are singular or not finite (projection * view * model)");
    if (!vxl_mat3_normal_matrix(f->normal, mv))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "the view * model matrix is singular");
    double rn[16], rf[16];
    memcpy(rn, inv, sizeof rn);
    memcpy(rf, inv, sizeof rf);
    for (int r = 0; r < 4; r++) {
        rn[12 + r] = inv[12 + r] - inv[8 + r]; /* ndc z = -1 */
        rf[12 + r] = inv[12 + r] + inv[8 + r]; /* ndc z = +1 */
        rn[8 + r] = rf[8 + r] = 0;
    }
    vxl_mat4_to_float(f->ray_near, rn);
    vxl_mat4_to_float(f->ray_far, rf);
    vxl_mat4_to_float(f->mv, mv);
    return VXL_OK;
}

/* Every release of ABI 1 before the reserved room grew had this size (fields
 * were taken from reserved[] until one word was left): the oldest layout a
 * caller can have compiled against. */
#define RENDER_PARAMS_OLDEST_SIZE (offsetof(vxl_render_params, shading_model) + sizeof(uint32_t))

int vxl_render_params_read(vxl_render_params *q, const vxl_render_params *p, vxl_err *e)
{
    memset(q, 0, sizeof *q);
    if (!p) return VXL_OK;
    if (p->struct_size != 0 && p->struct_size < RENDER_PARAMS_OLDEST_SIZE)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "render params struct_size %u is smaller than the oldest layout (%zu bytes)", p->struct_size,
                        RENDER_PARAMS_OLDEST_SIZE);
    /* An older caller's struct ends early: only its bytes are read, the rest
     * stays zero (every field's default). A newer caller's extra bytes are
     * not looked at. */
    size_t n = p->struct_size == 0 || p->struct_size > sizeof *q ? sizeof *q : p->struct_size;
    memcpy(q, p, n);
    for (uint32_t i = 0; i < VXL_RENDER_PARAMS_RESERVED; i++)
        if (q->reserved[i])
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                            "render params reserved[%u] is %u: it must be 0 (kept for future fields)", i,
                            q->reserved[i]);
    return VXL_OK;
}

int vxl_frame_resolve(vxl_frame *f, const vxl_render_params *pin, const vxl_volume_geom *g, vxl_err *e)
{
    memset(f, 0, sizeof *f);
    vxl_render_params params;
    int rc = vxl_render_params_read(&params, pin, e);
    if (rc) return rc;
    const vxl_render_params *p = &params;
    f->width = p->width ? p->width : 512;
    f->height = p->height ? p->height : 512;
    if (f->width > 16384 || f->height > 16384)
        return vxl_fail(e, VXL_ERR_LIMIT, "image %ux%u exceeds 16384 per side", f->width, f->height);
    if (p->filter >= VXL_FILTER_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown filter %u", p->filter);
    if (p->gradient_store > VXL_GRADIENT_STORE_32F)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown gradient_store %u", p->gradient_store);
    if (p->classify >= VXL_CLASSIFY_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown classify mode %u", p->classify);
    f->filter = p->filter;
    f->classify = p->classify;
    f->gopacity = p->gradient_opacity;
    if (f->gopacity >= VXL_GOPACITY_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown gradient_opacity mode %u", f->gopacity);
    if (p->technique >= VXL_TECHNIQUE_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown technique %u (0 raycast, 1 slices2d, 2 slices3d)",
                        p->technique);
    f->technique = p->technique;
    if (p->color_source >= VXL_COLOR_SOURCE_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown color_source %u (0 auto, 1 data, 2 tf)", p->color_source);
    if (p->color_space >= VXL_COLOR_SPACE_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown color_space %u (0 display, 1 linear)", p->color_space);
    f->color_source = p->color_source;
    f->color_space = p->color_space;
    rc = vxl_frame_resolve_mode(f, p, e); /* mode, iso_value, MatCap */
    if (rc) return rc;
    f->gradient_ref = p->gradient_ref == 0 ? 0.05f : p->gradient_ref;
    f->gradient_exp = p->gradient_exp == 0 ? 1.0f : p->gradient_exp;
    f->iso_thickness = p->iso_thickness == 0 ? 1.0f : p->iso_thickness;
    if (!(f->gradient_ref > 0 && f->gradient_ref < 1e6) || !(f->gradient_exp > 0 && f->gradient_exp <= 64) ||
        !(f->iso_thickness > 0 && f->iso_thickness <= 1000) || !isfinite(p->iso_value))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "gradient opacity parameters out of range");
    {
        double span = g->tex_hi - g->tex_lo;
        f->iso_pos = (float)((p->iso_value - g->tex_lo) / (span != 0 ? span : 1));
        if (p->minip_floor_on && p->mode == VXL_MODE_MINIP) {
            if (!isfinite(p->minip_floor))
                return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "minip_floor = %g is not a finite number",
                                (double)p->minip_floor);
            f->minip_floor_on = 1;
            f->minip_floor_pos = (float)((p->minip_floor - g->tex_lo) / (span != 0 ? span : 1));
        }
    }
    f->preint_size = p->preint_size ? p->preint_size : 256;
    if (f->preint_size < 16 || f->preint_size > 4096)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "preint_size %u must be in [16, 4096]", f->preint_size);
    f->store = p->gradient_store;
    f->shading = !p->shading_off && vxl_mode_shades(f->mode); /* projections have no surface */
    f->reuse = p->reuse_gradients != 0;
    f->jitter = !p->jitter_off;
    f->seed = p->jitter_seed;
    f->sample_distance = p->sample_distance == 0 ? DEFAULT_SAMPLE_DISTANCE : p->sample_distance;
    rc = check_float(e, "sample_distance", f->sample_distance, 1e-3f, 64);
    if (rc) return rc;
    float step = p->step == 0 ? DEFAULT_STEP : p->step;
    if (!(step > 0) || !isfinite(step))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "step = %g must be a positive number of voxels", step);
    /* Bound the samples per ray whatever the step: a 1e-4 step must not hang. */
    double diag = sqrt((double)g->dims[0] * g->dims[0] + (double)g->dims[1] * g->dims[1] +
                       (double)g->dims[2] * g->dims[2]);
    double min_step = diag / MAX_SAMPLES_PER_RAY;
    f->step = (float)fmin(fmax(step, min_step), MAX_STEP);
    f->max_steps = (int)ceil(diag / f->step) + 2;
    float et = p->early_termination == 0 ? 0.99f : p->early_termination;
    rc = check_float(e, "early_termination", et, 1e-6f, 1);
    if (rc) return rc;
    f->early_termination = p->no_skip ? 2.0f : et; /* > 1: never stops early */
    /* ISO opacity: the occupancy follows the iso-surface instead of the
     * table (bricks.c), conservatively for filters without a gradient bound. */
    f->skip = !p->no_skip;
    f->progressive = p->progressive != 0;
    f->depth_threshold = p->depth_threshold == 0 ? 0.5f : p->depth_threshold;
    rc = check_float(e, "depth_threshold", f->depth_threshold, 1e-6f, 1);
    if (rc) return rc;
    f->scene_depth = p->scene_depth;
    rc = resolve_matrices(f, p, g, e);
    if (!rc) rc = vxl_frame_resolve_environment(f, p, e);
    if (!rc) rc = resolve_lights(f, p, e);
    if (!rc) rc = vxl_frame_resolve_lighting(f, p, e);
    if (!rc) rc = vxl_frame_resolve_path(f, p, e);
    if (!rc) rc = vxl_frame_resolve_scene_shadows(f, p, e);
    if (!rc) rc = vxl_frame_cut_resolve(&f->cut, p, f->model, f->technique, e); /* cutaways */
    if (!rc) rc = vxl_frame_resolve_labels(f, p, e); /* labels */
    if (!rc) rc = vxl_frame_resolve_tf(f, p, g, e);
    if (rc) vxl_frame_free(f);
    return rc;
}

void vxl_frame_free(vxl_frame *f)
{
    free(f->tf_copy);
    f->tf_copy = NULL;
    vxl_frame_overlays_free(f);
    vxl_frame_channels_free(f);
}

uint64_t vxl_classification_key(const vxl_frame *f)
{
    uint64_t h = 1469598103934665603ull;
    h = vxl_fnv(h, f->tf, (size_t)f->tf_size * 4 * sizeof(float));
    h = vxl_fnv(h, &f->tf_size, sizeof f->tf_size);
    h = vxl_fnv(h, &f->window_offset, sizeof f->window_offset);
    h = vxl_fnv(h, &f->window_scale, sizeof f->window_scale);
    h = vxl_fnv(h, &f->opacity_scale, sizeof f->opacity_scale);
    return h;
}
