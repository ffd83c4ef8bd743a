/* preint.c - builds the pre-integration table from prefix integrals of
 * extinction T(x) = int tau and of extinction-weighted colour K(x) = int c tau,
 * with tau = -ln(1 - alpha) per voxel. For a segment of length d:
 *   alpha = 1 - exp(-d (T(b) - T(f)) / (b - f))
 *   colour = alpha (K(b) - K(f)) / (T(b) - T(f))
 * (the extinction-weighted mean colour; measured in measured-facts.md as the
 * accurate choice, 0.006 error at 1 sample per voxel), and for f = b the
 * limits alpha = 1 - exp(-d tau(f)), colour = alpha c(f). */
#include "preint.h"

#include "error.h"
#include "voxlight_dev.h"

#include <math.h>
#include <stdlib.h>

#define MAX_ALPHA (1.0 - 1e-7) /* keeps tau finite */
#define MAX_DEPTH 80.0
#define SUB 16             /* midpoint samples per table cell for the prefix integrals */         /* exp(-80) ~ 1e-35: beyond it the segment is opaque */

/* The transfer function at table position x in [0,1], as GL_LINEAR reads
 * a tf_size texture at classify.glsl's coordinate. */
static void tf_at(const float *tf, uint32_t tf_size, double x, double out[4])
{
    double u = x * (tf_size - 1);
    uint32_t i0 = (uint32_t)floor(u);
    if (i0 > tf_size - 1) i0 = tf_size - 1;
    uint32_t i1 = i0 + 1 < tf_size ? i0 + 1 : i0;
    double w = u - i0;
    for (int k = 0; k < 4; k++) out[k] = tf[4 * i0 + k] * (1 - w) + tf[4 * i1 + k] * w;
}

static double opacity_from_depth(double depth)
{
    return depth >= MAX_DEPTH ? 1.0 : depth <= 0 ? 0.0 : -expm1(-depth);
}

int vxl_preint_build(const float *tf, uint32_t tf_size, float opacity_scale, double step, uint32_t n, float *out)
{
    if (!tf || tf_size < 2 || n < 2 || !out || !(step > 0)) return -1;
    double *tau = malloc(n * sizeof *tau), *col = malloc(3 * (size_t)n * sizeof *col);
    double *T = malloc(n * sizeof *T), *K = malloc(3 * (size_t)n * sizeof *K);
    if (!tau || !col || !T || !K) {
        free(tau); free(col); free(T); free(K);
        return -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        double c[4];
        tf_at(tf, tf_size, i / (double)(n - 1), c);
        double a = c[3] * opacity_scale;
        a = a < 0 ? 0 : a > MAX_ALPHA ? MAX_ALPHA : a;
        tau[i] = -log1p(-a);
        for (int k = 0; k < 3; k++) col[3 * i + k] = c[k];
    }
    /* Prefix integrals over table index. tau is not linear between table
     * entries (the tf's alpha is), so each cell is integrated with SUB
     * midpoint samples of the tf itself: still O(n). */
    T[0] = 0;
    K[0] = K[1] = K[2] = 0;
    for (uint32_t i = 1; i < n; i++) {
        double t = 0, kk[3] = {0, 0, 0};
        for (int m = 0; m < SUB; m++) {
            double c[4];
            tf_at(tf, tf_size, (i - 1 + (m + 0.5) / SUB) / (double)(n - 1), c);
            double a = c[3] * opacity_scale;
            a = a < 0 ? 0 : a > MAX_ALPHA ? MAX_ALPHA : a;
            double tm = -log1p(-a) / SUB;
            t += tm;
            for (int k = 0; k < 3; k++) kk[k] += c[k] * tm;
        }
        T[i] = T[i - 1] + t;
        for (int k = 0; k < 3; k++) K[3 * i + k] = K[3 * (i - 1) + k] + kk[k];
    }
    for (uint32_t b = 0; b < n; b++)
        for (uint32_t f = 0; f < n; f++) {
            float *o = out + ((size_t)b * n + f) * 4;
            double alpha, rgb[3];
            if (f == b) {
                alpha = opacity_from_depth(step * tau[f]);
                for (int k = 0; k < 3; k++) rgb[k] = alpha * col[3 * f + k];
            } else {
                double dT = T[b] - T[f], di = (double)b - (double)f;
                alpha = opacity_from_depth(step * dT / di);
                for (int k = 0; k < 3; k++) {
                    double dK = K[3 * b + k] - K[3 * f + k];
                    /* no extinction on the way: alpha is 0 and so is the colour */
                    rgb[k] = fabs(dT) > 1e-30 ? alpha * dK / dT : 0;
                }
            }
            for (int k = 0; k < 3; k++) {
                double v = rgb[k] < 0 ? 0 : rgb[k] > alpha ? alpha : rgb[k];
                o[k] = (float)v;
            }
            o[3] = (float)alpha;
        }
    free(tau); free(col); free(T); free(K);
    return 0;
}

int vxl_preint_table(const float *tf, uint32_t tf_size, float opacity_scale, float step, uint32_t n, float *out)
{
    if (!tf || !out || tf_size < 2 || n < 2 || n > 4096 || !(step > 0) || !isfinite(step))
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "preint_table: bad table, size or step");
    float scale = opacity_scale == 0 ? 1.0f : opacity_scale;
    if (!(scale > 0) || !isfinite(scale))
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "preint_table: bad opacity scale %g", opacity_scale);
    if (vxl_preint_build(tf, tf_size, scale, step, n, out))
        return vxl_fail(NULL, VXL_ERR_NO_MEMORY, "preint_table: out of memory");
    return VXL_OK;
}
