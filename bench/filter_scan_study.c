/* filter_scan_study.c - the gradient filters on a real scan:
 * renders one close view per filter and light, writes the images, and prints
 * two smoothness measures of the normals:
 *  - hf: RMS of the shaded luminance minus its 3x3 mean, over pixels whose
 *    whole 3x3 neighbourhood is opaque (the image's high-frequency energy);
 *  - nbr: angle between the gradients (vxl_probe_gradients) at tissue points
 *    and at points 0.25 voxel away in a random direction: median and p90,
 *    degrees (the fine-scale roughness of the normal field).
 * Usage: filter-scan-study VOLUME OUTDIR [persp|ortho] [filter,filter,...]
 * Environment: FLOAT=1 uploads the scan as float32; AZ=deg the camera
 * azimuth; ZOOM=k CX=x CY=y another crop; LATTICE=1 prints the roughness by
 * lattice offset instead of rendering; TIME=1 prints frame-time ratios.
 * docs/filters_on_scans.md has the commands behind its tables.
 * Build: make (build/filter-scan-study); by hand: cc -O2 -std=c11 -D_GNU_SOURCE -Icsrc/include -Icsrc/volume -Icsrc/core \
 *          bench/filter_scan_study.c -Lbuild -lvoxlight -lm -Wl,-rpath,$PWD/build -o build/filter-scan-study */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "volume.h"
#include "voxlight_dev.h"

#define W 512
#define H 512

/* The same scan as float32 (env FLOAT=1): the volume texture then filters
 * in float instead of llvmpipe's 8-bit-rounded unorm8 path. */
static vxl_volume *as_float(vxl_volume *v)
{
    size_t n = (size_t)v->dims[0] * v->dims[1] * v->dims[2];
    float *d = malloc(n * sizeof *d);
    for (size_t i = 0; i < n; i++) {
        double t = v->texture_bits == 8    ? ((const uint8_t *)v->texels)[i] / 255.0
                   : v->texture_bits == 16 ? ((const uint16_t *)v->texels)[i] / 65535.0
                                           : ((const float *)v->texels)[i];
        d[i] = (float)(v->tex_lo + t * (v->tex_hi - v->tex_lo));
    }
    vxl_volume_desc desc = {.struct_size = sizeof desc, .dtype = VXL_DTYPE_F32, .has_affine = 1, .data = d};
    memcpy(desc.dims, v->dims, sizeof desc.dims);
    memcpy(desc.affine, v->affine, sizeof desc.affine);
    memcpy(desc.spacing, v->spacing, sizeof desc.spacing);
    vxl_volume *o = NULL;
    vxl_volume_create(&desc, NULL, &o);
    free(d);
    vxl_volume_destroy(v);
    return o;
}

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double hf_energy(const float *img)
{
    double s = 0;
    long n = 0;
    for (int y = 1; y < H - 1; y++)
        for (int x = 1; x < W - 1; x++) {
            double m = 0, c = 0;
            int opaque = 1;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    const float *q = img + 4 * ((y + dy) * W + x + dx);
                    opaque &= q[3] >= 0.99f;
                    double l = 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
                    m += l / 9;
                    if (!dx && !dy) c = l;
                }
            if (!opaque) continue;
            s += (c - m) * (c - m);
            n++;
        }
    return n ? sqrt(s / n) : NAN;
}

static uint64_t rng = 99;
static double uni(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* Tissue points: where the central-difference probe says the gradient is
 * large enough to shade (a boundary), chosen once for every filter. */
static void neighbour_angles(vxl_renderer *r, uint32_t filter, const float *pts, const float *nb, int n, double *med,
                             double *p90)
{
    float *g0 = malloc(sizeof(float) * 3 * n), *g1 = malloc(sizeof(float) * 3 * n);
    double *a = malloc(sizeof(double) * n);
    vxl_render_params p = {.struct_size = sizeof p, .filter = filter};
    *med = *p90 = NAN;
    if (!vxl_probe_gradients(r, &p, pts, (uint32_t)n, g0) && !vxl_probe_gradients(r, &p, nb, (uint32_t)n, g1)) {
        for (int i = 0; i < n; i++) {
            const float *u = g0 + 3 * i, *v = g1 + 3 * i;
            double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]), lv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            double c = lu > 0 && lv > 0 ? (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (lu * lv) : -1;
            a[i] = acos(c > 1 ? 1 : c < -1 ? -1 : c) * 180 / M_PI;
        }
        qsort(a, (size_t)n, sizeof *a, cmpd);
        *med = a[n / 2];
        *p90 = a[n * 9 / 10];
    }
    free(g0), free(g1), free(a);
}

/* Column-major ortho projection (glOrtho). */
static void ortho(float m[16], float l, float r, float b, float t, float n, float f)
{
    memset(m, 0, 16 * sizeof(float));
    m[0] = 2 / (r - l), m[5] = 2 / (t - b), m[10] = -2 / (f - n);
    m[12] = -(r + l) / (r - l), m[13] = -(t + b) / (t - b), m[14] = -(f + n) / (f - n), m[15] = 1;
}

