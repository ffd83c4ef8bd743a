/* stress_cases.h - the adversarial volumes and views of the stability stress
 * suite (test_stress.c). A case is a volume recipe plus a function that sets
 * up the render parameters (camera, transfer function, step, scene depth...)
 * and what the case expects beyond the invariants every render must keep. The
 * runner crosses each case with every filter, classification mode,
 * shading/reuse setting and backend, and in --full mode with variants. */
#ifndef VXL_STRESS_CASES_H
#define VXL_STRESS_CASES_H

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "axis_view.h" /* vxl_axis_view_ortho: GL's orthographic projection, as the CLI builds it */
#include "voxlight_dev.h"

/* ------------------------------------------------------------ environment */

typedef struct stress_env {
    int full;
    uint32_t n;         /* edge of the "N" volumes */
    uint32_t big_n;     /* edge of the "big" volume */
    uint32_t image;     /* default image side (a power of two, see stress_env_init) */
    uint32_t odd_image; /* odd side: the centre pixel's ray is exactly the central ray */
    uint32_t axis_image;/* image side of the axis-parallel orthographic cases (power of two) */
    uint32_t small_image;/* image side of the cases whose rays take the full 16384 samples */
    uint32_t max_image; /* scratch buffers hold max_image^2 pixels */
    int variant_count;  /* 1 by default; --full adds views, steps, sample distances, stores, jitter */
} stress_env;

#define STRESS_VARIANTS_FULL 12

static inline void stress_env_init(stress_env *e, int full)
{
    memset(e, 0, sizeof *e);
    e->full = full;
    e->n = full ? 32 : 8;
    e->big_n = full ? 128 : 32;
    /* Powers of two everywhere a scene depth is given: llvmpipe compiles a
     * shader variant per power-of-two-ness of every bound texture, and each
     * costs ~0.25 s per program. */
    e->image = full ? 64 : 32;
    e->odd_image = full ? 65 : 33;
    e->axis_image = full ? 64 : 32;
    e->small_image = full ? 9 : 5;
    e->max_image = 160; /* also covers the 20000x1 over-limit request (refused, never written) */
    e->variant_count = full ? STRESS_VARIANTS_FULL : 1;
}

/* ---------------------------------------------------------------- volumes */

/* value of voxel (i,j,k) of a volume of size d; idx is its linear index */
typedef double (*stress_fill)(uint32_t i, uint32_t j, uint32_t k, const uint32_t d[3], uint64_t idx);

enum {
    AFF_NONE,          /* identity (spacing 1) */
    AFF_SPACING_ANISO, /* no affine, spacing 0.1 : 1 : 10 */
    AFF_ANISO,         /* has_affine, diag(0.1, 1, 10) */
    AFF_HUGE,          /* diag(1e6) */
    AFF_TINY,          /* diag(1e-6) */
    AFF_ROT_SHEAR,     /* a rotation times a shear, with translation */
    AFF_FLIP,          /* diag(-1, 1, 1): negative determinant */
    AFF_FAR,           /* identity translated by 1e7 */
    AFF_EXTREME_ANISO, /* diag(1e6, 1e-6, 1) */
    AFF_SINGULAR,      /* all-zero 3x3: deliberately invalid */
    AFF_NAN,           /* NaN entries: deliberately invalid */
};

#define BIG_N 0xFFFFFFFFu

typedef struct stress_vol {
    uint32_t dtype;
    uint32_t dims[3]; /* 0 = env n, BIG_N = env big_n */
    stress_fill fill;
    int affine;
    double slope, inter;
    /* 0: grey; 3 or 4: a colour volume whose channel c is fill times
     * sv_channel_gain[c] (so NaN, Inf and extremes reach every channel) */
    /* or SV_CHANNELS(n): a multi-channel volume of n (2..8) channels
     * (docs/channels.md), interleaved, channel c fill times sv_channel_gain[c] */
    uint32_t components;
} stress_vol;

#define SV_CHANNELS(n) (0x100u | (n))
static inline uint32_t sv_channels(const stress_vol *s) { return s->components & 0x100u ? s->components & 0xffu : 0; }

static const double sv_channel_gain[8] = {1.0, 0.5, -1.0, 0.25, 2.0, -0.5, 0.75, 1.5};

static inline double sv_centre(const uint32_t d[3], int a) { return (d[a] - 1) / 2.0; }

static inline double sv_ball(uint32_t i, uint32_t j, uint32_t k, const uint32_t d[3])
{
    double m = d[0] > d[1] ? d[0] : d[1];
    m = m > d[2] ? m : d[2];
    double x = i - sv_centre(d, 0), y = j - sv_centre(d, 1), z = k - sv_centre(d, 2);
    double r = sqrt(x * x + y * y + z * z);
    return 1.0 / (1.0 + exp(2.0 * (r - 0.35 * m)));
}

#define FILL(name) static double name(uint32_t i, uint32_t j, uint32_t k, const uint32_t d[3], uint64_t idx)
#define UNUSED_FILL_ARGS (void)i, (void)j, (void)k, (void)d, (void)idx

FILL(fill_zero) { UNUSED_FILL_ARGS; return 0; }
FILL(fill_three) { UNUSED_FILL_ARGS; return 3; }
FILL(fill_minus_1e30) { UNUSED_FILL_ARGS; return -1e30; }
FILL(fill_u8_max) { UNUSED_FILL_ARGS; return 255; }
FILL(fill_ball) { (void)idx; return sv_ball(i, j, k, d); }
FILL(fill_bright_centre)
{
    (void)idx;
    return i == d[0] / 2 && j == d[1] / 2 && k == d[2] / 2 ? 1000.0 : 0.0;
}
FILL(fill_bright_corner) { (void)d, (void)idx; return i == 0 && j == 0 && k == 0 ? 1.0 : 0.0; }
FILL(fill_nan_in_ball) { return idx % 5 == 0 ? NAN : sv_ball(i, j, k, d); }
FILL(fill_all_nan) { UNUSED_FILL_ARGS; return NAN; }
FILL(fill_inf_in_ball) { return idx % 5 == 0 ? INFINITY : idx % 7 == 0 ? -INFINITY : sv_ball(i, j, k, d); }
FILL(fill_all_pos_inf) { UNUSED_FILL_ARGS; return INFINITY; }
FILL(fill_all_neg_inf) { UNUSED_FILL_ARGS; return -INFINITY; }
FILL(fill_nan_inf_mix)
{
    UNUSED_FILL_ARGS;
    return idx % 7 == 0 ? NAN : idx % 11 == 0 ? INFINITY : idx % 13 == 0 ? -INFINITY : (double)(idx % 16);
}
FILL(fill_pm_1e30) { UNUSED_FILL_ARGS; return (i + j + k) % 2 ? 1e30 : -1e30; }
FILL(fill_ball_1e30) { (void)idx; return 1e30 * sv_ball(i, j, k, d); }
FILL(fill_pm_flt_max) { UNUSED_FILL_ARGS; return (i + j + k) % 2 ? FLT_MAX : -FLT_MAX; }
FILL(fill_denormals) { UNUSED_FILL_ARGS; return ldexp((double)(idx % 97), -149); } /* float denormals, 0..96 ulp */
FILL(fill_denormal_ball) { (void)idx; return 1e-40 * sv_ball(i, j, k, d); }
FILL(fill_denormal_and_1e30) { UNUSED_FILL_ARGS; return idx % 3 == 0 ? 1e30 : idx % 3 == 1 ? -1e30 : 1e-40; }
FILL(fill_tiny_range) { (void)idx; return 1.0 + 1e-7 * sv_ball(i, j, k, d); } /* below float resolution at 1 */
FILL(fill_i16_checker) { UNUSED_FILL_ARGS; return (i + j + k) % 2 ? 32767 : -32768; }
FILL(fill_i16_min) { UNUSED_FILL_ARGS; return -32768; }
FILL(fill_i16_ball_extremes) { (void)idx; return sv_ball(i, j, k, d) > 0.5 ? 32767 : -32768; }
FILL(fill_i8_checker) { UNUSED_FILL_ARGS; return (i + j + k) % 2 ? 127 : -128; }
FILL(fill_u16_max_ball) { (void)idx; return 65535 * sv_ball(i, j, k, d); }
FILL(fill_i32_checker) { UNUSED_FILL_ARGS; return (i + j + k) % 2 ? 2147483647.0 : -2147483648.0; }
FILL(fill_u32_max_ball) { (void)idx; return 4294967295.0 * sv_ball(i, j, k, d); }
FILL(fill_pm_1e300) { UNUSED_FILL_ARGS; return (i + j + k) % 2 ? 1e300 : -1e300; }
FILL(fill_f64_denormal_ball) { (void)idx; return 1e-310 * sv_ball(i, j, k, d); }
FILL(fill_f64_max_and_nan) { UNUSED_FILL_ARGS; return idx % 3 == 0 ? DBL_MAX : idx % 3 == 1 ? -DBL_MAX : NAN; }
FILL(fill_i16_ramp) { (void)j, (void)k, (void)idx; return -32768.0 + 65535.0 * i / (d[0] > 1 ? d[0] - 1 : 1); }
FILL(fill_i16_ball) { (void)idx; return 1000.0 * sv_ball(i, j, k, d); }
FILL(fill_five) { UNUSED_FILL_ARGS; return 5; }
FILL(fill_index) { UNUSED_FILL_ARGS; return (double)idx; }

static inline void sv_store(void *raw, uint32_t dtype, uint64_t i, double x)
{
    /* integers: round and saturate (NaN -> 0) */
#define SAT(T, lo, hi) (isnan(x) ? (T)0 : x <= (lo) ? (T)(lo) : x >= (hi) ? (T)(hi) : (T)llround(x))
    switch (dtype) {
    case VXL_DTYPE_U8: ((uint8_t *)raw)[i] = SAT(uint8_t, 0, 255); break;
    case VXL_DTYPE_I8: ((int8_t *)raw)[i] = SAT(int8_t, -128, 127); break;
    case VXL_DTYPE_U16: ((uint16_t *)raw)[i] = SAT(uint16_t, 0, 65535); break;
    case VXL_DTYPE_I16: ((int16_t *)raw)[i] = SAT(int16_t, -32768, 32767); break;
    case VXL_DTYPE_U32: ((uint32_t *)raw)[i] = SAT(uint32_t, 0, 4294967295.0); break;
    case VXL_DTYPE_I32: ((int32_t *)raw)[i] = SAT(int32_t, -2147483648.0, 2147483647.0); break;
    case VXL_DTYPE_F32: ((float *)raw)[i] = (float)x; break;
    default: ((double *)raw)[i] = x; break;
    }
#undef SAT
}

