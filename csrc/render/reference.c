/* reference.c - the ground-truth renderer: the ray caster's equations
 * (raycast.frag, classify.glsl, shading.glsl) in double precision on the CPU,
 * sampling a phantom's analytic field and gradient at a fine step with no
 * jitter. Any change to those shaders' equations must be mirrored here.
 * Shadows, occlusion and scattering are in reference_light.c. */
#include <math.h>
#include <string.h>

#include "mat4.h"
#include "reference.h"

#define REF_MAX_STEP (1.0 / 16.0)

/* CLASSIFY_PRE: classify the analytic field at the 8 surrounding voxel
 * centres (premultiplied), interpolate trilinearly with clamp-to-edge, as
 * the GL path samples its pre-classified texture. */
static void classify_pre(const ref_ctx *c, const double p[3], double out[4])
{
    const uint32_t *dims = c->vol->dims;
    double span = c->vol->tex_hi - c->vol->tex_lo, acc[4] = {0, 0, 0, 0};
    double base[3], w[3];
    for (int a = 0; a < 3; a++) {
        double q = p[a] < 0 ? 0 : p[a] > dims[a] - 1 ? dims[a] - 1 : p[a];
        base[a] = floor(q);
        w[a] = q - base[a];
    }
    for (int i = 0; i < 8; i++) {
        double q[3], wt = 1, v, g[3], k[4];
        for (int a = 0; a < 3; a++) {
            int hi = (i >> a) & 1;
            q[a] = base[a] + hi;
            if (q[a] > dims[a] - 1) q[a] = dims[a] - 1;
            wt *= hi ? w[a] : 1 - w[a];
        }
        vxl_phantom_eval(c->d, q, &v, g);
        vxl_frame_classify(c->f, (v - c->vol->tex_lo) / span, k);
        for (int ch = 0; ch < 3; ch++) acc[ch] += wt * k[ch] * k[3];
        acc[3] += wt * k[3];
    }
    for (int ch = 0; ch < 3; ch++) out[ch] = acc[3] > 0 ? acc[ch] / acc[3] : 0;
    out[3] = acc[3];
}

static double correct_opacity(double a, double step)
{
    double t = 1 - a;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t <= 0 ? 1 : 1 - pow(t, step);
}

double vxl_ref_sample(const ref_ctx *c, const double p[3], double step, double col[4], double g[3], double *gm)
{
    const vxl_frame *f = c->f;
    double value, span = c->vol->tex_hi - c->vol->tex_lo;
    vxl_phantom_eval(c->d, p, &value, g);
    double vn = (value - c->vol->tex_lo) / span;
    /* gradient magnitude in normalised value per voxel, as the shader sees it */
    *gm = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) / fabs(span);
    if (f->gopacity == VXL_GOPACITY_ISO) {
        vxl_frame_classify(f, f->iso_pos, col);
        double dist = fabs(f->iso_pos - vn), r = f->iso_thickness, m = *gm;
        double a = m > 0 ? (dist <= r * m ? col[3] * (1 - dist / (r * m)) : 0) : (dist == 0 ? col[3] : 0);
        return correct_opacity(a, step);
    }
    /* PREINT approximates the same continuous integral as POST, so both
     * share this reference; PRE is a different image model. */
    if (f->classify == VXL_CLASSIFY_PRE) classify_pre(c, p, col);
    else vxl_frame_classify(f, vn, col);
    if (col[3] <= 0) return 0;
    double alpha = correct_opacity(col[3], step);
    if (f->gopacity == VXL_GOPACITY_BOUNDARY) alpha *= pow(fmin(*gm / f->gradient_ref, 1.0), f->gradient_exp);
    return alpha;
}

