/* modes_study.c - run time against error of the render modes
 * (docs/modes.md): for MIP, MinIP, average and ISO, at each ray step, the
 * median frame time and the error against a double-precision CPU reference
 * of the same trilinear field along the same rays.
 *   MIP / MinIP / average: the projected value (read back through a grey
 *     ramp, colour = windowed value) against the max / min / mean of the
 *     trilinear field along the ray, sampled in double every 1/64 voxel;
 *     RMSE and worst error in window units over the pixels whose ray meets
 *     the volume.
 *   ISO: the depth against the analytic sphere |x - c| = R of a distance
 *     field (mean and worst error in voxels, over rays that are not grazing):
 *     the trilinear interpolant's own error; and (iso-vs-trilinear) against
 *     the first crossing of that trilinear field found in double: the error
 *     of the refinement alone.
 * The volume: a smooth field of Gaussian blobs (projections) and a distance
 * field (ISO), seen by the default camera at azimuth 30, elevation 20, with
 * jitter off, so sample positions along a ray are t0 + i * step.
 * Writes a CSV and prints a table; frame times are medians of warm frames
 * and mean nothing on a loaded machine. Command (docs/benchmark.md):
 *   make -j1 build/voxlight-modesbench && ./build/voxlight-modesbench --out bench/modes.csv --md bench/out/modes.md */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

#define TF_N 4096
#define REF_PER_VOXEL 64
#define N_STEPS 5
static const float STEPS[N_STEPS] = {2.0f, 1.0f, 0.5f, 0.25f, 0.125f};

typedef struct field {
    uint32_t n;
    float *v;
    double lo, hi; /* data range: the window */
} field;

static double blobs(double x, double y, double z, uint32_t n)
{
    static const double c[4][4] = {{0.3, 0.35, 0.4, 0.12}, {0.65, 0.55, 0.5, 0.18}, {0.45, 0.7, 0.65, 0.08},
                                   {0.55, 0.3, 0.7, 0.1}};
    double s = 0;
    for (int b = 0; b < 4; b++) {
        double dx = x / n - c[b][0], dy = y / n - c[b][1], dz = z / n - c[b][2];
        s += (1.0 - 0.2 * b) * exp(-(dx * dx + dy * dy + dz * dz) / (2 * c[b][3] * c[b][3]));
    }
    return s;
}

static double sphere_distance(double x, double y, double z, uint32_t n)
{
    double c = 0.5 * (n - 1) + 0.13;
    return sqrt((x - c) * (x - c) + (y - c - 0.21) * (y - c - 0.21) + (z - c + 0.08) * (z - c + 0.08));
}

static int make_field(field *f, uint32_t n, double (*fn)(double, double, double, uint32_t), vxl_volume **vol)
{
    f->n = n;
    f->v = malloc(sizeof(float) * n * n * n);
    if (!f->v) return 1;
    f->lo = INFINITY;
    f->hi = -INFINITY;
    for (uint32_t k = 0; k < n; k++)
        for (uint32_t j = 0; j < n; j++)
            for (uint32_t i = 0; i < n; i++) {
                float v = (float)fn(i, j, k, n);
                f->v[i + n * (j + n * k)] = v;
                f->lo = v < f->lo ? v : f->lo;
                f->hi = v > f->hi ? v : f->hi;
            }
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_F32, .dims = {n, n, n}, .data = f->v};
    return vxl_volume_create(&d, NULL, vol);
}

/* Trilinear, clamp to edge, in double: the texture unit's reconstruction. */
static double trilinear(const field *f, const double p[3])
{
    int i0[3];
    double w[3];
    for (int a = 0; a < 3; a++) {
        double q = fmin(fmax(p[a], 0.0), f->n - 1.0);
        i0[a] = (int)floor(q);
        if (i0[a] > (int)f->n - 2) i0[a] = (int)f->n - 2;
        w[a] = q - i0[a];
    }
    double s = 0;
    for (int c = 0; c < 8; c++) {
        int x = i0[0] + (c & 1), y = i0[1] + (c >> 1 & 1), z = i0[2] + (c >> 2 & 1);
        double wt = ((c & 1) ? w[0] : 1 - w[0]) * ((c >> 1 & 1) ? w[1] : 1 - w[1]) * ((c >> 2 & 1) ? w[2] : 1 - w[2]);
        s += wt * f->v[x + f->n * (y + f->n * z)];
    }
    return s;
}