static inline uint32_t sv_dtype_size(uint32_t dtype)
{
    return dtype == VXL_DTYPE_U8 || dtype == VXL_DTYPE_I8 ? 1
         : dtype == VXL_DTYPE_U16 || dtype == VXL_DTYPE_I16 ? 2
         : dtype == VXL_DTYPE_F64 ? 8 : 4;
}

static inline void sv_diag(double a[16], double x, double y, double z)
{
    memset(a, 0, 16 * sizeof *a);
    a[0] = x;
    a[5] = y;
    a[10] = z;
    a[15] = 1;
}

/* Builds the volume; returns vxl_volume_create's code. */
static inline int stress_make_volume(const stress_vol *s, const stress_env *e, vxl_volume **out)
{
    uint32_t d[3];
    for (int a = 0; a < 3; a++) d[a] = s->dims[a] == BIG_N ? e->big_n : s->dims[a] ? s->dims[a] : e->n;
    uint64_t n = (uint64_t)d[0] * d[1] * d[2];
    const uint32_t comp = sv_channels(s) ? sv_channels(s) : s->components ? s->components : 1;
    void *raw = malloc(n * comp * sv_dtype_size(s->dtype));
    if (!raw) return VXL_ERR_NO_MEMORY;
    for (uint32_t k = 0; k < d[2]; k++)
        for (uint32_t j = 0; j < d[1]; j++)
            for (uint32_t i = 0; i < d[0]; i++) {
                uint64_t idx = i + (uint64_t)d[0] * (j + (uint64_t)d[1] * k);
                const double x = s->fill(i, j, k, d, idx);
                for (uint32_t c = 0; c < comp; c++)
                    sv_store(raw, s->dtype, idx * comp + c, comp > 1 ? x * sv_channel_gain[c] : x);
            }
    vxl_volume_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.struct_size = sizeof desc;
    desc.dtype = s->dtype;
    memcpy(desc.dims, d, sizeof d);
    desc.data = raw;
    desc.scl_slope = s->slope;
    desc.scl_inter = s->inter;
    desc.components = sv_channels(s) ? 0 : s->components;
    desc.channels = sv_channels(s);
    desc.channels_interleaved = 1;
    double *A = desc.affine;
    desc.has_affine = 1;
    switch (s->affine) {
    case AFF_NONE: desc.has_affine = 0; break;
    case AFF_SPACING_ANISO:
        desc.has_affine = 0;
        desc.spacing[0] = 0.1;
        desc.spacing[1] = 1;
        desc.spacing[2] = 10;
        break;
    case AFF_ANISO: sv_diag(A, 0.1, 1, 10); break;
    case AFF_HUGE: sv_diag(A, 1e6, 1e6, 1e6); break;
    case AFF_TINY: sv_diag(A, 1e-6, 1e-6, 1e-6); break;
    case AFF_ROT_SHEAR: {
        /* R = rotation by 37 degrees about (1,2,3)/|.|, S = shear x += 0.6 y + 0.3 z, spacing (1.5, 0.7, 2) */
        double ax[3] = {1, 2, 3}, l = sqrt(14.0), t = 37 * M_PI / 180, c = cos(t), sn = sin(t);
        for (int q = 0; q < 3; q++) ax[q] /= l;
        double R[3][3];
        for (int r = 0; r < 3; r++)
            for (int q = 0; q < 3; q++) R[r][q] = (r == q ? c : 0) + (1 - c) * ax[r] * ax[q];
        R[0][1] -= sn * ax[2]; R[0][2] += sn * ax[1];
        R[1][0] += sn * ax[2]; R[1][2] -= sn * ax[0];
        R[2][0] -= sn * ax[1]; R[2][1] += sn * ax[0];
        double S[3][3] = {{1.5, 0.6 * 0.7, 0.3 * 2}, {0, 0.7, 0}, {0, 0, 2}};
        sv_diag(A, 1, 1, 1);
        for (int r = 0; r < 3; r++)
            for (int q = 0; q < 3; q++) {
                double v = 0;
                for (int m = 0; m < 3; m++) v += R[r][m] * S[m][q];
                A[q * 4 + r] = v;
            }
        A[12] = -91.25;
        A[13] = 12.5;
        A[14] = 33.0;
        break;
    }
    case AFF_FLIP: sv_diag(A, -1, 1, 1); break;
    case AFF_FAR:
        sv_diag(A, 1, 1, 1);
        A[12] = 1e7;
        A[13] = -1e7;
        A[14] = 1e7;
        break;
    case AFF_EXTREME_ANISO: sv_diag(A, 1e6, 1e-6, 1); break;
    case AFF_SINGULAR: sv_diag(A, 0, 0, 0); break;
    case AFF_NAN:
        sv_diag(A, 1, 1, 1);
        A[0] = NAN;
        A[13] = NAN;
        break;
    }
    *out = NULL;
    int rc = vxl_volume_create(&desc, NULL, out);
    free(raw);
    return rc;
}

/* ------------------------------------------------------------------ views */

typedef struct stress_view_ctx {
    const stress_env *env;
    uint32_t dims[3];
    double c[3];   /* voxel-space centre; world too for the identity-affine cases */
    double n;      /* largest axis */
    double value_min, value_max; /* finite data range */
    float *depth;  /* scene-depth scratch, max_image^2 */
    float *tf;     /* transfer-function scratch, 65537 entries */
} stress_view_ctx;

static inline void stress_view_ctx_init(stress_view_ctx *vc, const stress_env *e, const vxl_volume *v)
{
    memset(vc, 0, sizeof *vc);
    vc->env = e;
    vxl_volume_info info;
    memset(&info, 0, sizeof info);
    info.struct_size = sizeof info;
    vxl_volume_get_info(v, &info);
    memcpy(vc->dims, info.dims, sizeof vc->dims);
    vc->value_min = info.value_min;
    vc->value_max = info.value_max;
    vc->n = 1;
    for (int a = 0; a < 3; a++) {
        vc->c[a] = (vc->dims[a] - 1) / 2.0;
        if (vc->dims[a] > vc->n) vc->n = vc->dims[a];
    }
    vc->depth = malloc((size_t)e->max_image * e->max_image * sizeof(float));
    vc->tf = malloc((size_t)65537 * 4 * sizeof(float));
}

static inline void stress_view_ctx_free(stress_view_ctx *vc)
{
    free(vc->depth);
    free(vc->tf);
}

static inline vxl_render_params stress_base_params(const stress_env *e)
{
    vxl_render_params p;
    memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.width = p.height = e->image;
    p.azimuth_deg = 30;
    p.elevation_deg = 20;
    return p;
}

static inline void sm_look_at(float out[16], const double eye[3], const double at[3], const double up[3])
{
    double f[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]}, s[3], u[3];
    double l = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int i = 0; i < 3; i++) f[i] /= l;
    s[0] = f[1] * up[2] - f[2] * up[1];
    s[1] = f[2] * up[0] - f[0] * up[2];
    s[2] = f[0] * up[1] - f[1] * up[0];
    l = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int i = 0; i < 3; i++) s[i] /= l;
    u[0] = s[1] * f[2] - s[2] * f[1];
    u[1] = s[2] * f[0] - s[0] * f[2];
    u[2] = s[0] * f[1] - s[1] * f[0];
    memset(out, 0, 16 * sizeof *out);
    for (int i = 0; i < 3; i++) {
        out[i * 4 + 0] = (float)s[i];
        out[i * 4 + 1] = (float)u[i];
        out[i * 4 + 2] = (float)-f[i];
    }
    out[12] = (float)-(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    out[13] = (float)-(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    out[14] = (float)(f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2]);
    out[15] = 1;
}

static inline void sm_frustum(float m[16], double l, double r, double b, double t, double n, double f)
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = (float)(2 * n / (r - l));
    m[5] = (float)(2 * n / (t - b));
    m[8] = (float)((r + l) / (r - l));
    m[9] = (float)((t + b) / (t - b));
    m[10] = (float)(-(f + n) / (f - n));
    m[11] = -1;
    m[14] = (float)(-2 * f * n / (f - n));
}

static inline void sm_persp(float m[16], double fovy_deg, double aspect, double n, double f)
{
    double t = n * tan(fovy_deg * M_PI / 360);
    sm_frustum(m, -t * aspect, t * aspect, -t, t, n, f);
}

/* F_NEAR_INVARIANT: the near plane sv_camera uses instead of the case's
 * (thread-local: the backends render concurrently). */
static _Thread_local double vc_near_override;

/* A perspective camera at eye looking at at, fovy degrees, near/far given. */
static inline void sv_camera(vxl_render_params *p, const double eye[3], const double at[3], const double up[3],
                             double fovy, double n, double f)
{
    p->has_camera = 1;
    sm_look_at(p->view, eye, at, up);
    if (vc_near_override > 0) n = vc_near_override;
    sm_persp(p->proj, fovy, (double)p->width / p->height, n, f);
}

/* The classification the camera cases use on the ball: gray, window [0,1],
 * opaque enough that the ball is clearly there. */
static inline void sv_ball_tf(vxl_render_params *p)
{
    p->preset = VXL_PRESET_GRAY;
    p->has_window = 1;
    p->window_low = 0;
    p->window_high = 1;
    p->opacity_scale = 4;
}

#define VIEW(name) static void name(vxl_render_params *p, stress_view_ctx *vc)
#define UNUSED_VIEW_ARGS (void)p, (void)vc

static const double UP_Y[3] = {0, 1, 0}, UP_Z[3] = {0, 0, 1};

VIEW(view_default) { UNUSED_VIEW_ARGS; }
VIEW(view_ball_default) { (void)vc; sv_ball_tf(p); }

