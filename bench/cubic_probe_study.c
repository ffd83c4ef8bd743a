/* cubic_probe_study.c - is the `cubic` filter's GPU evaluation the spline it
 * claims? Probes the cubic gradient (vxl_probe_gradients, the ray caster's
 * GLSL) at points of a real scan and compares it with the same interpolating
 * cubic B-spline derivative evaluated on the CPU in double precision from the
 * stored texels, and with that CPU evaluation when the two-fetch trick's
 * linear-fetch weights are rounded to 1/256 (8-bit fixed point).
 * Build: cc -O2 -std=c11 -D_GNU_SOURCE -Icsrc/include -Icsrc/volume -Icsrc/core bench/cubic_probe_study.c \
 *          -Lbuild -lvoxlight -lm -Wl,-rpath,$PWD/build -o build/cubic-probe-study
 * Run:   build/cubic-probe-study /usr/share/mricron/templates/ch2better.nii.gz */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "volume.h"
#include "voxlight_dev.h"

static uint32_t D[3];
static double *C; /* interpolating coefficients, double */

static double *at(double *a, int x, int y, int z) { return a + x + (size_t)D[0] * (y + (size_t)D[1] * z); }

/* Unser's recursive prefilter along one line (mirror boundary), stride s. */
static void prefilter_line(double *c, int n, size_t s)
{
    const double z = sqrt(3.0) - 2.0;
    double zk = 1, sum = 0;
    for (int k = 0; k < n && k < 40; k++, zk *= z) sum += zk * 6 * c[k * s];
    c[0] = sum;
    for (int k = 1; k < n; k++) c[k * s] = 6 * c[k * s] + z * c[(k - 1) * s];
    c[(n - 1) * s] = z / (z * z - 1) * (c[(n - 1) * s] + z * c[(n - 2) * s]);
    for (int k = n - 2; k >= 0; k--) c[k * s] = z * (c[(k + 1) * s] - c[k * s]);
}

static double coef(int x, int y, int z)
{
    x = x < 0 ? 0 : x >= (int)D[0] ? (int)D[0] - 1 : x; /* clamp to edge, as the texture */
    y = y < 0 ? 0 : y >= (int)D[1] ? (int)D[1] - 1 : y;
    z = z < 0 ? 0 : z >= (int)D[2] ? (int)D[2] - 1 : z;
    return *at(C, x, y, z);
}

static void bw(double a, double w[4], double dw[4])
{
    double b = 1 - a, a2 = a * a, a3 = a2 * a;
    w[0] = b * b * b / 6, w[1] = (3 * a3 - 6 * a2 + 4) / 6, w[2] = (-3 * a3 + 3 * a2 + 3 * a + 1) / 6, w[3] = a3 / 6;
    dw[0] = -0.5 * b * b, dw[1] = 0.5 * (3 * a2 - 4 * a), dw[2] = 0.5 * (-3 * a2 + 2 * a + 1), dw[3] = 0.5 * a2;
}

/* Exact: 64 coefficients. */
static void grad_exact(const float *p, double g[3])
{
    int b[3];
    double w[3][4], dw[3][4];
    for (int c = 0; c < 3; c++) b[c] = (int)floor(p[c]), bw(p[c] - b[c], w[c], dw[c]);
    g[0] = g[1] = g[2] = 0;
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                double c = coef(b[0] - 1 + i, b[1] - 1 + j, b[2] - 1 + k);
                g[0] += dw[0][i] * w[1][j] * w[2][k] * c;
                g[1] += w[0][i] * dw[1][j] * w[2][k] * c;
                g[2] += w[0][i] * w[1][j] * dw[2][k] * c;
            }
}

/* One trilinear fetch at voxel position q with the fractional weights
 * rounded to 1/256 (fixed point), as a texture unit with 8-bit weights. */
static double fetch_q(const double q[3])
{
    int b[3];
    double f[3];
    for (int c = 0; c < 3; c++) {
        b[c] = (int)floor(q[c]);
        f[c] = floor((q[c] - b[c]) * 256.0 + 0.5) / 256.0;
    }
    double s = 0;
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++)
                s += (i ? f[0] : 1 - f[0]) * (j ? f[1] : 1 - f[1]) * (k ? f[2] : 1 - f[2]) *
                     coef(b[0] + i, b[1] + j, b[2] + k);
    return s;
}

/* The shader's two-fetch evaluation with quantised fetches. */
static void grad_twofetch_q(const float *p, double g[3])
{
    double h[3][2], gg[3][2], dh[3][2], dg[3][2], base[3];
    for (int c = 0; c < 3; c++) {
        double w[4], dw[4];
        base[c] = floor(p[c]);
        bw(p[c] - base[c], w, dw);
        gg[c][0] = w[0] + w[1], gg[c][1] = w[2] + w[3];
        h[c][0] = -1 + w[1] / gg[c][0], h[c][1] = 1 + w[3] / gg[c][1];
        dg[c][0] = dw[0] + dw[1], dg[c][1] = dw[2] + dw[3];
        dh[c][0] = -1 + dw[1] / dg[c][0], dh[c][1] = 1 + dw[3] / dg[c][1];
    }
    for (int a = 0; a < 3; a++) {
        double s = 0;
        for (int i = 0; i < 8; i++) {
            int k[3] = {i & 1, (i >> 1) & 1, (i >> 2) & 1};
            double q[3], w = 1;
            for (int c = 0; c < 3; c++) {
                q[c] = base[c] + (c == a ? dh[c][k[c]] : h[c][k[c]]);
                w *= c == a ? dg[c][k[c]] : gg[c][k[c]];
            }
            s += w * fetch_q(q);
        }
        g[a] = s;
    }
}