/* clip' = crop * clip: ndc' = k (ndc - c) */
static void crop(float proj[16], float k, float cx, float cy)
{
    for (int col = 0; col < 4; col++) {
        float *c = proj + 4 * col;
        c[0] = k * c[0] - k * cx * c[3];
        c[1] = k * c[1] - k * cy * c[3];
    }
}

int main(int argc, char **argv)
{
    if (argc < 3) return fprintf(stderr, "usage: %s VOLUME OUTDIR [persp|ortho] [filters]\n", argv[0]), 2;
    int is_ortho = argc > 3 && !strcmp(argv[3], "ortho");
    const char *flist = argc > 4 ? argv[4] : "central,sobel26,precomputed,cubic";
    vxl_volume *v = NULL;
    vxl_renderer *r = NULL;
    vxl_renderer_options o = {.struct_size = sizeof o};
    if (vxl_volume_load(argv[1], NULL, &v)) return fprintf(stderr, "%s\n", vxl_last_error()), 1;
    if (getenv("FLOAT") && !(v = as_float(v))) return fprintf(stderr, "%s\n", vxl_last_error()), 1;
    if (vxl_renderer_create(&o, &r) || vxl_renderer_set_volume(r, v))
        return fprintf(stderr, "%s\n", vxl_last_error()), 1;
    vxl_volume_info info = {.struct_size = sizeof info};
    vxl_volume_get_info(v, &info);

    /* probe points: tissue (value 0.15..0.45 of the 8-bit scale = 38..115 of
     * 255) where central differences see a boundary, a neighbour 0.25 voxel away */
    enum { N = 20000 };
    float *pts = malloc(sizeof(float) * 3 * N * 4), *nb = malloc(sizeof(float) * 3 * N), *g = malloc(sizeof(float) * 3 * N * 4);
    for (int i = 0; i < 4 * N; i++)
        for (int c = 0; c < 3; c++) pts[3 * i + c] = (float)(10 + uni() * (info.dims[c] - 21));
    vxl_render_params pc = {.struct_size = sizeof pc, .filter = VXL_FILTER_CENTRAL};
    if (vxl_probe_gradients(r, &pc, pts, 4 * N, g)) return fprintf(stderr, "%s\n", vxl_renderer_error(r)), 1;
    int n = 0;
    for (int i = 0; i < 4 * N && n < N; i++) {
        double m = sqrt(g[3 * i] * g[3 * i] + g[3 * i + 1] * g[3 * i + 1] + g[3 * i + 2] * g[3 * i + 2]);
        if (m < 0.01) continue; /* flat: no surface to shade */
        memmove(pts + 3 * n, pts + 3 * i, 3 * sizeof(float));
        double d[3], l;
        do {
            for (int c = 0; c < 3; c++) d[c] = uni() * 2 - 1;
            l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        } while (l > 1 || l < 0.1);
        for (int c = 0; c < 3; c++) nb[3 * n + c] = pts[3 * n + c] + (float)(0.25 * d[c] / l);
        n++;
    }

    /* env ZOOM=k CX=x CY=y: another crop (ndc centre x, y of the uncropped view) */
    float zoom = getenv("ZOOM") ? (float)atof(getenv("ZOOM")) : 0;
    float cx = getenv("CX") ? (float)atof(getenv("CX")) : 0, cy = getenv("CY") ? (float)atof(getenv("CY")) : 0;
    vxl_render_params p = {.struct_size = sizeof p, .width = W, .height = H, .azimuth_deg = getenv("AZ") ? (float)atof(getenv("AZ")) : 0, .elevation_deg = 0};
    p.has_camera = 1;
    vxl_default_camera(r, &p, p.view, p.proj);
    if (is_ortho) {
        /* the default camera's view, an orthographic box around the volume:
         * the cerebellum from the front, as in the trial */
        float e = 0.5f * (float)(info.dims[0] * info.spacing[0] + info.dims[1] * info.spacing[1] + info.dims[2] * info.spacing[2]);
        float dist = -p.view[14];
        ortho(p.proj, -e / 2, e / 2, -e / 2, e / 2, dist - 2 * e, dist + 2 * e);
        crop(p.proj, zoom > 0 ? zoom : 2.5f, zoom > 0 ? cx : 0.0f, zoom > 0 ? cy : -0.55f);
    } else {
        crop(p.proj, zoom > 0 ? zoom : 3.0f, zoom > 0 ? cx : 0.1f, zoom > 0 ? cy : 0.35f); /* frontal cortex, close */
    }
    if (getenv("TIME")) {
        /* Frame time per filter at 384^2, default camera: one warm-up frame
         * (programs, prefilter), then the median of 3, interleaved over the
         * filters so a shared machine's load falls on all of them alike;
         * printed as ratios to the first filter. */
        vxl_render_params t = {.struct_size = sizeof t, .width = 384, .height = 384, .azimuth_deg = 30, .elevation_deg = 20};
        float *img = malloc(sizeof(float) * 4 * 384 * 384);
        uint32_t fs[16];
        int nf = 0;
        double ms[16][3];
        char fl2[256];
        snprintf(fl2, sizeof fl2, "%s", flist);
        for (char *name = strtok(fl2, ","); name && nf < 16; name = strtok(NULL, ","))
            if (vxl_filter_from_name(name, &fs[nf++])) return fprintf(stderr, "%s\n", vxl_last_error()), 1;
        for (int i = 0; i < nf; i++) {
            t.filter = fs[i];
            if (vxl_render(r, &t, img, NULL)) return fprintf(stderr, "%s\n", vxl_renderer_error(r)), 1;
        }
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < nf; i++) {
                struct timespec a, b;
                t.filter = fs[i];
                clock_gettime(CLOCK_MONOTONIC, &a);
                vxl_render(r, &t, img, NULL);
                clock_gettime(CLOCK_MONOTONIC, &b);
                ms[i][k] = (b.tv_sec - a.tv_sec) * 1e3 + (b.tv_nsec - a.tv_nsec) / 1e6;
            }
        double base = 0;
        for (int i = 0; i < nf; i++) {
            qsort(ms[i], 3, sizeof(double), cmpd);
            if (i == 0) base = ms[0][1];
            printf("%-12s median %.0f ms, %.2f x %s\n", vxl_filter_name(fs[i]), ms[i][1], ms[i][1] / base,
                   vxl_filter_name(fs[0]));
        }
        return 0;
    }
    if (getenv("LATTICE")) {
        /* Lattice modulation: the same roughness measure with every probe
         * point moved to offset t from the voxel lattice on all three axes
         * (t = 0: on a voxel centre, 0.5: a cell centre). A filter whose
         * noise differs with t draws the lattice into the image: on a flat
         * surface cut obliquely by the voxel planes, stripes one voxel apart. */
        float *lp = malloc(sizeof(float) * 3 * n), *ln = malloc(sizeof(float) * 3 * n);
        printf("%-12s %9s %9s %9s  (median neighbour angle, deg, at lattice offset t)\n", "filter", "t=0", "t=0.25",
               "t=0.5");
        char fl2[256];
        snprintf(fl2, sizeof fl2, "%s", flist);
        for (char *name = strtok(fl2, ","); name; name = strtok(NULL, ",")) {
            uint32_t f;
            if (vxl_filter_from_name(name, &f)) return fprintf(stderr, "%s\n", vxl_last_error()), 1;
            printf("%-12s", name);
            for (int k = 0; k < 3; k++) {
                for (int i = 0; i < 3 * n; i++) {
                    lp[i] = floorf(pts[i]) + 0.25f * k;
                    ln[i] = lp[i] + (nb[i] - pts[i]);
                }
                double med, p90;
                neighbour_angles(r, f, lp, ln, n, &med, &p90);
                printf(" %9.2f", med);
            }
            printf("\n");
        }
        return 0;
    }
    printf("%-12s %-7s %8s %8s %8s\n", "filter", "light", "hf", "nbr_med", "nbr_p90");
    char fl[256];
    snprintf(fl, sizeof fl, "%s", flist);
    for (char *name = strtok(fl, ","); name; name = strtok(NULL, ",")) {
        if (vxl_filter_from_name(name, &p.filter)) return fprintf(stderr, "%s\n", vxl_last_error()), 1;
        double med, p90;
        neighbour_angles(r, p.filter, pts, nb, n, &med, &p90);
        for (int L = 0; L < 2; L++) {
            /* a point light up and left of the camera, or a low sun from the side (world space, mm) */
            p.light_count = 1;
            memset(p.lights, 0, sizeof p.lights);
            if (L == 0) {
                /* the eye (world) = -R^T t, moved up and to the left in view space */
                float pos[4] = {0, 0, 0, 1}, off[3] = {-0.3f * -p.view[14], 0.4f * -p.view[14], 0};
                for (int a = 0; a < 3; a++)
                    for (int b = 0; b < 3; b++) pos[a] += p.view[4 * a + b] * (off[b] - p.view[12 + b]);
                memcpy(p.lights[0].position, pos, sizeof pos);
            } else {
                float dir[4] = {-0.8f, getenv("AZ") && atof(getenv("AZ")) > 90 ? -0.3f : 0.3f, 0.5f, 0};
                memcpy(p.lights[0].position, dir, sizeof dir);
            }
            float *img = malloc(sizeof(float) * 4 * W * H);
            if (vxl_render(r, &p, img, NULL)) return fprintf(stderr, "%s\n", vxl_renderer_error(r)), 1;
            char path[512];
            snprintf(path, sizeof path, "%s/%s_%s_%s.png", argv[2], is_ortho ? "ortho" : "persp", name, L ? "sun" : "point");
            vxl_write_image(path, img, NULL, W, H);
            printf("%-12s %-7s %8.5f %8.2f %8.2f\n", name, L ? "sun" : "point", hf_energy(img), med, p90);
            fflush(stdout);
            free(img);
        }
    }
    printf("(%d probe points)\n", n);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
    return 0;
}