/* cameras (identity-affine ball: world = voxel space) */
VIEW(cam_inside_centre)
{
    sv_ball_tf(p);
    double at[3] = {vc->c[0] + 0.3, vc->c[1] - 0.2, vc->c[2] - 1};
    sv_camera(p, vc->c, at, UP_Y, 60, 0.01, 100 * vc->n);
}
VIEW(cam_inside_centre_axis) /* eye on three voxel-boundary planes, looking exactly along -Z */
{
    sv_ball_tf(p);
    double at[3] = {vc->c[0], vc->c[1], vc->c[2] - 1};
    sv_camera(p, vc->c, at, UP_Y, 60, 0.01, 100 * vc->n);
}
VIEW(cam_inside_corner_looking_out)
{
    sv_ball_tf(p);
    double eye[3] = {0.1, 0.1, 0.1}, at[3] = {-1, -1.2, -0.9};
    sv_camera(p, eye, at, UP_Z, 60, 0.01, 100 * vc->n);
}
VIEW(cam_on_face_looking_in)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0], vc->c[1], vc->dims[2] - 0.5}, at[3] = {vc->c[0], vc->c[1], 0};
    sv_camera(p, eye, at, UP_Y, 60, 0.01, 100 * vc->n);
}
VIEW(cam_on_face_looking_out)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0], vc->c[1], vc->dims[2] - 0.5}, at[3] = {vc->c[0], vc->c[1], vc->dims[2] + 10.0};
    sv_camera(p, eye, at, UP_Y, 60, 0.01, 100 * vc->n);
}
VIEW(cam_on_corner)
{
    sv_ball_tf(p);
    double eye[3] = {-0.5, -0.5, -0.5};
    sv_camera(p, eye, vc->c, UP_Z, 60, 0.01, 100 * vc->n);
}
VIEW(cam_along_edge) /* the central ray runs exactly along the box edge y = z = -0.5 */
{
    sv_ball_tf(p);
    double eye[3] = {-5, -0.5, -0.5}, at[3] = {vc->dims[0] + 5.0, -0.5, -0.5};
    sv_camera(p, eye, at, UP_Z, 60, 0.01, 100 * vc->n);
}
VIEW(cam_persp_on_face_plane) /* eye on the plane x = -0.5, looking down -Z: the central ray lies in the face */
{
    sv_ball_tf(p);
    p->width = p->height = vc->env->odd_image;
    double eye[3] = {-0.5, vc->c[1], vc->dims[2] + 20.0}, at[3] = {-0.5, vc->c[1], 0};
    sv_camera(p, eye, at, UP_Y, 60, 0.01, 100 * vc->n);
}
VIEW(cam_persp_on_voxel_planes) /* central ray on x = 1.5, y = 2.5 (voxel boundaries) */
{
    sv_ball_tf(p);
    p->width = p->height = vc->env->odd_image;
    double eye[3] = {1.5, 2.5, vc->dims[2] + 20.0}, at[3] = {1.5, 2.5, 0};
    sv_camera(p, eye, at, UP_Y, 60, 0.01, 100 * vc->n);
}

/* Orthographic along an axis, one pixel per voxel, pixel centres exactly on
 * the voxel-boundary planes k + 0.5 (and on the box faces): the image side is
 * a power of two so the ndc arithmetic is exact. axis 0..5 = -X +X -Y +Y -Z +Z
 * (the direction the rays travel). */
static inline void sv_axis_ortho(vxl_render_params *p, stress_view_ctx *vc, int axis)
{
    sv_ball_tf(p);
    uint32_t w = vc->env->axis_image;
    p->width = p->height = w;
    p->has_camera = 1;
    int a = axis / 2;
    double sgn = axis % 2 ? 1 : -1; /* ray direction along the axis */
    double eye[3] = {0, 0, 0}, at[3] = {0, 0, 0};
    double dist = vc->n + 10;
    eye[a] = -sgn * dist;
    at[a] = eye[a] + sgn;
    sm_look_at(p->view, eye, at, a == 2 ? UP_Y : UP_Z);
    double half = w / 2.0;
    vxl_axis_view_ortho(p->proj, -half, half, -half, half, 1, 3 * dist);
}
VIEW(axis_ortho_minus_x) { sv_axis_ortho(p, vc, 0); }
VIEW(axis_ortho_plus_x) { sv_axis_ortho(p, vc, 1); }
VIEW(axis_ortho_minus_y) { sv_axis_ortho(p, vc, 2); }
VIEW(axis_ortho_plus_y) { sv_axis_ortho(p, vc, 3); }
VIEW(axis_ortho_minus_z) { sv_axis_ortho(p, vc, 4); }
VIEW(axis_ortho_plus_z) { sv_axis_ortho(p, vc, 5); }

VIEW(default_cam_top) { (void)vc; sv_ball_tf(p); p->azimuth_deg = 0; p->elevation_deg = 90; }
VIEW(default_cam_bottom) { (void)vc; sv_ball_tf(p); p->azimuth_deg = 45; p->elevation_deg = -90; }
VIEW(default_cam_front) /* central ray exactly along -Y through the voxel-boundary lines */
{
    sv_ball_tf(p);
    p->width = p->height = vc->env->odd_image;
    p->azimuth_deg = 0;
    p->elevation_deg = 0;
}
VIEW(default_cam_huge_angles) { (void)vc; sv_ball_tf(p); p->azimuth_deg = 1e9f; p->elevation_deg = -7.2e8f; }

/* projections */
VIEW(proj_near_1e6_far_1e9)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    sv_camera(p, eye, vc->c, UP_Z, 45, 1e-6, 1e9);
}
VIEW(proj_near_1e6_distant) /* the same clip planes, the camera 10x farther with a narrow field of view */
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 20 * vc->n, vc->c[1] - 15 * vc->n, vc->c[2] + 10 * vc->n};
    double dist = sqrt(400.0 + 225.0 + 100.0) * vc->n;
    sv_camera(p, eye, vc->c, UP_Z, 2.0 * atan(0.8 * vc->n / dist) * 180 / M_PI, 1e-6, 1e9);
}
VIEW(proj_near_1e3_far_1e6) /* a plausible viewport clip range: ratio 1e9 */
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    sv_camera(p, eye, vc->c, UP_Z, 45, 1e-3, 1e6);
}
VIEW(proj_near_eq_far) /* near = far * 0.999999, the thin slab through the centre */
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    double dist = sqrt(4.0 + 2.25 + 1.0) * vc->n;
    sv_camera(p, eye, vc->c, UP_Z, 45, dist * 0.999999, dist);
}
VIEW(proj_near_eq_far_ortho)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0], vc->c[1], vc->c[2] + 3 * vc->n}, at[3] = {vc->c[0], vc->c[1], 0};
    p->has_camera = 1;
    sm_look_at(p->view, eye, at, UP_Y);
    double f = 3 * vc->n, h = vc->n;
    vxl_axis_view_ortho(p->proj, -h, h, -h, h, f * 0.999999, f);
}
VIEW(proj_infinite_far) /* the classic infinite projection: m10 = -1, m14 = -2n */
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    sv_camera(p, eye, vc->c, UP_Z, 45, 0.1, 1);
    p->proj[10] = -1;
    p->proj[14] = -0.2f;
}
VIEW(proj_reversed_depth) /* near and far swapped: ndc -1 is the far plane */
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    sv_camera(p, eye, vc->c, UP_Z, 45, 10 * vc->n, 0.1);
}
VIEW(proj_ortho_oblique)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    p->has_camera = 1;
    sm_look_at(p->view, eye, vc->c, UP_Z);
    double h = vc->n;
    vxl_axis_view_ortho(p->proj, -h, h, -h, h, 0.5, 10 * vc->n);
}
VIEW(proj_ortho_inside) /* the near plane cuts through the volume */
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0], vc->c[1], vc->c[2] + 0.25}, at[3] = {vc->c[0] + 0.1, vc->c[1] + 0.2, 0};
    p->has_camera = 1;
    sm_look_at(p->view, eye, at, UP_Y);
    double h = vc->n;
    vxl_axis_view_ortho(p->proj, -h, h, -h, h, 0.01, 10 * vc->n);
}
VIEW(proj_ortho_huge_extent) /* the volume is far below a pixel */
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0], vc->c[1], vc->c[2] + 2 * vc->n}, at[3] = {vc->c[0], vc->c[1], 0};
    p->has_camera = 1;
    sm_look_at(p->view, eye, at, UP_Y);
    vxl_axis_view_ortho(p->proj, -1e7, 1e7, -1e7, 1e7, 0.5, 1e7);
}
VIEW(proj_fov_tiny)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    sv_camera(p, eye, vc->c, UP_Z, 1e-4, 0.1, 100 * vc->n);
}
VIEW(proj_fov_179)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    sv_camera(p, eye, vc->c, UP_Z, 179.9, 0.01, 100 * vc->n);
}
VIEW(proj_far_away_camera)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 1e6, vc->c[1] - 2e6, vc->c[2] + 5e5};
    double dist = sqrt(1e12 + 4e12 + 2.5e11);
    sv_camera(p, eye, vc->c, UP_Z, 2.0 * atan(vc->n / dist) * 180 / M_PI, 1, 1e7);
}
VIEW(proj_off_centre_frustum)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    p->has_camera = 1;
    sm_look_at(p->view, eye, vc->c, UP_Z);
    sm_frustum(p->proj, -0.05, 0.4, -0.3, 0.02, 0.1, 100 * vc->n);
}

/* scene depth (default camera on the ball) */
static inline void sv_depth_fill(vxl_render_params *p, stress_view_ctx *vc, float v)
{
    for (uint32_t i = 0; i < p->width * p->height; i++) vc->depth[i] = v;
    p->scene_depth = vc->depth;
}
VIEW(depth_zero) { sv_ball_tf(p); sv_depth_fill(p, vc, 0.0f); }
VIEW(depth_inf) { sv_ball_tf(p); sv_depth_fill(p, vc, INFINITY); }
VIEW(depth_flt_max) { sv_ball_tf(p); sv_depth_fill(p, vc, FLT_MAX); }
VIEW(depth_nan) { sv_ball_tf(p); sv_depth_fill(p, vc, NAN); }
VIEW(depth_negative) { sv_ball_tf(p); sv_depth_fill(p, vc, -1.0f); }
VIEW(depth_minus_inf) { sv_ball_tf(p); sv_depth_fill(p, vc, -INFINITY); }
VIEW(depth_denormal) { sv_ball_tf(p); sv_depth_fill(p, vc, 1e-40f); }
VIEW(depth_checker)
{
    sv_ball_tf(p);
    sv_depth_fill(p, vc, 0);
    for (uint32_t y = 0; y < p->height; y++)
        for (uint32_t x = 0; x < p->width; x++) vc->depth[y * p->width + x] = (x + y) % 2 ? INFINITY : 0.0f;
}
VIEW(depth_zero_inside) /* camera inside, depth 0: nothing */
{
    cam_inside_centre(p, vc);
    sv_depth_fill(p, vc, 0.0f);
}
VIEW(depth_inf_ortho) { sv_axis_ortho(p, vc, 4); sv_depth_fill(p, vc, INFINITY); }
VIEW(depth_zero_ortho) { sv_axis_ortho(p, vc, 4); sv_depth_fill(p, vc, 0.0f); }

