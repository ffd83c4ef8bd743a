/* bspline_bricks.c - the cubic filter's coefficients brick by brick, and the
 * precomputed filter's gradient maximum, on the CPU. See bspline_bricks.h. */
#include "bspline_bricks.h"

#include <math.h>
#include <stdlib.h>

#define POLE (-0.26794919243112270f) /* sqrt(3) - 2, as shaders/compute/bspline_prefilter.comp */
#define GAIN 6.0f

#define MAX_LINES 128 /* lines filtered together: at most a window edge */
_Static_assert(64 + 2 * (VXL_PAGE_GHOST + VXL_BSPLINE_MARGIN) <= MAX_LINES, "a window edge of the largest page brick");

/* `count` lines in place, line j's element k at c[k * stride + j * across]:
 * exactly bspline_prefilter.comp's recursion on each line (mirror boundary,
 * causal start truncated at 13 terms), with the loop across lines inside so
 * that independent lines fill the pipeline (and the vector unit, where the
 * lines lie side by side) instead of one line's chain of dependent steps. */
static void prefilter_lines(float *c, uint32_t n, size_t stride, size_t across, uint32_t count)
{
    if (n < 2) return;
    float acc[MAX_LINES];
    const uint32_t horizon = n < 13 ? n : 13;
    for (uint32_t j = 0; j < count; j++) acc[j] = 0.0f;
    float zk = 1.0f;
    for (uint32_t k = 0; k < horizon; k++) {
        for (uint32_t j = 0; j < count; j++) acc[j] += zk * GAIN * c[k * stride + j * across];
        zk *= POLE;
    }
    for (uint32_t j = 0; j < count; j++) c[j * across] = acc[j];
    for (uint32_t k = 1; k < n; k++)
        for (uint32_t j = 0; j < count; j++) {
            acc[j] = GAIN * c[k * stride + j * across] + POLE * acc[j];
            c[k * stride + j * across] = acc[j];
        }
    for (uint32_t j = 0; j < count; j++) {
        acc[j] = POLE / (POLE * POLE - 1.0f) * (acc[j] + POLE * c[(n - 2) * stride + j * across]);
        c[(n - 1) * stride + j * across] = acc[j];
    }
    for (uint32_t k = n - 1; k-- > 0;)
        for (uint32_t j = 0; j < count; j++) {
            acc[j] = POLE * (acc[j] - c[k * stride + j * across]);
            c[k * stride + j * across] = acc[j];
        }
}

size_t vxl_bspline_scratch_floats(const vxl_pages *pg)
{
    const size_t w = pg->brick + 2 * (VXL_PAGE_GHOST + VXL_BSPLINE_MARGIN);
    return w * w * w;
}

static int64_t clamp64(int64_t v, int64_t lo, int64_t hi) { return v < lo ? lo : v > hi ? hi : v; }

void vxl_bspline_brick(const vxl_pages *pg, const vxl_brick_store *s, const uint32_t dims[3], uint64_t i,
                       float *scratch, float *out)
{
    const uint32_t P = pg->brick, e = P + 2 * VXL_PAGE_GHOST;
    const uint64_t b[3] = {i % pg->grid[0], i / pg->grid[0] % pg->grid[1], i / ((uint64_t)pg->grid[0] * pg->grid[1])};
    int64_t lo[3], first[3], last[3];
    uint32_t size[3];
    for (int a = 0; a < 3; a++) {
        const int64_t v0 = (int64_t)b[a] * P - VXL_PAGE_GHOST, v1 = v0 + e - 1; /* the brick and its ghost */
        lo[a] = clamp64(v0 - VXL_BSPLINE_MARGIN, 0, dims[a] - 1);
        size[a] = (uint32_t)(clamp64(v1 + VXL_BSPLINE_MARGIN, 0, dims[a] - 1) - lo[a] + 1);
        first[a] = clamp64(v0, 0, dims[a] - 1) - lo[a]; /* the output's window range */
        last[a] = clamp64(v1, 0, dims[a] - 1) - lo[a];
    }
    vxl_pages_gather(pg, s, dims, lo, size, scratch);
    const size_t sy = size[0], sz = (size_t)size[0] * size[1];
    /* x over every line, then y and z only over the lines the output reads */
    const uint32_t nx = (uint32_t)(last[0] - first[0] + 1);
    for (uint32_t z = 0; z < size[2]; z++) prefilter_lines(scratch + z * sz, size[0], 1, sy, size[1]);
    for (uint32_t z = 0; z < size[2]; z++) prefilter_lines(scratch + first[0] + z * sz, size[1], sy, 1, nx);
    for (int64_t y = first[1]; y <= last[1]; y++) prefilter_lines(scratch + first[0] + y * sy, size[2], sz, 1, nx);
    for (uint32_t z = 0; z < e; z++)
        for (uint32_t y = 0; y < e; y++)
            for (uint32_t x = 0; x < e; x++) {
                int64_t w[3];
                const uint32_t l[3] = {x, y, z};
                for (int a = 0; a < 3; a++)
                    w[a] = clamp64((int64_t)b[a] * P + l[a] - VXL_PAGE_GHOST, 0, dims[a] - 1) - lo[a];
                *out++ = scratch[w[0] + w[1] * sy + w[2] * sz];
            }
}

/* ---- the precomputed filter's maximum ---- */

/* A cube of floats of edge n, and the 3-tap filter k along axis a written
 * to dst over the box [lo, hi) (which keeps one voxel from the faces along a). */
