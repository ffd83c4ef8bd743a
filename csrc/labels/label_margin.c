/* label_margin.c - each voxel's margin inside its own label (label_margin.h).
 * Each label's indicator is smoothed separably over its bounding box grown
 * by the kernel's radius, so the work follows the labels' extents, not
 * their number; a label map whose boxes add up to much more than the volume
 * (many labels spread over all of it) is smoothed voxel by voxel instead,
 * which costs a fixed (2 RADIUS + 1)^3 taps a voxel. */
#include "label_margin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define R VXL_LABEL_MARGIN_RADIUS
#define IDS 65536u
#define BOX_FACTOR 16 /* boxes worth more than this many volumes: voxel by voxel */

static void kernel(float k[2 * R + 1])
{
    double s = 0;
    for (int i = -R; i <= R; i++) s += exp(-0.5 * i * i / (VXL_LABEL_MARGIN_SIGMA * VXL_LABEL_MARGIN_SIGMA));
    for (int i = -R; i <= R; i++)
        k[i + R] = (float)(exp(-0.5 * i * i / (VXL_LABEL_MARGIN_SIGMA * VXL_LABEL_MARGIN_SIGMA)) / s);
}

static uint8_t encode(double m)
{
    double mu = m - 0.5;
    if (mu < VXL_LABEL_MARGIN_MIN) mu = VXL_LABEL_MARGIN_MIN;
    if (mu > 0.5) mu = 0.5;
    return (uint8_t)lround(mu * 510.0);
}

/* Along one axis of the box (n[0] x n[1] x n[2], axis a): dst = src
 * convolved with k, taps past the box repeating its edge: where the box
 * ends at the volume's face the label goes on as it ends there (so a
 * label's margins do not depend on where the volume ends), elsewhere the
 * edge is one of the radius's zeros. */
static void smooth_axis(float *dst, const float *src, const uint32_t n[3], int a, const float *k)
{
    const size_t stride = a == 0 ? 1 : a == 1 ? n[0] : (size_t)n[0] * n[1];
    const long len = (long)n[a];
    const size_t total = (size_t)n[0] * n[1] * n[2];
    for (size_t i = 0; i < total; i++) {
        const long p = (long)((i / stride) % (size_t)len);
        float s = 0;
        for (long d = -R; d <= R; d++) {
            const long q = p + d < 0 ? -p : p + d >= len ? len - 1 - p : d;
            s += k[d + R] * src[(long)i + q * (long)stride];
        }
        dst[i] = s;
    }
}

static void by_voxel(uint8_t *out, const uint16_t *ids, const uint32_t dims[3], const float *k)
{
    for (uint32_t z = 0; z < dims[2]; z++)
        for (uint32_t y = 0; y < dims[1]; y++)
            for (uint32_t x = 0; x < dims[0]; x++) {
                const size_t i = x + (size_t)dims[0] * (y + (size_t)dims[1] * z);
                const uint16_t own = ids[i];
                double m = 0;
                for (int dz = -R; dz <= R; dz++) {
                    long zz = (long)z + dz;
                    zz = zz < 0 ? 0 : zz >= (long)dims[2] ? (long)dims[2] - 1 : zz;
                    for (int dy = -R; dy <= R; dy++) {
                        long yy = (long)y + dy;
                        yy = yy < 0 ? 0 : yy >= (long)dims[1] ? (long)dims[1] - 1 : yy;
                        const uint16_t *row = ids + (size_t)dims[0] * ((size_t)yy + (size_t)dims[1] * (size_t)zz);
                        float sx = 0;
                        for (int dx = -R; dx <= R; dx++) {
                            long xx = (long)x + dx;
                            xx = xx < 0 ? 0 : xx >= (long)dims[0] ? (long)dims[0] - 1 : xx;
                            if (row[xx] == own) sx += k[dx + R];
                        }
                        m += (double)sx * k[dy + R] * k[dz + R];
                    }
                }
                out[i] = encode(m);
            }
}

int vxl_label_margin_build(uint8_t *out, const uint16_t *ids, const uint32_t dims[3])
{
    float k[2 * R + 1];
    kernel(k);
    const size_t n = (size_t)dims[0] * dims[1] * dims[2];
    uint32_t *box = malloc(IDS * 6 * sizeof *box); /* per id: lo x y z, hi x y z (inclusive) */
    if (!box) return -1;
    for (uint32_t i = 0; i < IDS; i++) {
        box[6 * i] = box[6 * i + 1] = box[6 * i + 2] = UINT32_MAX;
        box[6 * i + 3] = box[6 * i + 4] = box[6 * i + 5] = 0;
    }
    for (uint32_t z = 0; z < dims[2]; z++)
        for (uint32_t y = 0; y < dims[1]; y++)
            for (uint32_t x = 0; x < dims[0]; x++) {
                uint32_t *b = box + 6 * (size_t)ids[x + (size_t)dims[0] * (y + (size_t)dims[1] * z)];
                const uint32_t c[3] = {x, y, z};
                for (int a = 0; a < 3; a++) {
                    if (c[a] < b[a]) b[a] = c[a];
                    if (c[a] > b[3 + a]) b[3 + a] = c[a];
                }
            }
    /* each box grown by the radius (the smoothed indicator reaches that far), clipped to the volume */
    double work = 0;
    size_t biggest = 0;
    for (uint32_t i = 0; i < IDS; i++) {
        uint32_t *b = box + 6 * (size_t)i;
        if (b[0] == UINT32_MAX) continue;
        size_t v = 1;
        for (int a = 0; a < 3; a++) {
            b[a] = b[a] > R ? b[a] - R : 0;
            b[3 + a] = b[3 + a] + R < dims[a] ? b[3 + a] + R : dims[a] - 1;
            v *= b[3 + a] - b[a] + 1;
        }
        work += (double)v;
        if (v > biggest) biggest = v;
    }
    if (work > (double)BOX_FACTOR * (double)n) {
        free(box);
        by_voxel(out, ids, dims, k);
        return 0;
    }
    float *a = malloc(biggest * sizeof *a), *t = malloc(biggest * sizeof *t);
    if (!a || !t) {
        free(a);
        free(t);
        free(box);
        return -1;
    }
    for (uint32_t id = 0; id < IDS; id++) {
        const uint32_t *b = box + 6 * (size_t)id;
        if (b[0] == UINT32_MAX) continue;
        const uint32_t m[3] = {b[3] - b[0] + 1, b[4] - b[1] + 1, b[5] - b[2] + 1};
        for (uint32_t z = 0; z < m[2]; z++)
            for (uint32_t y = 0; y < m[1]; y++) {
                const uint16_t *row = ids + b[0] + (size_t)dims[0] * (b[1] + y + (size_t)dims[1] * (b[2] + z));
                float *dst = a + (size_t)m[0] * (y + (size_t)m[1] * z);
                for (uint32_t x = 0; x < m[0]; x++) dst[x] = row[x] == id ? 1.0f : 0.0f;
            }
        smooth_axis(t, a, m, 0, k);
        smooth_axis(a, t, m, 1, k);
        smooth_axis(t, a, m, 2, k);
        for (uint32_t z = 0; z < m[2]; z++)
            for (uint32_t y = 0; y < m[1]; y++) {
                const size_t o = b[0] + (size_t)dims[0] * (b[1] + y + (size_t)dims[1] * (b[2] + z));
                const float *src = t + (size_t)m[0] * (y + (size_t)m[1] * z);
                for (uint32_t x = 0; x < m[0]; x++)
                    if (ids[o + x] == id) out[o + x] = encode(src[x]);
            }
    }
    free(a);
    free(t);
    free(box);
    return 0;
}