/* classification */
VIEW(window_degenerate) { (void)vc; sv_ball_tf(p); p->window_low = p->window_high = 0.5f; }
VIEW(window_degenerate_zero) { (void)vc; sv_ball_tf(p); p->window_low = p->window_high = 0.0f; }
VIEW(window_degenerate_1e30) { (void)vc; sv_ball_tf(p); p->window_low = p->window_high = 1e30f; }
VIEW(window_inverted) { (void)vc; sv_ball_tf(p); p->window_low = 1; p->window_high = 0; }
VIEW(window_huge) { (void)vc; sv_ball_tf(p); p->window_low = -1e30f; p->window_high = 1e30f; }
VIEW(window_flt_max) { (void)vc; sv_ball_tf(p); p->window_low = -FLT_MAX; p->window_high = FLT_MAX; }
VIEW(window_tiny) { (void)vc; sv_ball_tf(p); p->window_low = 0.5f; p->window_high = nextafterf(0.5f, 1); }
VIEW(window_denormal) { (void)vc; sv_ball_tf(p); p->window_low = 0; p->window_high = 1e-40f; }
VIEW(window_far_above) { (void)vc; sv_ball_tf(p); p->window_low = 1e30f; p->window_high = 2e30f; }
VIEW(opacity_1e6) { (void)vc; sv_ball_tf(p); p->opacity_scale = 1e6f; }
VIEW(opacity_tiny) { (void)vc; sv_ball_tf(p); p->opacity_scale = 1e-30f; }
VIEW(opacity_1e6_huge_values) { (void)vc; p->opacity_scale = 1e6f; p->preset = VXL_PRESET_HOT; }
static inline void sv_tf_table(vxl_render_params *p, stress_view_ctx *vc, uint32_t n, int kind)
{
    for (uint32_t i = 0; i < n; i++) {
        float *e = vc->tf + 4 * i, x = (float)i / (float)(n - 1);
        if (kind == 0) { /* NaN, Inf, negative and > 1 entries */
            static const float bad[6] = {NAN, INFINITY, -INFINITY, -5.0f, 1e30f, 0.5f};
            for (int c = 0; c < 4; c++) e[c] = bad[(i + c) % 6];
        } else if (kind == 1) { /* opaque white everywhere */
            e[0] = e[1] = e[2] = e[3] = 1;
        } else if (kind == 2) { /* a one-entry opacity spike */
            e[0] = x;
            e[1] = 1 - x;
            e[2] = 0.5f;
            e[3] = i == n / 2 ? 1.0f : 0.0f;
        } else { /* smooth ramp */
            e[0] = e[1] = e[2] = x;
            e[3] = 0.3f * x;
        }
    }
    p->tf_rgba = vc->tf;
    p->tf_size = n;
    p->has_window = 1;
    p->window_low = 0;
    p->window_high = 1;
}
VIEW(tf_nan_inf_entries) { sv_tf_table(p, vc, 256, 0); }
VIEW(tf_opaque_white) { sv_tf_table(p, vc, 256, 1); }
VIEW(tf_spike) { sv_tf_table(p, vc, 4096, 2); }
VIEW(tf_size_2) { sv_tf_table(p, vc, 2, 3); }
VIEW(tf_size_16384) { sv_tf_table(p, vc, 16384, 3); }
VIEW(tf_size_16385) { sv_tf_table(p, vc, 16385, 3); }
VIEW(tf_size_65536) { sv_tf_table(p, vc, 65536, 3); }
/* Gradient-magnitude opacity and the pre-integration table at their limits.
 * Each gradient-opacity mode is a program of its own per filter, classify
 * mode and shading, and llvmpipe compiles each at ~0.25 s: by default these
 * cases turn it on for every filter with one classify mode each (classify =
 * filter mod count, as the runner's own gradient-opacity renders), in --full
 * for every render. Returns whether this render gets it. */
static inline int sv_gop(vxl_render_params *p, const stress_view_ctx *vc, uint32_t mode)
{
    if (!vc->env->full && (p->shading_off || p->classify != p->filter % VXL_CLASSIFY_COUNT)) return 0;
    p->gradient_opacity = mode;
    return 1;
}
VIEW(gop_boundary_ref_tiny)
{
    sv_ball_tf(p);
    if (!sv_gop(p, vc, VXL_GOPACITY_BOUNDARY)) return;
    p->gradient_ref = 1e-30f;
    p->gradient_exp = 64;
}
VIEW(gop_boundary_ref_huge)
{
    sv_ball_tf(p);
    if (!sv_gop(p, vc, VXL_GOPACITY_BOUNDARY)) return;
    p->gradient_ref = 9.9e5f;
    p->gradient_exp = 1e-30f;
}
VIEW(gop_iso_thin)
{
    sv_ball_tf(p);
    if (!sv_gop(p, vc, VXL_GOPACITY_ISO)) return;
    p->iso_value = (float)(0.5 * (vc->value_min + vc->value_max));
    p->iso_thickness = 1e-30f;
}
VIEW(gop_iso_thick)
{
    sv_ball_tf(p);
    if (!sv_gop(p, vc, VXL_GOPACITY_ISO)) return;
    p->iso_value = (float)(0.5 * (vc->value_min + vc->value_max));
    p->iso_thickness = 1000;
}
VIEW(gop_iso_outside_data)
{
    sv_ball_tf(p);
    if (!sv_gop(p, vc, VXL_GOPACITY_ISO)) return;
    p->iso_value = -1e30f;
}
VIEW(gop_iso_constant_volume) /* zero gradient everywhere, value exactly at the iso value */
{
    sv_tf_table(p, vc, 256, 1);
    if (!sv_gop(p, vc, VXL_GOPACITY_ISO)) return;
    p->iso_value = (float)vc->value_min;
}
VIEW(preint_size_16) { (void)vc; sv_ball_tf(p); p->preint_size = 16; }
VIEW(preint_size_4096) { (void)vc; sv_ball_tf(p); p->preint_size = 4096; }
VIEW(preint_spike_large_step) { sv_tf_table(p, vc, 4096, 2); p->step = 7.5f; }
VIEW(preset_ct_window_default) { (void)vc; p->preset = VXL_PRESET_CT; }
VIEW(preset_bone) { (void)vc; p->preset = VXL_PRESET_BONE; }

/* steps */
static inline void sv_small_image(vxl_render_params *p, stress_view_ctx *vc)
{
    p->width = p->height = vc->env->small_image;
}
VIEW(step_1e_4) { sv_ball_tf(p); sv_small_image(p, vc); p->step = 1e-4f; }
VIEW(step_100) { (void)vc; sv_ball_tf(p); p->step = 100; }
VIEW(step_1e30) { (void)vc; sv_ball_tf(p); p->step = 1e30f; }
VIEW(step_denormal) { sv_ball_tf(p); sv_small_image(p, vc); p->step = 1e-40f; }
VIEW(step_1e_4_inside) { sv_small_image(p, vc); cam_inside_centre(p, vc); p->step = 1e-4f; }
VIEW(step_100_axis) { sv_axis_ortho(p, vc, 1); p->step = 100; }
VIEW(sample_distance_min) { (void)vc; sv_ball_tf(p); p->sample_distance = 1e-3f; }
VIEW(sample_distance_max) { (void)vc; sv_ball_tf(p); p->sample_distance = 64; }
VIEW(early_termination_min) { (void)vc; sv_ball_tf(p); p->early_termination = 1e-6f; p->depth_threshold = 1e-6f; }
VIEW(depth_threshold_one) { (void)vc; sv_ball_tf(p); p->depth_threshold = 1; p->opacity_scale = 1e6f; }
VIEW(no_skip_opaque) { (void)vc; sv_ball_tf(p); p->no_skip = 1; p->opacity_scale = 1e6f; }
VIEW(image_1x1) { (void)vc; sv_ball_tf(p); p->width = p->height = 1; }
VIEW(image_strip) { (void)vc; sv_ball_tf(p); p->width = 157; p->height = 1; }

/* lighting */
VIEW(lights_8_extreme)
{
    (void)vc;
    sv_ball_tf(p);
    p->light_count = VXL_MAX_LIGHTS;
    for (int i = 0; i < VXL_MAX_LIGHTS; i++) {
        vxl_light *l = &p->lights[i];
        l->position[0] = (float)((i & 1) ? 1e30 : -1e-30);
        l->position[1] = (float)((i & 2) ? 1 : -1);
        l->position[2] = (float)((i & 4) ? 1e-30 : -1e30);
        l->position[3] = (float)(i % 2);
        l->color[0] = 1e6f;
        l->color[1] = 0.5f;
        l->intensity = 1e6f;
    }
}
VIEW(light_point_at_centre) /* a point light on (within float rounding of) the first sample of the central ray */
{
    cam_inside_centre_axis(p, vc); /* near plane 0.01, looking down -Z, no jitter: samples at z = c - 0.01 - k */
    p->jitter_off = 1;
    p->step = 1;
    p->light_count = 1;
    p->lights[0].position[0] = (float)vc->c[0];
    p->lights[0].position[1] = (float)vc->c[1];
    p->lights[0].position[2] = (float)(vc->c[2] - 0.01);
    p->lights[0].position[3] = 1;
}
VIEW(light_point_at_eye)
{
    sv_ball_tf(p);
    double eye[3] = {vc->c[0] + 2 * vc->n, vc->c[1] - 1.5 * vc->n, vc->c[2] + vc->n};
    sv_camera(p, eye, vc->c, UP_Z, 45, 0.1, 100 * vc->n);
    p->light_count = 1;
    for (int a = 0; a < 3; a++) p->lights[0].position[a] = (float)eye[a];
    p->lights[0].position[3] = 1;
}
VIEW(light_tiny_direction)
{
    (void)vc;
    sv_ball_tf(p);
    p->light_count = 1;
    p->lights[0].position[2] = 1e-38f;
}
VIEW(material_extreme)
{
    (void)vc;
    sv_ball_tf(p);
    p->has_material = 1;
    p->ambient = p->diffuse = p->specular = 100;
    p->shininess = 1e4f;
}
VIEW(material_zero)
{
    (void)vc;
    sv_ball_tf(p);
    p->has_material = 1; /* all zero; shininess 0 */
}

/* The World's light at its extremes: radiance and strength at their
 * largest (every cell saturates), a rotation of many turns, no lamps, each
 * model that reads it; a uniform World with occlusion and a lamp. */
VIEW(environment_extreme)
{
    (void)vc;
    sv_ball_tf(p);
    static const float sky[4 * 2 * 3] = {0, 0, 0, 3.4e38f, 1e-38f, 0, 1e30f, 1e30f, 1e30f, 1, 2, 3,
                                          0, 1e6f, 0, 5, 5, 5, 3.4e38f, 3.4e38f, 3.4e38f, 0.5f, 0, 0};
    static vxl_environment env;
    env = (vxl_environment){.struct_size = sizeof env, .width = 4, .height = 2, .rgb = sky, .strength = 1e6f,
                            .rotation_deg = 1e30f};
    p->environment = &env;
    p->light_count = 0;
    p->shading_model = VXL_SHADING_SCATTER;
    p->anisotropy = 0.99f;
}
VIEW(environment_uniform_shadowed)
{
    (void)vc;
    sv_ball_tf(p);
    static const float grey[3] = {0.5f, 0.5f, 0.5f};
    static vxl_environment env;
    env = (vxl_environment){.struct_size = sizeof env, .width = 1, .height = 1, .rgb = grey, .strength = 1};
    p->environment = &env;
    p->shading_model = VXL_SHADING_SHADOWED;
    p->ambient_occlusion = 4;
    p->light_count = 1;
    p->lights[0].position[2] = 1;
}