static void pass3(const float *src, float *dst, uint32_t n, int a, const float k[3], const uint32_t lo[3],
                  const uint32_t hi[3])
{
    const size_t step = a == 0 ? 1 : a == 1 ? n : (size_t)n * n;
    for (uint32_t z = lo[2]; z < hi[2]; z++)
        for (uint32_t y = lo[1]; y < hi[1]; y++)
            for (uint32_t x = lo[0]; x < hi[0]; x++) {
                const size_t t = x + (size_t)n * (y + (size_t)n * z);
                dst[t] = k[0] * src[t - step] + k[1] * src[t] + k[2] * src[t + step];
            }
}

/* Planes of the blurred cube whose volume position lies outside the volume
 * take the nearest inside plane's values: the Sobel reads the blurred
 * volume with clamped positions. */
static void clamp_planes(float *c, uint32_t n, int64_t origin, uint32_t dim, int a, uint32_t lo, uint32_t hi)
{
    const size_t step = a == 0 ? 1 : a == 1 ? n : (size_t)n * n;
    for (uint32_t l = lo; l < hi; l++) {
        const int64_t g = origin + l, in = clamp64(g, 0, (int64_t)dim - 1);
        if (g == in) continue;
        const uint32_t from = (uint32_t)(in - origin);
        for (size_t q = 0; q < (size_t)n * n; q++) { /* every line across the plane */
            const size_t u = q % n, v = q / n;
            const size_t base = a == 0 ? n * (u + (size_t)n * v) : a == 1 ? u + (size_t)n * n * v : u + (size_t)n * v;
            c[base + l * step] = c[base + from * step];
        }
    }
}

float vxl_pages_gradient_max(const vxl_pages *pg, const vxl_brick_store *s, const uint32_t dims[3])
{
    const uint32_t P = pg->brick, n = P + 4; /* the brick, the Sobel's reach and the blur's */
    const size_t cube = (size_t)n * n * n;
    float *buf = malloc(7 * cube * sizeof *buf);
    if (!buf) return -1.0f;
    float *v = buf, *t = buf + cube, *u = buf + 2 * cube, *w = buf + 3 * cube, *comp = buf + 4 * cube;
    static const float smooth[3] = {0.25f, 0.5f, 0.25f}, deriv[3] = {-1.0f, 0.0f, 1.0f};
    float max2 = 0.0f;
    for (uint64_t i = 0; i < vxl_page_count(pg); i++) {
        if (vxl_pages_flat_around(pg, i, VXL_GRADIENT_SUPPORT)) continue; /* zero gradient */
        const uint64_t b[3] = {i % pg->grid[0], i / pg->grid[0] % pg->grid[1], i / ((uint64_t)pg->grid[0] * pg->grid[1])};
        int64_t lo[3];
        uint32_t m[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = (int64_t)b[a] * P - 2;
            m[a] = (uint32_t)((int64_t)dims[a] - (int64_t)b[a] * P < P ? dims[a] - b[a] * P : P);
        }
        const uint32_t size[3] = {n, n, n};
        vxl_pages_gather(pg, s, dims, lo, size, v);
        /* blur at local 1 .. n-2 (volume positions brick - 1 .. brick + P) */
        const uint32_t in0[3] = {1, 0, 0}, in1[3] = {n - 1, n, n};
        pass3(v, t, n, 0, smooth, in0, in1);
        const uint32_t in2[3] = {1, 1, 0}, in3[3] = {n - 1, n - 1, n};
        pass3(t, u, n, 1, smooth, in2, in3);
        const uint32_t bl[3] = {1, 1, 1}, bh[3] = {n - 1, n - 1, n - 1};
        pass3(u, t, n, 2, smooth, bl, bh); /* t: the blurred volume */
        for (int a = 0; a < 3; a++) clamp_planes(t, n, lo[a], dims[a], a, 1, n - 1);
        /* Sobel at the brick's voxels (local 2 .. 2+m-1) per component:
         * derivative along one axis, [1,2,1] along the other two */
        const uint32_t o0[3] = {2, 2, 2}, o1[3] = {2 + m[0], 2 + m[1], 2 + m[2]};
        float *g[3] = {NULL, NULL, NULL};
        for (int a = 0; a < 3; a++) {
            const int s1 = (a + 1) % 3, s2 = (a + 2) % 3;
            uint32_t l1[3], h1[3], l2[3], h2[3];
            for (int k = 0; k < 3; k++) { /* first smoothing: its axis at the brick, the rest wide */
                l1[k] = k == s1 ? o0[k] : 1;
                h1[k] = k == s1 ? o1[k] : n - 1;
                l2[k] = k == a ? 1 : o0[k];
                h2[k] = k == a ? n - 1 : o1[k];
            }
            pass3(t, u, n, s1, smooth, l1, h1);
            pass3(u, w, n, s2, smooth, l2, h2);
            g[a] = comp + a * cube;
            pass3(w, g[a], n, a, deriv, o0, o1);
        }
        for (uint32_t z = o0[2]; z < o1[2]; z++)
            for (uint32_t y = o0[1]; y < o1[1]; y++)
                for (uint32_t x = o0[0]; x < o1[0]; x++) {
                    const size_t q = x + (size_t)n * (y + (size_t)n * z);
                    /* [1,2,1] smoothing is /4 twice here and 16 x the shader's weights: /32 -> /2 */
                    const float gx = g[0][q] * 0.5f, gy = g[1][q] * 0.5f, gz = g[2][q] * 0.5f;
                    const float m2 = gx * gx + gy * gy + gz * gz;
                    max2 = m2 > max2 ? m2 : max2;
                }
    }
    free(buf);
    return sqrtf(max2);
}
