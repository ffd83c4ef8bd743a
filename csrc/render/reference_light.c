/* reference_light.c - the ground truth of voxlight.h's VXL_SHADING_SHADOWED
 * and _SCATTER: shadow rays to every light through the classified phantom,
 * soft shadows over the light's extent, ambient occlusion over the sphere of
 * directions and the Henyey-Greenstein phase function, in double precision.
 * Every direction set is fixed (Vogel and Fibonacci spirals), so the image
 * is deterministic. */
#include <math.h>

#include "mat4.h"
#include "reference.h"

/* Secondary rays integrate the optical depth with the midpoint rule at this
 * step: the phantoms are smooth over a voxel, so a quarter voxel is well
 * below the error of any illumination volume the fast path can afford. */
#define REF_LIGHT_STEP 0.25
#define REF_SOFT_SAMPLES 32     /* points of a light's disc or directions of a sun's cone */
#define REF_AO_DIRECTIONS 64    /* directions of the sphere for ambient occlusion */
#define GOLDEN_ANGLE 2.39996322972865332 /* pi (3 - sqrt 5): spreads a spiral's points evenly */
#define NEGLIGIBLE_TRANSMITTANCE 1e-12

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double normalize3(double a[3])
{
    double n = sqrt(dot3(a, a));
    if (n > 0)
        for (int k = 0; k < 3; k++) a[k] /= n;
    return n;
}

/* Transmittance from voxel-space point p along unit direction dir over len
 * voxels, ending where the ray leaves the volume box (empty outside). */
static double transmittance(const ref_ctx *c, const double p[3], const double dir[3], double len)
{
    const uint32_t *dims = c->vol->dims;
    double t1 = len;
    for (int a = 0; a < 3; a++) {
        if (dir[a] > 0) t1 = fmin(t1, (dims[a] - 0.5 - p[a]) / dir[a]);
        else if (dir[a] < 0) t1 = fmin(t1, (-0.5 - p[a]) / dir[a]);
    }
    if (!(t1 > 0) || !isfinite(t1)) return 1;
    double n = ceil(t1 / REF_LIGHT_STEP), dt = t1 / n, trans = 1;
    for (double k = 0; k < n; k++) {
        double q[3], col[4], g[3], gm, t = (k + 0.5) * dt;
        for (int a = 0; a < 3; a++) q[a] = p[a] + t * dir[a];
        trans *= 1 - vxl_ref_sample(c, q, dt, col, g, &gm);
        if (trans < NEGLIGIBLE_TRANSMITTANCE) return 0;
    }
    return trans;
}

/* u, v: a unit basis of the plane perpendicular to unit vector axis. */
static void perpendicular_basis(const double axis[3], double u[3], double v[3])
{
    double e[3] = {0, 0, 0};
    e[fabs(axis[0]) < 0.9 ? 0 : 1] = 1;
    u[0] = axis[1] * e[2] - axis[2] * e[1];
    u[1] = axis[2] * e[0] - axis[0] * e[2];
    u[2] = axis[0] * e[1] - axis[1] * e[0];
    normalize3(u);
    v[0] = axis[1] * u[2] - axis[2] * u[1];
    v[1] = axis[2] * u[0] - axis[0] * u[2];
    v[2] = axis[0] * u[1] - axis[1] * u[0];
}

static void world_to_voxel(const ref_ctx *c, const double w[3], double wcoord, double out[3])
{
    double in[4] = {w[0], w[1], w[2], wcoord}, o[4];
    vxl_mat4_transform(c->inv_model, in, o);
    for (int k = 0; k < 3; k++) out[k] = o[k];
}

/* T_i: the transmittance from voxel point p to light i, averaged over the
 * light's extent (voxlight.h: a sun's cone of directions, a point light's
 * disc facing the sample). */
static double light_transmittance(const ref_ctx *c, int i, const double p[3])
{
    const vxl_frame *f = c->f;
    double lw[3] = {f->light_world[i][0], f->light_world[i][1], f->light_world[i][2]};
    int point = f->light_world[i][3] != 0, n = f->light_size[i] > 0 ? REF_SOFT_SAMPLES : 1;
    double pw[4], in[4] = {p[0], p[1], p[2], 1}, axis[3], u[3], v[3];
    vxl_mat4_transform(c->f->model, in, pw);
    for (int k = 0; k < 3; k++) axis[k] = point ? lw[k] - pw[k] : lw[k];
    if (!(normalize3(axis) > 0)) return 1; /* the sample sits on the light */
    perpendicular_basis(axis, u, v);
    double cos_half = cos(0.5 * f->light_size[i]), sum = 0;
    for (int s = 0; s < n; s++) {
        double frac = (s + 0.5) / n, phi = s * GOLDEN_ANGLE, dir[3];
        if (point) { /* a point of the disc, uniform by area */
            double r = n > 1 ? f->light_size[i] * sqrt(frac) : 0, q[3], qv[3];
            for (int k = 0; k < 3; k++) q[k] = lw[k] + r * (cos(phi) * u[k] + sin(phi) * v[k]);
            world_to_voxel(c, q, 1, qv);
            for (int k = 0; k < 3; k++) dir[k] = qv[k] - p[k];
            double len = normalize3(dir);
            sum += len > 0 ? transmittance(c, p, dir, len) : 1;
        } else { /* a direction of the cone, uniform by solid angle */
            double ct = n > 1 ? 1 - (1 - cos_half) * frac : 1, st = sqrt(fmax(0, 1 - ct * ct)), d[3];
            for (int k = 0; k < 3; k++) d[k] = ct * axis[k] + st * (cos(phi) * u[k] + sin(phi) * v[k]);
            world_to_voxel(c, d, 0, dir);
            sum += normalize3(dir) > 0 ? transmittance(c, p, dir, INFINITY) : 1;
        }
    }
    return sum / n;
}