/* The path tracer (PATH) at its extremes, in one case (one program per
 * filter): the World above, the largest material, a backward phase, a
 * lamp far away and a directional one, the longest paths, two samples from
 * the top of the index range. It refuses the gradient-opacity crossings
 * and the modes by name (a clean refusal). */
VIEW(path_extreme)
{
    environment_extreme(p, vc);
    p->has_material = 1;
    p->ambient = p->diffuse = p->specular = 100;
    p->shininess = 1e4f;
    p->shading_model = VXL_SHADING_PATH;
    p->anisotropy = -0.99f;
    p->light_count = 2;
    p->lights[0].position[2] = 1;
    p->lights[1].position[0] = 1e30f;
    p->lights[1].position[3] = 1;
    p->path_samples = 2;
    p->path_sample_offset = 0xfffffff0u;
    p->path_bounces = VXL_PATH_MAX_BOUNCES;
    p->path_seed = 0xffffffffu;
}

/* deliberately invalid inputs: each must give its error code with a message */
VIEW(bad_tf_size_zero) { sv_tf_table(p, vc, 256, 3); p->tf_size = 0; }
VIEW(bad_tf_size_one) { sv_tf_table(p, vc, 2, 3); p->tf_size = 1; }
VIEW(bad_tf_size_65537) { sv_tf_table(p, vc, 65537, 3); }
VIEW(bad_step_negative) { UNUSED_VIEW_ARGS; p->step = -0.5f; }
VIEW(bad_step_nan) { UNUSED_VIEW_ARGS; p->step = NAN; }
VIEW(bad_step_inf) { UNUSED_VIEW_ARGS; p->step = INFINITY; }
VIEW(bad_window_nan) { UNUSED_VIEW_ARGS; p->has_window = 1; p->window_low = NAN; p->window_high = 1; }
VIEW(bad_window_inf) { UNUSED_VIEW_ARGS; p->has_window = 1; p->window_low = 0; p->window_high = INFINITY; }
VIEW(bad_opacity_over) { UNUSED_VIEW_ARGS; p->opacity_scale = 2e6f; }
VIEW(bad_opacity_negative) { UNUSED_VIEW_ARGS; p->opacity_scale = -1; }
VIEW(bad_opacity_nan) { UNUSED_VIEW_ARGS; p->opacity_scale = NAN; }
VIEW(bad_view_nan) { cam_inside_centre(p, vc); p->view[5] = NAN; }
VIEW(bad_proj_zero) { cam_inside_centre(p, vc); memset(p->proj, 0, sizeof p->proj); }
VIEW(bad_model_singular) { UNUSED_VIEW_ARGS; p->has_model = 1; }
VIEW(bad_model_inf)
{
    UNUSED_VIEW_ARGS;
    p->has_model = 1;
    p->model[0] = p->model[5] = p->model[10] = p->model[15] = INFINITY;
}
VIEW(bad_azimuth_nan) { UNUSED_VIEW_ARGS; p->azimuth_deg = NAN; }
VIEW(bad_filter) { UNUSED_VIEW_ARGS; p->filter = VXL_FILTER_COUNT; }
VIEW(bad_classify) { UNUSED_VIEW_ARGS; p->classify = VXL_CLASSIFY_COUNT; }
VIEW(bad_gradient_store) { UNUSED_VIEW_ARGS; p->gradient_store = 3; }
VIEW(bad_sample_distance_small) { UNUSED_VIEW_ARGS; p->sample_distance = 1e-4f; }
VIEW(bad_sample_distance_nan) { UNUSED_VIEW_ARGS; p->sample_distance = NAN; }
VIEW(bad_early_termination) { UNUSED_VIEW_ARGS; p->early_termination = -1; }
VIEW(bad_depth_threshold) { UNUSED_VIEW_ARGS; p->depth_threshold = 2; }
VIEW(bad_light_count) { UNUSED_VIEW_ARGS; p->light_count = VXL_MAX_LIGHTS + 1; }
VIEW(bad_light_nan) { UNUSED_VIEW_ARGS; p->light_count = 1; p->lights[0].position[1] = NAN; }
VIEW(bad_light_zero_direction) { UNUSED_VIEW_ARGS; p->light_count = 1; }
VIEW(bad_light_colour)
{
    UNUSED_VIEW_ARGS;
    p->light_count = 1;
    p->lights[0].position[2] = 1;
    p->lights[0].color[0] = -1;
}
VIEW(bad_material_nan) { UNUSED_VIEW_ARGS; p->has_material = 1; p->ambient = NAN; }
VIEW(bad_image_too_wide) { UNUSED_VIEW_ARGS; p->width = 20000; p->height = 1; }
VIEW(bad_struct_size) { UNUSED_VIEW_ARGS; p->struct_size = 8; }
VIEW(bad_gradient_opacity) { UNUSED_VIEW_ARGS; p->gradient_opacity = VXL_GOPACITY_COUNT; }
VIEW(bad_gradient_ref) { UNUSED_VIEW_ARGS; p->gradient_opacity = VXL_GOPACITY_BOUNDARY; p->gradient_ref = -1; }
VIEW(bad_gradient_exp) { UNUSED_VIEW_ARGS; p->gradient_opacity = VXL_GOPACITY_BOUNDARY; p->gradient_exp = 65; }
VIEW(bad_iso_value) { UNUSED_VIEW_ARGS; p->gradient_opacity = VXL_GOPACITY_ISO; p->iso_value = NAN; }
VIEW(bad_iso_thickness) { UNUSED_VIEW_ARGS; p->gradient_opacity = VXL_GOPACITY_ISO; p->iso_thickness = 1001; }
VIEW(bad_preint_size_small) { UNUSED_VIEW_ARGS; p->preint_size = 15; }
VIEW(bad_preint_size_large) { UNUSED_VIEW_ARGS; p->preint_size = 4097; }
VIEW(bad_preset) { UNUSED_VIEW_ARGS; p->preset = VXL_PRESET_COUNT + 3; }
VIEW(bad_environment_pixel)
{
    UNUSED_VIEW_ARGS;
    static const float px[6] = {1, 1, 1, 1, NAN, 1};
    static vxl_environment env;
    env = (vxl_environment){.struct_size = sizeof env, .width = 2, .height = 1, .rgb = px, .strength = 1};
    p->environment = &env;
}

/* ------------------------------------------------------------------ cases */

enum {
    GROUP_values,
    GROUP_dtypes_and_scaling,
    GROUP_shapes,
    GROUP_affines,
    GROUP_cameras,
    GROUP_projections,
    GROUP_scene_depth,
    GROUP_classification,
    GROUP_steps,
    GROUP_lighting,
    GROUP_invalid_inputs,
    GROUP_COUNT
};

enum {
    F_VISIBLE = 1,            /* some pixel has alpha > 0 (without gradient-magnitude opacity) */
    F_EMPTY = 2,              /* every pixel transparent, depth +inf */
    F_SAME_AS_NO_DEPTH = 4,   /* equals the render without the scene depth, bit for bit */
    F_ALLOW_CREATE_ERROR = 8, /* vxl_volume_create may refuse the data cleanly instead */
    F_BAD_VOLUME = 16,        /* the volume itself is the invalid input: check recovery on a good one */
    F_TF_MATCHES_256 = 64,    /* the image equals (within rounding) the one with the 256-entry ramp */
    F_FULL_ONLY = 32,         /* --full only: the case needs a texture state of its own (8-bit volumes, no
                                 skipping), which costs llvmpipe a recompilation of every program */
    F_NEAR_INVARIANT = 128,   /* equals (within rounding) the image with the near plane at 0.1: the volume
                                 lies far beyond both, so the near plane must not change a pixel */
    F_ONE_FILTER = 256,       /* by default one filter (the case's index modulo VXL_FILTER_COUNT, so a group of
                                 such cases covers several), --full every filter: the case's programs are
                                 variants of their own (a colour volume's texture, the environment's light), each a cold compilation
                                 for llvmpipe in CI, and the filters' code is the same as in every other case */
};

typedef struct stress_case {
    const char *name;
    int group;
    stress_vol vol;
    void (*view)(vxl_render_params *p, stress_view_ctx *vc);
    int expect_rc;
    unsigned flags;
    unsigned alt_rc_mask; /* expect_rc OK: these clean errors (1 << code) are acceptable instead */
} stress_case;

#define F32 VXL_DTYPE_F32
#define N3 {0, 0, 0}
#define VOL(dt, fill) {dt, N3, fill, AFF_NONE, 0, 0, 0}
#define BALL VOL(F32, fill_ball)
#define BALL_AFF(aff) {F32, N3, fill_ball, aff, 0, 0, 0}
#define OK VXL_OK
#define BAD VXL_ERR_INVALID_ARGUMENT
#define TF_SIZE_ERRORS (1u << VXL_ERR_INVALID_ARGUMENT | 1u << VXL_ERR_LIMIT)