/* Gauss-Jordan inverse of a column-major 4x4; 0 if singular. */
static int invert4(const double m[16], double out[16])
{
    double a[4][8];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            a[r][c] = m[4 * c + r];
            a[r][4 + c] = r == c;
        }
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c])) piv = r;
        if (fabs(a[piv][c]) < 1e-300) return 0;
        for (int k = 0; k < 8; k++) {
            double t = a[c][k];
            a[c][k] = a[piv][k];
            a[piv][k] = t;
        }
        double d = a[c][c];
        for (int k = 0; k < 8; k++) a[c][k] /= d;
        for (int r = 0; r < 4; r++)
            if (r != c) {
                double s = a[r][c];
                for (int k = 0; k < 8; k++) a[r][k] -= s * a[c][k];
            }
    }
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) out[4 * c + r] = a[r][4 + c];
    return 1;
}

static void mul4(const double a[16], const double b[16], double out[16])
{
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++) {
            double s = 0;
            for (int k = 0; k < 4; k++) s += a[4 * k + r] * b[4 * c + k];
            out[4 * c + r] = s;
        }
}

/* The ray of pixel (px, py) in voxel space (the model is the identity):
 * origin o (at the near plane), unit dir, and the box's [t0, t1]; 0 if it misses. */
typedef struct ray {
    double o[3], dir[3], t0, t1;
    double view_row2[4]; /* view-space z of a voxel-space point */
} ray;

static int pixel_ray(const double inv_pv[16], const double view[16], uint32_t n, uint32_t w, uint32_t h, uint32_t px,
                     uint32_t py, ray *r)
{
    double ndc[2] = {(px + 0.5) / w * 2 - 1, (py + 0.5) / h * 2 - 1}, pt[2][3];
    for (int e = 0; e < 2; e++) {
        double c[4] = {ndc[0], ndc[1], e ? 1.0 : -1.0, 1.0}, o[4] = {0, 0, 0, 0};
        for (int row = 0; row < 4; row++)
            for (int k = 0; k < 4; k++) o[row] += inv_pv[4 * k + row] * c[k];
        for (int a = 0; a < 3; a++) pt[e][a] = o[a] / o[3];
    }
    double len = 0;
    for (int a = 0; a < 3; a++) {
        r->o[a] = pt[0][a];
        r->dir[a] = pt[1][a] - pt[0][a];
        len += r->dir[a] * r->dir[a];
    }
    len = sqrt(len);
    r->t0 = 0;
    r->t1 = INFINITY;
    for (int a = 0; a < 3; a++) {
        r->dir[a] /= len;
        if (fabs(r->dir[a]) < 1e-12) {
            if (r->o[a] < -0.5 || r->o[a] > n - 0.5) return 0;
            continue;
        }
        double ta = (-0.5 - r->o[a]) / r->dir[a], tb = (n - 0.5 - r->o[a]) / r->dir[a];
        r->t0 = fmax(r->t0, fmin(ta, tb));
        r->t1 = fmin(r->t1, fmax(ta, tb));
    }
    for (int k = 0; k < 4; k++) r->view_row2[k] = view[4 * k + 2];
    return r->t0 < r->t1;
}

/* The reference projection of a ray: max, min and mean (the integral's) of the field. */
static void reference_projection(const field *f, const ray *r, double out[3])
{
    double len = r->t1 - r->t0;
    int m = (int)ceil(len * REF_PER_VOXEL);
    double mx = -INFINITY, mn = INFINITY, sum = 0;
    for (int i = 0; i <= m; i++) {
        double t = r->t0 + len * i / m, p[3];
        for (int a = 0; a < 3; a++) p[a] = r->o[a] + t * r->dir[a];
        double v = trilinear(f, p);
        mx = fmax(mx, v);
        mn = fmin(mn, v);
        sum += (i == 0 || i == m) ? 0.5 * v : v; /* trapezoid */
    }
    out[0] = mx;
    out[1] = mn;
    out[2] = sum / m;
}

static void grey_ramp(float *tf)
{
    for (int i = 0; i < TF_N; i++) {
        float x = (float)i / (TF_N - 1);
        tf[4 * i] = tf[4 * i + 1] = tf[4 * i + 2] = x;
        tf[4 * i + 3] = 1;
    }
}

/* The first crossing of iso by the trilinear field along the ray, in double:
 * every 1/64 voxel, then bisection to 1e-9 voxels; -1 if none. */
static double reference_crossing(const field *f, const ray *r, double iso)
{
    double len = r->t1 - r->t0, prev_t = r->t0, p[3];
    int m = (int)ceil(len * REF_PER_VOXEL), prev_above = -1;
    for (int i = 0; i <= m; i++) {
        double t = r->t0 + len * i / m;
        for (int a = 0; a < 3; a++) p[a] = r->o[a] + t * r->dir[a];
        int above = trilinear(f, p) >= iso;
        if (prev_above >= 0 && above != prev_above) {
            double a0 = prev_t, b0 = t;
            while (b0 - a0 > 1e-9) {
                double mid = 0.5 * (a0 + b0);
                for (int a = 0; a < 3; a++) p[a] = r->o[a] + mid * r->dir[a];
                if ((trilinear(f, p) >= iso) == prev_above) a0 = mid;
                else b0 = mid;
            }
            return 0.5 * (a0 + b0);
        }
        prev_above = above;
        prev_t = t;
    }
    return -1;
}