static double ang(const double *a, const double *b)
{
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
    return acos(c > 1 ? 1 : c < -1 ? -1 : c) * 180 / M_PI;
}

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
    if (argc < 2) return fprintf(stderr, "usage: %s VOLUME\n", argv[0]), 2;
    vxl_volume *v = NULL;
    vxl_renderer *r = NULL;
    if (vxl_volume_load(argv[1], NULL, &v)) return fprintf(stderr, "%s\n", vxl_last_error()), 1;
    memcpy(D, v->dims, sizeof D);
    size_t n = (size_t)D[0] * D[1] * D[2];
    C = malloc(n * sizeof *C);
    for (size_t i = 0; i < n; i++) /* the stored value, as the GL texture reads it */
        C[i] = v->texture_bits == 8    ? ((const uint8_t *)v->texels)[i] / 255.0
               : v->texture_bits == 16 ? ((const uint16_t *)v->texels)[i] / 65535.0
                                       : ((const float *)v->texels)[i];
    double *T = malloc(n * sizeof *T); /* the texels, for choosing points */
    memcpy(T, C, n * sizeof *T);
    for (uint32_t z = 0; z < D[2]; z++)
        for (uint32_t y = 0; y < D[1]; y++) prefilter_line(at(C, 0, y, z), D[0], 1);
    for (uint32_t z = 0; z < D[2]; z++)
        for (uint32_t x = 0; x < D[0]; x++) prefilter_line(at(C, x, 0, z), D[1], D[0]);
    for (uint32_t y = 0; y < D[1]; y++)
        for (uint32_t x = 0; x < D[0]; x++) prefilter_line(at(C, x, y, 0), D[2], (size_t)D[0] * D[1]);

    /* points in tissue (stored value 0.15..0.45: ch2better's grey/white
     * matter on the 8-bit scale), 8+ voxels from the border */
    enum { N = 20000 };
    float *pts = malloc(sizeof(float) * 3 * N), *gpu = malloc(sizeof(float) * 3 * N);
    uint64_t s = 12345;
    int m = 0;
    while (m < N) {
        float q[3];
        for (int c = 0; c < 3; c++) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            q[c] = (float)(8 + (double)(s >> 11) / 9007199254740992.0 * (D[c] - 17));
        }
        double t = *at(T, (int)lrintf(q[0]), (int)lrintf(q[1]), (int)lrintf(q[2]));
        if (t < 0.15 || t > 0.45) continue;
        memcpy(pts + 3 * m++, q, sizeof q);
    }
    vxl_renderer_options o = {.struct_size = sizeof o};
    if (vxl_renderer_create(&o, &r) || vxl_renderer_set_volume(r, v)) return fprintf(stderr, "%s\n", vxl_last_error()), 1;
    vxl_render_params p = {.struct_size = sizeof p, .filter = VXL_FILTER_CUBIC};
    if (argc > 2) vxl_filter_from_name(argv[2], &p.filter);
    if (vxl_probe_gradients(r, &p, pts, N, gpu)) return fprintf(stderr, "%s\n", vxl_renderer_error(r)), 1;
    double *a_gpu = malloc(N * sizeof(double)), *a_q = malloc(N * sizeof(double)), *a_gq = malloc(N * sizeof(double));
    double rel_gpu = 0, rel_q = 0, mag = 0;
    for (int i = 0; i < N; i++) {
        double e[3], q[3], g[3] = {gpu[3 * i], gpu[3 * i + 1], gpu[3 * i + 2]};
        grad_exact(pts + 3 * i, e);
        grad_twofetch_q(pts + 3 * i, q);
        a_gpu[i] = ang(g, e);
        a_q[i] = ang(q, e);
        a_gq[i] = ang(g, q);
        double le = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        mag += le;
        rel_gpu += sqrt((g[0] - e[0]) * (g[0] - e[0]) + (g[1] - e[1]) * (g[1] - e[1]) + (g[2] - e[2]) * (g[2] - e[2]));
        rel_q += sqrt((q[0] - e[0]) * (q[0] - e[0]) + (q[1] - e[1]) * (q[1] - e[1]) + (q[2] - e[2]) * (q[2] - e[2]));
    }
    qsort(a_gpu, N, sizeof(double), cmpd);
    qsort(a_q, N, sizeof(double), cmpd);
    qsort(a_gq, N, sizeof(double), cmpd);
    printf("%d points in tissue, mean |grad| %.4g per voxel (normalised value)\n", N, mag / N);
    printf("angle GPU vs double spline:         median %.3f  p95 %.3f  p99 %.3f deg; mean |error| %.3g (%.2f%% of mean |grad|)\n",
           a_gpu[N / 2], a_gpu[N * 95 / 100], a_gpu[N * 99 / 100], rel_gpu / N, 100 * rel_gpu / mag);
    printf("angle 8-bit-weight model vs double: median %.3f  p95 %.3f  p99 %.3f deg; mean |error| %.3g (%.2f%% of mean |grad|)\n",
           a_q[N / 2], a_q[N * 95 / 100], a_q[N * 99 / 100], rel_q / N, 100 * rel_q / mag);
    printf("angle GPU vs 8-bit-weight model:    median %.3f  p95 %.3f  p99 %.3f deg\n", a_gq[N / 2], a_gq[N * 95 / 100],
           a_gq[N * 99 / 100]);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
    return 0;
}