static const stress_case stress_cases[] = {
    /* values */
    {"const_zero", GROUP_values, VOL(F32, fill_zero), view_default, OK, 0, 0},
    {"const_three", GROUP_values, VOL(F32, fill_three), view_default, OK, 0, 0},
    {"const_minus_1e30", GROUP_values, VOL(F32, fill_minus_1e30), view_default, OK, 0, 0},
    {"const_u8_255", GROUP_values, VOL(VXL_DTYPE_U8, fill_u8_max), view_default, OK, F_FULL_ONLY, 0},
    {"const_three_opaque_tf", GROUP_values, VOL(F32, fill_three), tf_opaque_white, OK, F_VISIBLE, 0},
    {"single_bright_voxel", GROUP_values, VOL(F32, fill_bright_centre), view_default, OK, F_VISIBLE, 0},
    {"single_bright_corner_voxel", GROUP_values, VOL(F32, fill_bright_corner), view_default, OK, 0, 0},
    {"nan_voxels_in_ball", GROUP_values, VOL(F32, fill_nan_in_ball), view_default, OK, F_VISIBLE, 0},
    {"all_nan", GROUP_values, VOL(F32, fill_all_nan), view_default, OK, 0, 0},
    {"inf_voxels_in_ball", GROUP_values, VOL(F32, fill_inf_in_ball), view_default, OK, F_VISIBLE, 0},
    {"all_pos_inf", GROUP_values, VOL(F32, fill_all_pos_inf), view_default, OK, 0, 0},
    {"all_neg_inf", GROUP_values, VOL(F32, fill_all_neg_inf), view_default, OK, 0, 0},
    {"nan_inf_mix", GROUP_values, VOL(F32, fill_nan_inf_mix), view_default, OK, 0, 0},
    {"pm_1e30_checker", GROUP_values, VOL(F32, fill_pm_1e30), view_default, OK, 0, 0},
    {"ball_times_1e30", GROUP_values, VOL(F32, fill_ball_1e30), opacity_1e6_huge_values, OK, F_VISIBLE, 0},
    {"pm_flt_max_checker", GROUP_values, VOL(F32, fill_pm_flt_max), view_default, OK, 0, 0},
    {"denormals", GROUP_values, VOL(F32, fill_denormals), view_default, OK, 0, 0},
    {"denormal_ball", GROUP_values, VOL(F32, fill_denormal_ball), view_default, OK, F_VISIBLE, 0},
    {"denormals_and_pm_1e30", GROUP_values, VOL(F32, fill_denormal_and_1e30), view_default, OK, 0, 0},
    {"range_below_float_resolution", GROUP_values, VOL(F32, fill_tiny_range), view_default, OK, 0, 0},

    /* data types and value scaling */
    {"i16_extremes_checker", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_I16, fill_i16_checker), view_default, OK, 0, 0},
    {"i16_constant_min", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_I16, fill_i16_min), view_default, OK, 0, 0},
    {"i16_ball_at_extremes", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_I16, fill_i16_ball_extremes), preset_bone, OK,
     F_VISIBLE, 0},
    {"i16_extremes_ct_preset", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_I16, fill_i16_checker),
     preset_ct_window_default, OK, 0, 0},
    {"i8_extremes_checker", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_I8, fill_i8_checker), view_default, OK,
     F_FULL_ONLY, 0},
    {"u16_full_range_ball", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_U16, fill_u16_max_ball), view_default, OK,
     F_VISIBLE, 0},
    /* colour volumes: the voxels' colour beside the luminance scalar (docs/colour.md) */
    {"colour_rgb_u8_const", GROUP_dtypes_and_scaling, {VXL_DTYPE_U8, N3, fill_u8_max, AFF_NONE, 0, 0, 3}, view_default,
     OK, F_ONE_FILTER, 0},
    {"colour_rgba_u16_ball", GROUP_dtypes_and_scaling, {VXL_DTYPE_U16, N3, fill_u16_max_ball, AFF_NONE, 0, 0, 4},
     view_default, OK, F_ONE_FILTER, 0},
    {"colour_rgb_f32_nan_inf_mix", GROUP_dtypes_and_scaling, {F32, N3, fill_nan_inf_mix, AFF_NONE, 0, 0, 3},
     view_default, OK, F_ONE_FILTER, 0},
    {"colour_rgb_f64_max_and_nan", GROUP_dtypes_and_scaling, {VXL_DTYPE_F64, N3, fill_f64_max_and_nan, AFF_ROT_SHEAR, 0, 0, 3},
     view_default, OK, F_ONE_FILTER, 0},
    /* multi-channel volumes: the scalar (channel 0) through the matrix, and
     * every channel drawn in one march (test_stress.c, render_channels):
     * two texture groups lit, one group of float channels with NaN and Inf */
    {"channels_u16_ball_6", GROUP_dtypes_and_scaling, {VXL_DTYPE_U16, N3, fill_u16_max_ball, AFF_NONE, 0, 0, SV_CHANNELS(6)},
     view_default, OK, 0, 0},
    {"channels_f32_nan_inf_mix_3", GROUP_dtypes_and_scaling, {F32, N3, fill_nan_inf_mix, AFF_ROT_SHEAR, 0, 0, SV_CHANNELS(3)},
     view_default, OK, 0, 0},
    {"i32_extremes_checker", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_I32, fill_i32_checker), view_default, OK, 0, 0},
    {"u32_full_range_ball", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_U32, fill_u32_max_ball), view_default, OK,
     F_VISIBLE, 0},
    {"f64_pm_1e300_checker", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_F64, fill_pm_1e300), view_default, OK, 0, 0},
    {"f64_denormal_ball", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_F64, fill_f64_denormal_ball), view_default, OK,
     F_VISIBLE, 0},
    {"f64_max_and_nan", GROUP_dtypes_and_scaling, VOL(VXL_DTYPE_F64, fill_f64_max_and_nan), view_default, OK, 0, 0},
    {"scl_slope_zero", GROUP_dtypes_and_scaling, {VXL_DTYPE_I16, N3, fill_i16_ramp, AFF_NONE, 0, 5, 0}, view_default,
     OK, 0, 0},
    {"scl_slope_negative_i16", GROUP_dtypes_and_scaling, {VXL_DTYPE_I16, N3, fill_i16_ball, AFF_NONE, -1, 0, 0},
     view_default, OK, F_VISIBLE, 0},
    {"scl_slope_negative_f32", GROUP_dtypes_and_scaling, {F32, N3, fill_ball, AFF_NONE, -3, 1, 0}, view_default, OK,
     F_VISIBLE, 0},
    {"scl_slope_negative_huge", GROUP_dtypes_and_scaling, {VXL_DTYPE_I16, N3, fill_i16_checker, AFF_NONE, -1e30, 7, 0},
     view_default, OK, 0, 0},
    {"scl_slope_tiny", GROUP_dtypes_and_scaling, {VXL_DTYPE_I16, N3, fill_i16_ramp, AFF_NONE, 1e-300, 0, 0},
     view_default, OK, 0, 0},
    {"scl_slope_overflows_double", GROUP_dtypes_and_scaling,
     {VXL_DTYPE_I16, N3, fill_i16_checker, AFF_NONE, 1e305, 0, 0}, view_default, OK, F_ALLOW_CREATE_ERROR, 0},
    {"scl_slope_negative_window", GROUP_dtypes_and_scaling, {VXL_DTYPE_I16, N3, fill_i16_ball, AFF_NONE, -1, 0, 0},
     window_inverted, OK, 0, 0},

    /* shapes */
    {"dims_1x1x1", GROUP_shapes, {F32, {1, 1, 1}, fill_five, AFF_NONE, 0, 0, 0}, view_default, OK, 0, 0},
    {"dims_1x1x1_opaque", GROUP_shapes, {F32, {1, 1, 1}, fill_five, AFF_NONE, 0, 0, 0}, tf_opaque_white, OK,
     F_VISIBLE, 0},
    {"dims_1x1x1_nan", GROUP_shapes, {F32, {1, 1, 1}, fill_all_nan, AFF_NONE, 0, 0, 0}, view_default, OK, 0, 0},
    {"dims_2x2x2", GROUP_shapes, {F32, {2, 2, 2}, fill_index, AFF_NONE, 0, 0, 0}, view_default, OK, 0, 0},
    {"dims_2x2x2_i16", GROUP_shapes, {VXL_DTYPE_I16, {2, 2, 2}, fill_i16_checker, AFF_NONE, 0, 0, 0}, view_default,
     OK, 0, 0},
    {"dims_1xNxN", GROUP_shapes, {F32, {1, 0, 0}, fill_ball, AFF_NONE, 0, 0, 0}, view_ball_default, OK, F_VISIBLE, 0},
    {"dims_Nx1xN", GROUP_shapes, {F32, {0, 1, 0}, fill_ball, AFF_NONE, 0, 0, 0}, view_ball_default, OK, F_VISIBLE, 0},
    {"dims_NxNx1", GROUP_shapes, {F32, {0, 0, 1}, fill_ball, AFF_NONE, 0, 0, 0}, view_ball_default, OK, F_VISIBLE, 0},
    {"dims_1x1xN", GROUP_shapes, {F32, {1, 1, 0}, fill_index, AFF_NONE, 0, 0, 0}, view_default, OK, 0, 0},
    {"dims_Nx1x1", GROUP_shapes, {F32, {0, 1, 1}, fill_index, AFF_NONE, 0, 0, 0}, view_default, OK, 0, 0},
    {"dims_1xNxN_edge_on", GROUP_shapes, {F32, {1, 0, 0}, fill_ball, AFF_NONE, 0, 0, 0}, axis_ortho_minus_y, OK, 0, 0},
    {"dims_1xNxN_face_on", GROUP_shapes, {F32, {1, 0, 0}, fill_ball, AFF_NONE, 0, 0, 0}, axis_ortho_plus_x, OK,
     F_VISIBLE, 0},

    /* affines */
    {"aniso_affine_0.1_1_10", GROUP_affines, BALL_AFF(AFF_ANISO), view_default, OK, F_VISIBLE, 0},
    {"aniso_spacing_0.1_1_10", GROUP_affines, BALL_AFF(AFF_SPACING_ANISO), view_default, OK, F_VISIBLE, 0},
    {"huge_affine_1e6", GROUP_affines, BALL_AFF(AFF_HUGE), view_default, OK, F_VISIBLE, 0},
    {"tiny_affine_1e-6", GROUP_affines, BALL_AFF(AFF_TINY), view_default, OK, F_VISIBLE, 0},
    {"rotated_sheared_affine", GROUP_affines, BALL_AFF(AFF_ROT_SHEAR), view_default, OK, F_VISIBLE, 0},
    {"flipped_affine", GROUP_affines, BALL_AFF(AFF_FLIP), view_default, OK, F_VISIBLE, 0},
    {"far_translated_affine_1e7", GROUP_affines, BALL_AFF(AFF_FAR), view_default, OK, 0, 0},
    {"extreme_aniso_affine_1e6_1e-6_1", GROUP_affines, BALL_AFF(AFF_EXTREME_ANISO), view_default, OK, 0, 0},
    {"huge_affine_top_view", GROUP_affines, BALL_AFF(AFF_HUGE), default_cam_top, OK, F_VISIBLE, 0},

    /* cameras */
    {"camera_inside", GROUP_cameras, BALL, cam_inside_centre, OK, F_VISIBLE, 0},
    {"camera_inside_axis_parallel", GROUP_cameras, BALL, cam_inside_centre_axis, OK, F_VISIBLE, 0},
    {"camera_inside_corner_looking_out", GROUP_cameras, BALL, cam_inside_corner_looking_out, OK, 0, 0},
    {"camera_on_face_looking_in", GROUP_cameras, BALL, cam_on_face_looking_in, OK, F_VISIBLE, 0},
    {"camera_on_face_looking_out", GROUP_cameras, BALL, cam_on_face_looking_out, OK, F_EMPTY, 0},
    {"camera_on_corner", GROUP_cameras, BALL, cam_on_corner, OK, F_VISIBLE, 0},
    {"camera_ray_along_edge", GROUP_cameras, BALL, cam_along_edge, OK, 0, 0},
    {"persp_central_ray_in_face", GROUP_cameras, BALL, cam_persp_on_face_plane, OK, F_VISIBLE, 0},
    {"persp_central_ray_on_voxel_planes", GROUP_cameras, BALL, cam_persp_on_voxel_planes, OK, F_VISIBLE, 0},
    {"axis_rays_minus_x", GROUP_cameras, BALL, axis_ortho_minus_x, OK, F_VISIBLE, 0},
    {"axis_rays_plus_x", GROUP_cameras, BALL, axis_ortho_plus_x, OK, F_VISIBLE, 0},
    {"axis_rays_minus_y", GROUP_cameras, BALL, axis_ortho_minus_y, OK, F_VISIBLE, 0},
    {"axis_rays_plus_y", GROUP_cameras, BALL, axis_ortho_plus_y, OK, F_VISIBLE, 0},
    {"axis_rays_minus_z", GROUP_cameras, BALL, axis_ortho_minus_z, OK, F_VISIBLE, 0},
    {"axis_rays_plus_z", GROUP_cameras, BALL, axis_ortho_plus_z, OK, F_VISIBLE, 0},
    {"default_camera_top", GROUP_cameras, BALL, default_cam_top, OK, F_VISIBLE, 0},
    {"default_camera_bottom", GROUP_cameras, BALL, default_cam_bottom, OK, F_VISIBLE, 0},
    {"default_camera_front", GROUP_cameras, BALL, default_cam_front, OK, F_VISIBLE, 0},
    {"default_camera_huge_angles", GROUP_cameras, BALL, default_cam_huge_angles, OK, F_VISIBLE, 0},

    /* projections */
    {"near_1e-6_far_1e9", GROUP_projections, BALL, proj_near_1e6_far_1e9, OK, F_VISIBLE | F_NEAR_INVARIANT, 0},
    {"near_1e-6_far_1e9_distant_camera", GROUP_projections, BALL, proj_near_1e6_distant, OK, F_VISIBLE | F_NEAR_INVARIANT, 0},
    {"near_1e-3_far_1e6", GROUP_projections, BALL, proj_near_1e3_far_1e6, OK, F_VISIBLE | F_NEAR_INVARIANT, 0},
    {"near_eq_far_0.999999", GROUP_projections, BALL, proj_near_eq_far, OK, 0, 0},
    {"near_eq_far_ortho", GROUP_projections, BALL, proj_near_eq_far_ortho, OK, 0, 0},
    {"infinite_far_plane", GROUP_projections, BALL, proj_infinite_far, OK, F_VISIBLE, 0},
    {"reversed_depth_range", GROUP_projections, BALL, proj_reversed_depth, OK, 0, 0},
    {"ortho_oblique", GROUP_projections, BALL, proj_ortho_oblique, OK, F_VISIBLE, 0},
    {"ortho_near_plane_inside", GROUP_projections, BALL, proj_ortho_inside, OK, F_VISIBLE, 0},
    {"ortho_huge_extent", GROUP_projections, BALL, proj_ortho_huge_extent, OK, 0, 0},
    {"fov_1e-4_degrees", GROUP_projections, BALL, proj_fov_tiny, OK, F_VISIBLE, 0},
    {"fov_179.9_degrees", GROUP_projections, BALL, proj_fov_179, OK, 0, 0},
    {"camera_1e6_away_narrow_fov", GROUP_projections, BALL, proj_far_away_camera, OK, F_VISIBLE, 0},
    {"off_centre_frustum", GROUP_projections, BALL, proj_off_centre_frustum, OK, 0, 0},

    /* scene depth */
    {"scene_depth_zero", GROUP_scene_depth, BALL, depth_zero, OK, F_EMPTY, 0},
    {"scene_depth_inf", GROUP_scene_depth, BALL, depth_inf, OK, F_VISIBLE | F_SAME_AS_NO_DEPTH, 0},
    {"scene_depth_flt_max", GROUP_scene_depth, BALL, depth_flt_max, OK, F_VISIBLE | F_SAME_AS_NO_DEPTH, 0},
    {"scene_depth_nan", GROUP_scene_depth, BALL, depth_nan, OK, 0, 0},
    {"scene_depth_negative", GROUP_scene_depth, BALL, depth_negative, OK, 0, 0},
    {"scene_depth_minus_inf", GROUP_scene_depth, BALL, depth_minus_inf, OK, 0, 0},
    {"scene_depth_denormal", GROUP_scene_depth, BALL, depth_denormal, OK, F_EMPTY, 0},
    {"scene_depth_checker_zero_inf", GROUP_scene_depth, BALL, depth_checker, OK, F_VISIBLE, 0},
    {"scene_depth_zero_camera_inside", GROUP_scene_depth, BALL, depth_zero_inside, OK, F_EMPTY, 0},
    {"scene_depth_inf_ortho_axis", GROUP_scene_depth, BALL, depth_inf_ortho, OK, F_VISIBLE | F_SAME_AS_NO_DEPTH, 0},
    {"scene_depth_zero_ortho_axis", GROUP_scene_depth, BALL, depth_zero_ortho, OK, F_EMPTY, 0},

    /* classification */
    {"window_low_eq_high", GROUP_classification, BALL, window_degenerate, OK, F_VISIBLE, 0},
    {"window_low_eq_high_zero", GROUP_classification, BALL, window_degenerate_zero, OK, 0, 0},
    {"window_low_eq_high_1e30", GROUP_classification, BALL, window_degenerate_1e30, OK, 0, 0},
    {"window_inverted", GROUP_classification, BALL, window_inverted, OK, 0, 0},
    {"window_pm_1e30", GROUP_classification, BALL, window_huge, OK, 0, 0},
    {"window_pm_flt_max", GROUP_classification, BALL, window_flt_max, OK, 0, 0},
    {"window_one_ulp", GROUP_classification, BALL, window_tiny, OK, F_VISIBLE, 0},
    {"window_denormal_width", GROUP_classification, BALL, window_denormal, OK, F_VISIBLE, 0},
    {"window_far_above_data", GROUP_classification, BALL, window_far_above, OK, F_EMPTY, 0},
    {"opacity_scale_1e6", GROUP_classification, BALL, opacity_1e6, OK, F_VISIBLE, 0},
    {"opacity_scale_1e-30", GROUP_classification, BALL, opacity_tiny, OK, 0, 0},
    {"tf_nan_inf_entries", GROUP_classification, BALL, tf_nan_inf_entries, OK, 0, 0},
    {"tf_opaque_white", GROUP_classification, BALL, tf_opaque_white, OK, F_VISIBLE, 0},
    {"tf_single_entry_spike", GROUP_classification, BALL, tf_spike, OK, 0, 0},
    {"tf_size_2", GROUP_classification, BALL, tf_size_2, OK, F_VISIBLE, 0},
    /* the API takes up to 65536 entries; llvmpipe's 1D textures stop at 16384: either works or a clean
     * up-front refusal, never a GL error or a silently wrong image */
    {"tf_size_16384", GROUP_classification, BALL, tf_size_16384, OK, F_VISIBLE | F_TF_MATCHES_256, TF_SIZE_ERRORS},
    {"tf_size_16385", GROUP_classification, BALL, tf_size_16385, OK, F_VISIBLE | F_TF_MATCHES_256, TF_SIZE_ERRORS},
    {"tf_size_65536", GROUP_classification, BALL, tf_size_65536, OK, F_VISIBLE | F_TF_MATCHES_256, TF_SIZE_ERRORS},
    {"gradient_opacity_ref_1e-30_exp_64", GROUP_classification, BALL, gop_boundary_ref_tiny, OK, 0, 0},
    {"gradient_opacity_ref_1e6_exp_1e-30", GROUP_classification, BALL, gop_boundary_ref_huge, OK, 0, 0},
    {"iso_thickness_1e-30", GROUP_classification, BALL, gop_iso_thin, OK, 0, 0},
    {"iso_thickness_1000", GROUP_classification, BALL, gop_iso_thick, OK, 0, 0},
    {"iso_value_outside_data", GROUP_classification, BALL, gop_iso_outside_data, OK, 0, 0},
    {"iso_on_constant_volume", GROUP_classification, VOL(F32, fill_three), gop_iso_constant_volume, OK, 0, 0},
    {"preint_size_16", GROUP_classification, BALL, preint_size_16, OK, F_VISIBLE, 0},
    {"preint_size_4096", GROUP_classification, BALL, preint_size_4096, OK, F_VISIBLE | F_FULL_ONLY, 0},
    {"spike_tf_step_7.5", GROUP_classification, BALL, preint_spike_large_step, OK, 0, 0},

    /* steps and termination */
    {"step_1e-4", GROUP_steps, BALL, step_1e_4, OK, F_VISIBLE, 0},
    {"step_100", GROUP_steps, BALL, step_100, OK, 0, 0},
    {"step_1e30", GROUP_steps, BALL, step_1e30, OK, 0, 0},
    {"step_denormal", GROUP_steps, BALL, step_denormal, OK, F_VISIBLE, 0},
    {"step_1e-4_camera_inside", GROUP_steps, BALL, step_1e_4_inside, OK, F_VISIBLE, 0},
    {"step_100_axis_rays", GROUP_steps, BALL, step_100_axis, OK, 0, 0},
    {"step_1e-4_big_volume", GROUP_steps, {F32, {BIG_N, BIG_N, BIG_N}, fill_ball, AFF_NONE, 0, 0, 0}, step_1e_4, OK,
     F_VISIBLE, 0},
    {"sample_distance_1e-3", GROUP_steps, BALL, sample_distance_min, OK, F_VISIBLE, 0},
    {"sample_distance_64", GROUP_steps, BALL, sample_distance_max, OK, F_VISIBLE, 0},
    {"early_termination_1e-6", GROUP_steps, BALL, early_termination_min, OK, F_VISIBLE, 0},
    {"depth_threshold_1", GROUP_steps, BALL, depth_threshold_one, OK, F_VISIBLE, 0},
    {"no_skip_opaque", GROUP_steps, BALL, no_skip_opaque, OK, F_VISIBLE | F_FULL_ONLY, 0},
    {"image_1x1", GROUP_steps, BALL, image_1x1, OK, 0, 0},
    {"image_157x1", GROUP_steps, BALL, image_strip, OK, 0, 0},

    /* lighting */
    {"eight_extreme_lights", GROUP_lighting, BALL, lights_8_extreme, OK, F_VISIBLE, 0},
    {"point_light_on_a_sample", GROUP_lighting, BALL, light_point_at_centre, OK, F_VISIBLE, 0},
    {"point_light_at_the_eye", GROUP_lighting, BALL, light_point_at_eye, OK, F_VISIBLE, 0},
    {"light_direction_1e-38", GROUP_lighting, BALL, light_tiny_direction, OK, F_VISIBLE, 0},
    {"material_extreme", GROUP_lighting, BALL, material_extreme, OK, F_VISIBLE, 0},
    {"material_zero", GROUP_lighting, BALL, material_zero, OK, 0, 0},
    {"environment_extreme", GROUP_lighting, BALL, environment_extreme, OK, F_VISIBLE | F_ONE_FILTER, 0},
    {"environment_uniform_shadowed", GROUP_lighting, BALL, environment_uniform_shadowed, OK, F_VISIBLE | F_ONE_FILTER, 0},
    {"path_extreme", GROUP_lighting, BALL, path_extreme, OK, F_VISIBLE | F_ONE_FILTER, 1u << VXL_ERR_INVALID_ARGUMENT},

    /* deliberately invalid inputs */
    {"invalid_tf_size_zero", GROUP_invalid_inputs, BALL, bad_tf_size_zero, BAD, 0, 0},
    {"invalid_tf_size_one", GROUP_invalid_inputs, BALL, bad_tf_size_one, BAD, 0, 0},
    {"invalid_tf_size_65537", GROUP_invalid_inputs, BALL, bad_tf_size_65537, BAD, 0, 0},
    {"invalid_step_negative", GROUP_invalid_inputs, BALL, bad_step_negative, BAD, 0, 0},
    {"invalid_step_nan", GROUP_invalid_inputs, BALL, bad_step_nan, BAD, 0, 0},
    {"invalid_step_inf", GROUP_invalid_inputs, BALL, bad_step_inf, BAD, 0, 0},
    {"invalid_window_nan", GROUP_invalid_inputs, BALL, bad_window_nan, BAD, 0, 0},
    {"invalid_window_inf", GROUP_invalid_inputs, BALL, bad_window_inf, BAD, 0, 0},
    {"invalid_opacity_scale_2e6", GROUP_invalid_inputs, BALL, bad_opacity_over, BAD, 0, 0},
    {"invalid_opacity_scale_negative", GROUP_invalid_inputs, BALL, bad_opacity_negative, BAD, 0, 0},
    {"invalid_opacity_scale_nan", GROUP_invalid_inputs, BALL, bad_opacity_nan, BAD, 0, 0},
    {"invalid_view_nan", GROUP_invalid_inputs, BALL, bad_view_nan, BAD, 0, 0},
    {"invalid_projection_zero", GROUP_invalid_inputs, BALL, bad_proj_zero, BAD, 0, 0},
    {"invalid_model_singular", GROUP_invalid_inputs, BALL, bad_model_singular, BAD, 0, 0},
    {"invalid_model_inf", GROUP_invalid_inputs, BALL, bad_model_inf, BAD, 0, 0},
    {"invalid_affine_singular", GROUP_invalid_inputs, BALL_AFF(AFF_SINGULAR), view_default, BAD, F_BAD_VOLUME, 0},
    {"invalid_affine_nan", GROUP_invalid_inputs, BALL_AFF(AFF_NAN), view_default, BAD,
     F_ALLOW_CREATE_ERROR | F_BAD_VOLUME, 0},
    {"invalid_azimuth_nan", GROUP_invalid_inputs, BALL, bad_azimuth_nan, BAD, 0, 0},
    {"invalid_filter", GROUP_invalid_inputs, BALL, bad_filter, BAD, 0, 0},
    {"invalid_classify", GROUP_invalid_inputs, BALL, bad_classify, BAD, 0, 0},
    {"invalid_gradient_store", GROUP_invalid_inputs, BALL, bad_gradient_store, BAD, 0, 0},
    {"invalid_sample_distance_1e-4", GROUP_invalid_inputs, BALL, bad_sample_distance_small, BAD, 0, 0},
    {"invalid_sample_distance_nan", GROUP_invalid_inputs, BALL, bad_sample_distance_nan, BAD, 0, 0},
    {"invalid_early_termination", GROUP_invalid_inputs, BALL, bad_early_termination, BAD, 0, 0},
    {"invalid_depth_threshold", GROUP_invalid_inputs, BALL, bad_depth_threshold, BAD, 0, 0},
    {"invalid_light_count", GROUP_invalid_inputs, BALL, bad_light_count, BAD, 0, 0},
    {"invalid_light_nan", GROUP_invalid_inputs, BALL, bad_light_nan, BAD, 0, 0},
    {"invalid_light_zero_direction", GROUP_invalid_inputs, BALL, bad_light_zero_direction, BAD, 0, 0},
    {"invalid_light_colour", GROUP_invalid_inputs, BALL, bad_light_colour, BAD, 0, 0},
    {"invalid_material_nan", GROUP_invalid_inputs, BALL, bad_material_nan, BAD, 0, 0},
    {"invalid_image_20000_wide", GROUP_invalid_inputs, BALL, bad_image_too_wide, VXL_ERR_LIMIT, 0, 0},
    {"invalid_struct_size", GROUP_invalid_inputs, BALL, bad_struct_size, BAD, 0, 0},
    {"invalid_gradient_opacity_mode", GROUP_invalid_inputs, BALL, bad_gradient_opacity, BAD, 0, 0},
    {"invalid_gradient_ref_negative", GROUP_invalid_inputs, BALL, bad_gradient_ref, BAD, 0, 0},
    {"invalid_gradient_exp_65", GROUP_invalid_inputs, BALL, bad_gradient_exp, BAD, 0, 0},
    {"invalid_iso_value_nan", GROUP_invalid_inputs, BALL, bad_iso_value, BAD, 0, 0},
    {"invalid_iso_thickness_1001", GROUP_invalid_inputs, BALL, bad_iso_thickness, BAD, 0, 0},
    {"invalid_preint_size_15", GROUP_invalid_inputs, BALL, bad_preint_size_small, BAD, 0, 0},
    {"invalid_preint_size_4097", GROUP_invalid_inputs, BALL, bad_preint_size_large, BAD, 0, 0},
    {"invalid_preset", GROUP_invalid_inputs, BALL, bad_preset, BAD, 0, 0},
    {"invalid_environment_pixel", GROUP_invalid_inputs, BALL, bad_environment_pixel, BAD, 0, 0},
};