typedef struct row {
    const char *mode;
    float step;
    double ms, err_mean, err_max;
    uint64_t samples;
} row;

int main(int argc, char **argv)
{
    uint32_t size = 256, n = 96;
    int frames = 5;
    const char *out = "bench/modes.csv", *md = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) size = 64, n = 32, frames = 1;
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
        else if (!strcmp(argv[i], "--md") && i + 1 < argc) md = argv[++i];
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: %s [--quick] [--size N] [--frames N] [--out FILE.csv] [--md FILE.md]\n", argv[0]);
            return 2;
        }
    }
    if (size < 8 || size > 4096 || frames < 1 || frames > 64) {
        fprintf(stderr, "modes: --size 8..4096, --frames 1..64\n");
        return 2;
    }
    vxl_renderer_options o = {.struct_size = sizeof o};
    vxl_renderer *r = NULL;
    field fb = {0}, fs = {0};
    vxl_volume *vb = NULL, *vs = NULL;
    float *tf = malloc(sizeof(float) * TF_N * 4), *img = malloc(sizeof(float) * size * size * 4),
          *depth = malloc(sizeof(float) * size * size);
    row rows[5 * N_STEPS];
    int nrows = 0, rc = 1;
    double *ref = NULL;      /* per pixel: the reference max, min, mean */
    unsigned char *hit = NULL; /* per pixel: its ray meets the volume */
    if (!tf || !img || !depth || vxl_renderer_create(&o, &r) || make_field(&fb, n, blobs, &vb) ||
        make_field(&fs, n, sphere_distance, &vs)) {
        fprintf(stderr, "modes: %s\n", r ? vxl_renderer_error(r) : vxl_last_error());
        goto done;
    }
    grey_ramp(tf);
    vxl_render_params p = base_params(size);
    p.jitter_off = 1;
    p.tf_rgba = tf;
    p.tf_size = TF_N;
    p.has_window = 1;
    float view[16], proj[16];
    double dview[16], dproj[16], pv[16], inv_pv[16];
    if (vxl_renderer_set_volume(r, vb) || vxl_default_camera(r, &p, view, proj)) {
        fprintf(stderr, "modes: %s\n", vxl_renderer_error(r));
        goto done;
    }
    for (int k = 0; k < 16; k++) dview[k] = view[k], dproj[k] = proj[k];
    mul4(dproj, dview, pv);
    if (!invert4(pv, inv_pv)) goto done;
    p.has_camera = 1;
    memcpy(p.view, view, sizeof view);
    memcpy(p.proj, proj, sizeof proj);

    /* the projections, against the blobs' reference */
    p.window_low = (float)fb.lo;
    p.window_high = (float)fb.hi;
    ref = malloc(sizeof(double) * 3 * size * size);
    hit = malloc((size_t)size * size);
    if (!ref || !hit) goto done;
    for (uint32_t py = 0; py < size; py++)
        for (uint32_t px = 0; px < size; px++) {
            ray ry;
            size_t i = (size_t)py * size + px;
            hit[i] = (unsigned char)pixel_ray(inv_pv, dview, n, size, size, px, py, &ry);
            if (hit[i]) reference_projection(&fb, &ry, ref + 3 * i);
        }
    for (uint32_t mode = VXL_MODE_MIP; mode <= VXL_MODE_AVERAGE; mode++)
        for (int s = 0; s < N_STEPS; s++) {
            p.mode = mode;
            p.step = STEPS[s];
            double ms = median_ms(r, &p, img, frames);
            vxl_render_stats st = {.struct_size = sizeof st};
            vxl_renderer_get_stats(r, &st);
            double se = 0, mx = 0;
            size_t cnt = 0;
            for (size_t i = 0; i < (size_t)size * size; i++) {
                if (!hit[i]) continue;
                double want = (ref[3 * i + mode - VXL_MODE_MIP] - fb.lo) / (fb.hi - fb.lo);
                double e = fabs(img[4 * i] - want);
                se += e * e;
                mx = fmax(mx, e);
                cnt++;
            }
            rows[nrows++] = (row){vxl_mode_name(mode), STEPS[s], ms, cnt ? sqrt(se / cnt) : 0, mx, st.samples};
        }

    /* ISO: depth against the analytic sphere of the distance field */
    if (vxl_renderer_set_volume(r, vs)) {
        fprintf(stderr, "modes: %s\n", vxl_renderer_error(r));
        goto done;
    }
    const double radius = 0.3 * n, c[3] = {0.5 * (n - 1) + 0.13, 0.5 * (n - 1) + 0.13 + 0.21, 0.5 * (n - 1) + 0.13 - 0.08};
    p.mode = VXL_MODE_ISO;
    p.iso_value = (float)radius;
    p.window_low = (float)fs.lo;
    p.window_high = (float)fs.hi;
    for (int s = 0; s < N_STEPS; s++) {
        p.step = STEPS[s];
        double ms = median_ms(r, &p, img, frames);
        vxl_render(r, &p, img, depth);
        vxl_render_stats st = {.struct_size = sizeof st};
        vxl_renderer_get_stats(r, &st);
        double sum = 0, mx = 0, tsum = 0, tmx = 0;
        size_t cnt = 0;
        for (uint32_t py = 0; py < size; py++)
            for (uint32_t px = 0; px < size; px++) {
                ray ry;
                if (!pixel_ray(inv_pv, dview, n, size, size, px, py, &ry)) continue;
                /* |o + t dir - c| = R: the nearer root, skipping rays within 2% of grazing */
                double oc[3], b = 0, cc = 0;
                for (int a = 0; a < 3; a++) {
                    oc[a] = ry.o[a] - c[a];
                    b += oc[a] * ry.dir[a];
                    cc += oc[a] * oc[a];
                }
                double disc = b * b - (cc - radius * radius);
                if (disc < 0.04 * radius * radius) continue;
                double t = -b - sqrt(disc), x[4] = {ry.o[0] + t * ry.dir[0], ry.o[1] + t * ry.dir[1],
                                                    ry.o[2] + t * ry.dir[2], 1};
                double want = 0;
                for (int k = 0; k < 4; k++) want -= ry.view_row2[k] * x[k];
                double got = depth[(size_t)py * size + px];
                /* view units are voxels here (identity model, rigid view) */
                double e = isinf(got) ? INFINITY : fabs(got - want);
                /* and against the trilinear field's own crossing: the refinement's error alone */
                double tr = reference_crossing(&fs, &ry, radius), et = INFINITY;
                if (tr >= 0) {
                    double xt[4] = {ry.o[0] + tr * ry.dir[0], ry.o[1] + tr * ry.dir[1], ry.o[2] + tr * ry.dir[2], 1};
                    double wt = 0;
                    for (int k = 0; k < 4; k++) wt -= ry.view_row2[k] * xt[k];
                    et = fabs(got - wt);
                }
                sum += e;
                mx = fmax(mx, e);
                tsum += et;
                tmx = fmax(tmx, et);
                cnt++;
            }
        rows[nrows++] = (row){"iso", STEPS[s], ms, cnt ? sum / cnt : 0, mx, st.samples};
        rows[nrows++] = (row){"iso-vs-trilinear", STEPS[s], ms, cnt ? tsum / cnt : 0, tmx, st.samples};
    }

    FILE *csv = fopen(out, "w");
    if (!csv) {
        fprintf(stderr, "modes: cannot write %s\n", out);
        goto done;
    }
    fprintf(csv, "mode,step,ms_median,error_mean,error_max,error_unit,samples,size,volume\n");
    for (int i = 0; i < nrows; i++)
        fprintf(csv, "%s,%g,%.3f,%.6g,%.6g,%s,%llu,%u,%u\n", rows[i].mode, rows[i].step, rows[i].ms, rows[i].err_mean,
                rows[i].err_max, strncmp(rows[i].mode, "iso", 3) ? "window (rmse)" : "voxels (mean)",
                (unsigned long long)rows[i].samples, size, n);
    fclose(csv);
    FILE *mdf = md ? fopen(md, "w") : NULL;
    FILE *outs[2] = {stdout, mdf};
    for (int k = 0; k < 2; k++) {
        if (!outs[k]) continue;
        fprintf(outs[k], "| mode | step (voxels) | frame (ms, median) | samples | error (mean) | error (worst) |\n");
        fprintf(outs[k], "|---|---|---|---|---|---|\n");
        for (int i = 0; i < nrows; i++)
            fprintf(outs[k], "| %s | %g | %.1f | %llu | %.2e %s | %.2e |\n", rows[i].mode, rows[i].step, rows[i].ms,
                    (unsigned long long)rows[i].samples, rows[i].err_mean,
                    strncmp(rows[i].mode, "iso", 3) ? "(RMSE, window units)" : "(voxels of depth)", rows[i].err_max);
    }
    if (mdf) fclose(mdf);
    fprintf(stderr, "modes: %ux%u images, volumes of %u^3, wrote %s%s%s\n", size, size, n, out, md ? " and " : "",
            md ? md : "");
    rc = 0;
done:
    free(ref);
    free(hit);
    vxl_volume_destroy(vb);
    vxl_volume_destroy(vs);
    vxl_renderer_destroy(r);
    free(fb.v);
    free(fs.v);
    free(tf);
    free(img);
    free(depth);
    return rc;
}
