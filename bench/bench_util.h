/* bench_util.h - timing and image error shared by the study programs. */
#ifndef VXL_BENCH_UTIL_H
#define VXL_BENCH_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "voxlight.h"

/* An OSMesa renderer holding the volume at path (the CPU copy freed), or
 * NULL with the library's message printed after `tool`. */
static inline vxl_renderer *renderer_with_volume(const char *path, const char *tool)
{
    vxl_volume *v = NULL;
    vxl_renderer *r = NULL;
    vxl_renderer_options o = {.struct_size = sizeof o, .backend = VXL_BACKEND_OSMESA};
    if (vxl_volume_load(path, NULL, &v) || vxl_renderer_create(&o, &r)) {
        fprintf(stderr, "%s: %s\n", tool, vxl_last_error());
        vxl_volume_destroy(v);
        return NULL;
    }
    int rc = vxl_renderer_set_volume(r, v);
    vxl_volume_destroy(v);
    if (rc) {
        fprintf(stderr, "%s: %s\n", tool, vxl_renderer_error(r));
        vxl_renderer_destroy(r);
        return NULL;
    }
    return r;
}

static inline double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static inline int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Median of `frames` (1..64, what voxlight-bench's --frames accepts) renders
 * after one warm-up that builds grids and programs; -1 if a render failed
 * (the message is in vxl_renderer_error). */
static inline double median_ms(vxl_renderer *r, const vxl_render_params *p, float *img, int frames)
{
    double t[64];
    if (vxl_render(r, p, img, NULL)) return -1;
    for (int i = 0; i < frames; i++) {
        double s = now_ms();
        if (vxl_render(r, p, img, NULL)) return -1;
        t[i] = now_ms() - s;
    }
    qsort(t, (size_t)frames, sizeof *t, cmp_d);
    return t[frames / 2];
}

/* The studies' common frame: size^2, the default camera at azimuth 30,
 * elevation 20; everything else the library default. */
static inline vxl_render_params base_params(uint32_t size)
{
    vxl_render_params p;
    memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.width = p.height = size;
    p.azimuth_deg = 30;
    p.elevation_deg = 20;
    return p;
}

static inline double psnr(const float *a, const float *b, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; i++) s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    s = sqrt(s / n);
    return s > 0 ? 20 * log10(1 / s) : 200;
}

#endif