#define STRESS_CASE_COUNT (sizeof stress_cases / sizeof stress_cases[0])

/* ------------------------------------------------------------ variants */

static const char *const stress_variant_names[STRESS_VARIANTS_FULL] = {
    "base", "view_front", "view_top", "view_below", "step_0.1", "step_2.5",
    "sd_0.25", "sd_3", "store_16f", "store_32f", "jitter_off", "seed_max"};

static inline const char *stress_variant_name(int v)
{
    return v >= 0 && v < STRESS_VARIANTS_FULL ? stress_variant_names[v] : "?";
}

static inline int stress_variant_moves_camera(int v) { return v >= 1 && v <= 3; }

/* Applies variant v to p (after the case's view); 0 = the variant does not
 * apply to this render (skip it). The invalid-input cases keep their one
 * invalid field: only the base variant. */
static inline int stress_apply_variant(vxl_render_params *p, const stress_view_ctx *vc, const stress_case *c, int v)
{
    (void)vc;
    if (c->expect_rc != VXL_OK) return v == 0;
    int default_view = !p->has_camera && p->azimuth_deg == 30 && p->elevation_deg == 20;
    int gradients = !p->shading_off;
    switch (v) {
    case 0: return 1;
    case 1: if (!default_view) return 0; p->azimuth_deg = 0; p->elevation_deg = 0; return 1;
    case 2: if (!default_view) return 0; p->azimuth_deg = 45; p->elevation_deg = 90; return 1;
    case 3: if (!default_view) return 0; p->azimuth_deg = -137.5f; p->elevation_deg = -63; return 1;
    case 4: if (p->step != 0) return 0; p->step = 0.1f; return 1;
    case 5: if (p->step != 0) return 0; p->step = 2.5f; return 1;
    case 6: if (p->sample_distance != 0 || !gradients) return 0; p->sample_distance = 0.25f; return 1;
    case 7: if (p->sample_distance != 0 || !gradients) return 0; p->sample_distance = 3; return 1;
    case 8:
    case 9:
        if (p->filter != VXL_FILTER_PRECOMPUTED || !gradients) return 0;
        p->gradient_store = v == 8 ? VXL_GRADIENT_STORE_16F : VXL_GRADIENT_STORE_32F;
        return 1;
    case 10: if (p->jitter_off) return 0; p->jitter_off = 1; return 1;
    case 11: p->jitter_seed = 0xFFFFFFFFu; return 1;
    default: return 0;
    }
}