static void shade(const ref_ctx *c, double rgb[3], const double g[3], const double pos[3], const double v[3])
{
    const vxl_frame *f = c->f;
    double n[3];
    for (int r = 0; r < 3; r++) n[r] = c->normal[r] * g[0] + c->normal[3 + r] * g[1] + c->normal[6 + r] * g[2];
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 1e-20)) return;
    for (int k = 0; k < 3; k++) n[k] /= len;
    if (n[0] * v[0] + n[1] * v[1] + n[2] * v[2] < 0)
        for (int k = 0; k < 3; k++) n[k] = -n[k];
    double acc[3];
    for (int k = 0; k < 3; k++) acc[k] = f->material[0] * rgb[k];
    for (int i = 0; i < f->light_count; i++) {
        double l[3];
        for (int k = 0; k < 3; k++) l[k] = f->light_pos[i][3] == 0 ? f->light_pos[i][k] : f->light_pos[i][k] - pos[k];
        double ll = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
        if (!(ll > 0)) continue;
        for (int k = 0; k < 3; k++) l[k] /= ll;
        double ndl = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
        if (ndl <= 0) continue;
        double h[3] = {l[0] + v[0], l[1] + v[1], l[2] + v[2]};
        double hl = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
        double ndh = hl > 0 ? (n[0] * h[0] + n[1] * h[1] + n[2] * h[2]) / hl : 0;
        double spec = pow(ndh > 0 ? ndh : 0, f->material[3]);
        for (int k = 0; k < 3; k++) acc[k] += f->light_color[i][k] * (f->material[1] * ndl * rgb[k] + f->material[2] * spec);
    }
    for (int k = 0; k < 3; k++) rgb[k] = acc[k] < 0 ? 0 : acc[k] > 1 ? 1 : acc[k];
}

static void trace(const ref_ctx *c, double px, double py, float *out_rgba, float *out_depth)
{
    const vxl_frame *f = c->f;
    memset(out_rgba, 0, 4 * sizeof *out_rgba);
    *out_depth = INFINITY;
    double ndc[2] = {px / f->width * 2 - 1, py / f->height * 2 - 1};
    double hn[4], hf[4], a[4] = {ndc[0], ndc[1], -1, 1}, b[4] = {ndc[0], ndc[1], 1, 1};
    vxl_mat4_transform(c->inv_mvp, a, hn);
    vxl_mat4_transform(c->inv_mvp, b, hf);
    double o[3], dir[3];
    /* as raycast.frag: the direction without dividing by the far point's w */
    for (int k = 0; k < 3; k++) {
        o[k] = hn[k] / hn[3];
        dir[k] = hf[k] * hn[3] - hn[k] * hf[3];
    }
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    double t_far = hn[3] * hf[3] > 0 ? len / (hn[3] * hf[3]) : INFINITY;
    if (!(len > 0) || !isfinite(len) || isnan(t_far)) return;
    for (int k = 0; k < 3; k++) dir[k] /= len;
    double t0 = 0, t1 = t_far;
    const uint32_t *dims = c->vol->dims;
    for (int k = 0; k < 3; k++) {
        double lo = -0.5, hi = dims[k] - 0.5;
        if (fabs(dir[k]) < 1e-12) {
            if (o[k] < lo || o[k] > hi) return;
        } else {
            double ta = (lo - o[k]) / dir[k], tb = (hi - o[k]) / dir[k];
            t0 = fmax(t0, fmin(ta, tb));
            t1 = fmin(t1, fmax(ta, tb));
        }
    }
    double z0 = c->mv[2] * o[0] + c->mv[6] * o[1] + c->mv[10] * o[2] + c->mv[14];
    double dz = c->mv[2] * dir[0] + c->mv[6] * dir[1] + c->mv[10] * dir[2];
    if (f->scene_depth && dz < 0) {
        double dd = f->scene_depth[(size_t)py * f->width + (size_t)px];
        if (!isnan(dd)) t1 = fmin(t1, (-dd - z0) / dz);
    }
    if (!(t0 < t1)) return;
    double cap[3] = {0, 0, 0}; /* clip planes and crop box as cut.glsl (cutters are not modelled) */
    if (f->cut.any && !vxl_frame_cut_interval(&f->cut, o, dir, &t0, &t1, cap)) return;
    int capped = f->cut.caps && (cap[0] != 0 || cap[1] != 0 || cap[2] != 0);
    double view_dir[3];
    for (int r = 0; r < 3; r++) view_dir[r] = -(c->mv[r] * dir[0] + c->mv[4 + r] * dir[1] + c->mv[8 + r] * dir[2]);
    double vl = sqrt(view_dir[0] * view_dir[0] + view_dir[1] * view_dir[1] + view_dir[2] * view_dir[2]);
    for (int k = 0; k < 3; k++) view_dir[k] /= vl;
    double acc[4] = {0, 0, 0, 0};
    for (double t = t0; t < t1; t += c->step) {
        double p[3] = {o[0] + t * dir[0], o[1] + t * dir[1], o[2] + t * dir[2]}, g[3], col[4], gm;
        double alpha = vxl_ref_sample(c, p, c->step, col, g, &gm);
        if (alpha <= 0) continue;
        if (capped && t < t0 + f->step) { /* the cap: the cut's normal over the first step (cut_cap) */
            double cl = sqrt(cap[0] * cap[0] + cap[1] * cap[1] + cap[2] * cap[2]), span = c->vol->tex_hi - c->vol->tex_lo;
            gm = fmax(gm, 1.0);
            for (int k = 0; k < 3; k++) g[k] = cap[k] / cl * gm * fabs(span);
        }
        if (f->shading) {
            double pos[3];
            for (int r = 0; r < 3; r++) pos[r] = c->mv[r] * p[0] + c->mv[4 + r] * p[1] + c->mv[8 + r] * p[2] + c->mv[12 + r];
            /* the shader's gradient is of normalised values: same direction */
            if (f->shading_model == VXL_SHADING_PHONG) shade(c, col, g, pos, view_dir);
            else vxl_ref_shade_lit(c, col, g, gm, p, pos, view_dir);
        }
        double w = (1 - acc[3]) * alpha;
        for (int k = 0; k < 3; k++) acc[k] += w * col[k];
        acc[3] += w;
        if (isinf(*out_depth) && acc[3] >= f->depth_threshold) *out_depth = (float)-(z0 + dz * t);
        /* 1e-12 of transmittance left changes nothing and would go denormal */
        if (acc[3] >= f->early_termination || 1 - acc[3] < 1e-12) break;
    }
    for (int k = 0; k < 4; k++) out_rgba[k] = (float)(acc[k] < 0 ? 0 : acc[k] > 1 ? 1 : acc[k]);
}

