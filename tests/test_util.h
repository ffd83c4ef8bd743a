/* test_util.h - shared helpers for the C tests: analytic volumes, a renderer
 * on the requested backend, image checks. */
#ifndef VXL_TEST_UTIL_H
#define VXL_TEST_UTIL_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dynlib.h"
#include "os.h"
#include "scenes.h"
#include "voxlight.h"

typedef double (*field_fn)(double x, double y, double z, const double *prm);

/* A float32 volume sampled from f at voxel centres (voxel-space coords). */
static inline vxl_volume *make_volume_f32(uint32_t nx, uint32_t ny, uint32_t nz, field_fn f, const double *prm)
{
    float *d = malloc(sizeof(float) * nx * ny * nz);
    if (!d) return NULL;
    for (uint32_t k = 0; k < nz; k++)
        for (uint32_t j = 0; j < ny; j++)
            for (uint32_t i = 0; i < nx; i++) d[i + nx * (j + ny * k)] = (float)f(i, j, k, prm);
    vxl_volume_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.struct_size = sizeof desc;
    desc.dtype = VXL_DTYPE_F32;
    desc.dims[0] = nx;
    desc.dims[1] = ny;
    desc.dims[2] = nz;
    desc.data = d;
    vxl_volume *v = NULL;
    vxl_volume_create(&desc, NULL, &v);
    free(d);
    return v;
}

/* prm: a, b, c, d of f = a x + b y + c z + d */
static inline double field_ramp(double x, double y, double z, const double *p)
{
    return p[0] * x + p[1] * y + p[2] * z + p[3];
}

/* prm: cx, cy, cz, sigma: a smooth Gaussian blob, value in (0,1] */
static inline double field_blob(double x, double y, double z, const double *p)
{
    double dx = x - p[0], dy = y - p[1], dz = z - p[2];
    return exp(-(dx * dx + dy * dy + dz * dz) / (2 * p[3] * p[3]));
}

/* prm: cx, cy, cz, radius: 1 inside a ball, 0 outside, smoothed over ~1 voxel */
static inline double field_ball(double x, double y, double z, const double *p)
{
    double r = sqrt((x - p[0]) * (x - p[0]) + (y - p[1]) * (y - p[1]) + (z - p[2]) * (z - p[2]));
    return 1.0 / (1.0 + exp(2.0 * (r - p[3])));
}

static inline double angle_deg(const float *a, const double *b)
{
    double la = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
    double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    if (!(la > 0) || !(lb > 0)) return 180.0;
    double c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
    c = c > 1 ? 1 : c < -1 ? -1 : c;
    return acos(c) * 180.0 / M_PI;
}

/* 1 if Mesa's OSMesa can be loaded, as the library loads it (same soname).
 * The handle stays open: llvmpipe is not safe to unload, and the library
 * then finds it loaded. */
static inline int osmesa_installed(void)
{
    static int known, have;
    if (!known) {
        known = 1;
        have = vxl_dynlib_open("libOSMesa.so.8", NULL, 0) != NULL;
    }
    return have;
}

/* The software backend the tests render on: OSMesa where it is installed,
 * else Mesa's surfaceless EGL, which is what `auto` and every user get on a
 * release without OSMesa (Mesa 25.1 removed it). The fallback is announced on
 * stdout, which ./build.sh test shows, so a log says which backend ran. On
 * Windows (under Wine: its OpenGL is Mesa's llvmpipe through GLX) it is WGL,
 * the only backend there. */
static inline uint32_t software_backend(void)
{
    static int announced;
    if (!strcmp(vxl_os_name(), "windows")) return VXL_BACKEND_WGL;
    if (osmesa_installed()) return VXL_BACKEND_OSMESA;
    if (!announced) {
        announced = 1;
        printf("software backend: egl (libOSMesa.so.8 is not installed: the tests render on Mesa's EGL)\n");
        fflush(stdout);
    }
    return VXL_BACKEND_EGL;
}

static inline vxl_renderer *make_renderer(uint32_t backend)
{
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.backend = backend;
    vxl_renderer *r = NULL;
    return vxl_renderer_create(&o, &r) == VXL_OK ? r : NULL;
}

/* A renderer on the software backend with the given storage, page brick
 * and memory budget (0: defaults); compressed_domain as voxlight_dev.h says. */
static inline vxl_renderer *make_stored_renderer(uint32_t storage, uint32_t page_brick, uint64_t budget,
                                                 uint32_t compressed_domain)
{
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.backend = software_backend();
    o.storage = storage;
    o.page_brick = page_brick;
    o.memory_budget_bytes = budget;
    o.compressed_domain = compressed_domain;
    vxl_renderer *r = NULL;
    return vxl_renderer_create(&o, &r) == VXL_OK ? r : NULL;
}

/* The stats of r's last frame (zeros but struct_size when it has none). */
static inline vxl_render_stats renderer_stats(vxl_renderer *r)
{
    vxl_render_stats s;
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    vxl_renderer_get_stats(r, &s);
    return s;
}

/* 1 if every pixel is finite, colour in [0,1], alpha >= each colour channel
 * (premultiplied), depth finite or +inf and positive. */
static inline int image_is_sane(const float *rgba, const float *depth, size_t npix)
{
    for (size_t i = 0; i < npix; i++) {
        const float *p = rgba + 4 * i;
        for (int c = 0; c < 4; c++)
            if (!isfinite(p[c]) || p[c] < 0 || p[c] > 1) return 0;
        for (int c = 0; c < 3; c++)
            if (p[c] > p[3] + 1e-6f) return 0;
        if (depth && (isnan(depth[i]) || depth[i] < 0 || (isinf(depth[i]) && depth[i] < 0))) return 0;
    }
    return 1;
}

static inline double image_rmse(const float *a, const float *b, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; i++) s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return sqrt(s / (double)n);
}

/* PSNR in dB of two images with values in [0,1]; 200 for identical ones. */
static inline double image_psnr(const float *a, const float *b, size_t n)
{
    double r = image_rmse(a, b, n);
    return r > 0 ? 20 * log10(1.0 / r) : 200;
}

static inline double alpha_sum(const float *rgba, size_t npix)
{
    double s = 0;
    for (size_t i = 0; i < npix; i++) s += rgba[4 * i + 3];
    return s;
}

#endif