/* ------------------------------------------------------ render modes */

/* The renders each case gets beside the DVR matrix: every render
 * mode but DVR, ISO shaded by a MatCap, and a cutaway (a clip plane through
 * the volume's centre, half-space and slab) on DVR and MIP. */
enum { SM_MIP, SM_MINIP, SM_AVERAGE, SM_ISO, SM_ISO_MATCAP, SM_DVR_CUT, SM_MIP_SLAB, SM_COUNT };

static inline const char *stress_mode_render_name(int m)
{
    static const char *const names[SM_COUNT] = {"mip", "minip", "average", "iso", "iso+matcap", "dvr+clip", "mip+slab"};
    return m >= 0 && m < SM_COUNT ? names[m] : "?";
}

/* Sets p (after the case's view) for render m, with mc and cut as
 * the MatCap and cutaway it may point to. For a valid case the classify,
 * gradient-opacity and technique settings the modes refuse are reset (the
 * DVR matrix covers those); an invalid case keeps what makes it invalid. */
static inline void stress_mode_params(vxl_render_params *p, int m, int valid, const stress_view_ctx *vc, vxl_matcap *mc,
                                      vxl_cutaway *cut)
{
    static const float cap[2 * 2 * 4] = {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 1};
    const uint32_t modes[SM_COUNT] = {VXL_MODE_MIP, VXL_MODE_MINIP, VXL_MODE_AVERAGE, VXL_MODE_ISO, VXL_MODE_ISO,
                                      VXL_MODE_DVR, VXL_MODE_MIP};
    p->mode = modes[m];
    if (valid && m != SM_DVR_CUT) {
        p->classify = VXL_CLASSIFY_POST;
        p->gradient_opacity = VXL_GOPACITY_OFF;
        p->technique = VXL_TECHNIQUE_RAYCAST;
    }
    if (m == SM_ISO_MATCAP) {
        *mc = (vxl_matcap){.struct_size = sizeof *mc, .width = 2, .height = 2, .rgba = cap, .key = 19};
        p->matcap = mc;
    }
    if (m == SM_DVR_CUT || m == SM_MIP_SLAB) {
        memset(cut, 0, sizeof *cut);
        cut->struct_size = sizeof *cut;
        cut->clip_plane_count = 1;
        /* keeps x + 0.3 y - 0.2 z >= that of the centre (voxel = world for the identity-affine cases) */
        const float n[3] = {1.0f, 0.3f, -0.2f};
        cut->clip_planes[0].plane[0] = n[0];
        cut->clip_planes[0].plane[1] = n[1];
        cut->clip_planes[0].plane[2] = n[2];
        cut->clip_planes[0].plane[3] = -(float)(n[0] * vc->c[0] + n[1] * vc->c[1] + n[2] * vc->c[2]);
        cut->clip_planes[0].thickness = m == SM_MIP_SLAB ? (float)(0.25 * vc->n) : 0.0f;
        p->cutaway = cut;
    }
}

#undef F32
#undef N3
#undef VOL
#undef BALL
#undef BALL_AFF
#undef OK
#undef BAD
#undef TF_SIZE_ERRORS

#endif