int vxl_reference_render(const vxl_phantom_desc *d, const vxl_volume *vol, const vxl_render_params *p, float *rgba,
                         float *depth)
{
    if (!d || !vol || !rgba) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "phantom, volume or rgba is NULL");
    double probe_v, probe_g[3], origin[3] = {0, 0, 0};
    int rc = vxl_phantom_eval(d, origin, &probe_v, probe_g);
    if (rc) return rc;
    vxl_volume_geom g = vxl_volume_geom_of(vol);
    vxl_frame f;
    rc = vxl_frame_resolve(&f, p, &g, NULL);
    if (rc) return rc;
    ref_ctx c = {.d = d, .f = &f, .vol = vol};
    double mvp[16];
    vxl_mat4_mul(c.mv, f.view, f.model);
    vxl_mat4_mul(mvp, f.proj, c.mv);
    vxl_mat4_invert(c.inv_mvp, mvp); /* resolve already proved it invertible */
    if (!vxl_mat4_invert(c.inv_model, f.model)) {
        vxl_frame_free(&f);
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "the model matrix is singular");
    }
    for (int i = 0; i < 9; i++) c.normal[i] = f.normal[i];
    c.step = fmin(f.step, REF_MAX_STEP);
    for (uint32_t y = 0; y < f.height; y++)
        for (uint32_t x = 0; x < f.width; x++) {
            size_t i = (size_t)y * f.width + x;
            float dd;
            trace(&c, x + 0.5, y + 0.5, rgba + 4 * i, &dd);
            if (depth) depth[i] = dd;
        }
    vxl_frame_free(&f);
    return VXL_OK;
}