/* AO: the mean transmittance over a Fibonacci sphere of directions (voxel
 * space) along rays of ao_radius voxels. */
static double ambient_occlusion(const ref_ctx *c, const double p[3])
{
    if (!(c->f->ao_radius > 0)) return 1;
    double sum = 0;
    for (int s = 0; s < REF_AO_DIRECTIONS; s++) {
        double z = 1 - 2 * (s + 0.5) / REF_AO_DIRECTIONS, r = sqrt(fmax(0, 1 - z * z)), phi = s * GOLDEN_ANGLE;
        double dir[3] = {r * cos(phi), r * sin(phi), z};
        sum += transmittance(c, p, dir, c->f->ao_radius);
    }
    return sum / REF_AO_DIRECTIONS;
}

/* 4 pi times the Henyey-Greenstein phase function: 1 for g = 0. */
static double hg_4pi(double cos_t, double g)
{
    return (1 - g * g) / pow(1 + g * g - 2 * g * cos_t, 1.5);
}

void vxl_ref_shade_lit(const ref_ctx *c, double rgb[3], const double g[3], double gm, const double p[3],
                       const double pos[3], const double v[3])
{
    const vxl_frame *f = c->f;
    int scatter = f->shading_model == VXL_SHADING_SCATTER;
    double n[3];
    for (int r = 0; r < 3; r++) n[r] = c->normal[r] * g[0] + c->normal[3 + r] * g[1] + c->normal[6 + r] * g[2];
    int has_normal = normalize3(n) > 1e-20;
    if (!has_normal && !scatter) return; /* no direction: unlit, as PHONG */
    if (has_normal && dot3(n, v) < 0)
        for (int k = 0; k < 3; k++) n[k] = -n[k];
    double w = !has_normal ? 0 : scatter ? fmin(1, gm / f->gradient_ref) : 1;
    double occ = f->material[0] > 0 ? ambient_occlusion(c, p) : 1;
    double amb = f->material[0] * (1 - f->ao_strength * (1 - occ)), acc[3];
    for (int k = 0; k < 3; k++) acc[k] = amb * rgb[k];
    for (int i = 0; i < f->light_count; i++) {
        double l[3];
        for (int k = 0; k < 3; k++) l[k] = f->light_pos[i][3] == 0 ? f->light_pos[i][k] : f->light_pos[i][k] - pos[k];
        if (!(normalize3(l) > 0)) continue;
        double spot[3] = {f->light_spot_dir[i][0], f->light_spot_dir[i][1], f->light_spot_dir[i][2]};
        double mask = f->light_pos[i][3] != 0 ? vxl_frame_spot_mask(f, i, -dot3(l, spot)) : 1;
        if (!(mask > 0)) continue;
        double surf[3] = {0, 0, 0}, ndl = has_normal ? dot3(n, l) : 0;
        if (w > 0 && ndl > 0) {
            double h[3] = {l[0] + v[0], l[1] + v[1], l[2] + v[2]};
            double ndh = normalize3(h) > 0 ? dot3(n, h) : 0;
            double spec = pow(ndh > 0 ? ndh : 0, f->material[3]);
            for (int k = 0; k < 3; k++) surf[k] = f->material[1] * ndl * rgb[k] + f->material[2] * spec;
        }
        /* t: between the light's travel (-l) and the direction to the eye (v) */
        double phase = scatter && w < 1 ? hg_4pi(-dot3(l, v), f->anisotropy) : 0;
        if (surf[0] == 0 && surf[1] == 0 && surf[2] == 0 && phase == 0) continue;
        double trans = light_transmittance(c, i, p);
        for (int k = 0; k < 3; k++)
            acc[k] += trans * mask * f->light_color[i][k] * (w * surf[k] + (1 - w) * f->material[1] * rgb[k] * phase);
    }
    for (int k = 0; k < 3; k++) rgb[k] = acc[k] < 0 ? 0 : acc[k] > 1 ? 1 : acc[k];
}
