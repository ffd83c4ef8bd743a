/* bricks.c - occupancy of bricks under a classification, and the Chebyshev
 * distance map that lets rays leap over runs of empty bricks. CPU-side: the
 * grid is small (ch2better at 8^3 bricks: 38x47x40 = 71k entries). */
#include "bricks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "voxlight.h"

/* VOXLIGHT_BRICK_SIZE (4..64) overrides the brick edge for measurements; the
 * default is justified in docs/skipping.md. */
uint32_t vxl_skip_brick_size(void)
{
    const char *env = getenv("VOXLIGHT_BRICK_SIZE");
    long v = env ? strtol(env, NULL, 10) : 0;
    return v >= 4 && v <= 64 ? (uint32_t)v : VXL_DEFAULT_BRICK;
}

uint32_t vxl_skip_brick_size_for(const uint32_t dims[3])
{
    if (getenv("VOXLIGHT_BRICK_SIZE")) return vxl_skip_brick_size();
    uint64_t n = 1;
    for (int a = 0; a < 3; a++) n *= (dims[a] + VXL_FINE_BRICK - 1) / VXL_FINE_BRICK;
    return n <= VXL_FINE_BRICK_MAX_COUNT ? VXL_FINE_BRICK : VXL_DEFAULT_BRICK;
}

/* Table index a normalised value maps to (as classify.glsl computes it). */
static double table_pos(const vxl_occupancy_rule *f, double v)
{
    double x = (v - f->window_offset) * f->window_scale;
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return x * (f->tf_size - 1);
}

/* 1-D exact L-infinity distance along one axis of a grid (in place on d):
 * d[i] = min_j max(|i - j|, d[j]), computed by brute force per line, which
 * at these grid sizes (<= 2048 / brick) is cheap and obviously right. */
static void chebyshev_axis(uint8_t *d, const uint32_t dims[3], int axis, uint8_t *line, uint8_t *out)
{
    uint32_t n = dims[axis];
    uint32_t stride = axis == 0 ? 1 : axis == 1 ? dims[0] : dims[0] * dims[1];
    uint32_t ou = axis == 0 ? dims[1] : dims[0], ov = axis == 2 ? dims[1] : dims[2];
    for (uint32_t v = 0; v < ov; v++)
        for (uint32_t u = 0; u < ou; u++) {
            size_t base = axis == 0 ? (size_t)dims[0] * (u + (size_t)dims[1] * v)
                        : axis == 1 ? u + (size_t)dims[0] * dims[1] * v
                                    : u + (size_t)dims[0] * v;
            for (uint32_t i = 0; i < n; i++) line[i] = d[base + (size_t)i * stride];
            for (uint32_t i = 0; i < n; i++) {
                uint32_t best = line[i];
                for (uint32_t j = 0; j < n && best > 0; j++) {
                    uint32_t dist = i > j ? i - j : j - i;
                    if (dist >= best) { if (j > i) break; else continue; }
                    uint32_t c = dist > line[j] ? dist : line[j];
                    if (c < best) best = c;
                }
                out[i] = (uint8_t)best;
            }
            for (uint32_t i = 0; i < n; i++) d[base + (size_t)i * stride] = out[i];
        }
}

uint32_t vxl_bricks_gradient_apron(uint32_t filter, float sample_distance)
{
    /* cubic: the prefiltered B-spline's derivative is not bounded by adjacent
     * differences; precomputed: stored relative to the volume's largest
     * gradient. Taps at +-d reach floor(p -+ d) .. +1: ceil(d) + 1 voxels. */
    if (filter == VXL_FILTER_CUBIC || filter == VXL_FILTER_PRECOMPUTED) return 0;
    /* approximating B-spline: its derivative is a convex blend of adjacent
     * differences over texels floor(p) - 1 .. floor(p) + 2 */
    if (filter == VXL_FILTER_CUBIC_SMOOTH) return 2;
    return (uint32_t)ceil(sample_distance) + 1;
}

/* Levoy's iso-surface opacity is non-zero only where |iso - v| <= r*|g|.
 * A sample's v lies in its brick's [min, max] and |g| <= the brick's
 * gradient bound, so a brick is occupied unless iso lies outside that range
 * widened by r times the bound. Without a usable bound, every brick is. */
static void classify_iso(vxl_bricks *b, const vxl_occupancy_rule *f)
{
    size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    uint32_t need = vxl_bricks_gradient_apron(f->filter, f->sample_distance);
    int bounded = need && b->gbound && b->gbound_apron >= need;
    uint32_t occupied = 0;
    for (size_t i = 0; i < n; i++) {
        int occ = 1;
        if (bounded) {
            /* 2% + 1e-4: texture filtering's fixed-point weights can stretch a
             * difference quotient slightly beyond the exact interpolant's */
            double reach = f->iso_thickness * (double)b->gbound[i] * 1.02 + 1e-4;
            occ = !(f->iso_pos < b->minmax[2 * i] - reach || f->iso_pos > b->minmax[2 * i + 1] + reach);
            if (isnan(reach) || isnan(b->minmax[2 * i]) || isnan(b->minmax[2 * i + 1])) occ = 1;
        }
        b->distance[i] = occ ? 0 : 255;
        occupied += (uint32_t)occ;
    }
    b->occupied = occupied;
}

/* Occupancy under the transfer function: a brick is occupied when any table
 * entry its [min, max] can reach has non-zero opacity. -1 out of memory. */
static int classify_table(vxl_bricks *b, const vxl_occupancy_rule *f)
{
    size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    /* prefix count of table entries with non-zero opacity */
    uint32_t *nonzero = malloc(((size_t)f->tf_size + 1) * sizeof *nonzero);
    if (!nonzero) return -1;
    nonzero[0] = 0;
    for (uint32_t i = 0; i < f->tf_size; i++) nonzero[i + 1] = nonzero[i] + (f->tf[4 * i + 3] * f->opacity_scale > 0);
    uint32_t occupied = 0;
    for (size_t i = 0; i < n; i++) {
        double u0 = table_pos(f, b->minmax[2 * i]), u1 = table_pos(f, b->minmax[2 * i + 1]);
        if (u0 > u1) { double t = u0; u0 = u1; u1 = t; }
        if (isnan(u0) || isnan(u1)) { /* cannot be placed in the table: assume visible */
            u0 = 0;
            u1 = f->tf_size - 1;
        }
        /* linear filtering reads floor(u)..floor(u)+1; widen by one entry
         * each way so float rounding in the shader can never escape */
        long lo = (long)floor(u0) - 1, hi = (long)floor(u1) + 2;
        if (lo < 0) lo = 0;
        if (hi > (long)f->tf_size - 1) hi = (long)f->tf_size - 1;
        int occ = nonzero[hi + 1] - nonzero[lo] > 0;
        b->distance[i] = occ ? 0 : 255;
        occupied += (uint32_t)occ;
    }
    free(nonzero);
    b->occupied = occupied;
    return 0;
}

int vxl_bricks_classify(vxl_bricks *b, const vxl_occupancy_rule *f)
{
    uint64_t key = f->table_key;
    if (f->iso) { /* occupancy follows the iso-surface, its thickness and the filter */
        float iso[5] = {f->iso_pos, f->iso_thickness, f->sample_distance, (float)f->filter, (float)b->gbound_apron};
        for (int i = 0; i < 5; i++) {
            uint32_t bits;
            memcpy(&bits, &iso[i], sizeof bits);
            key = (key ^ (bits + 0x9e3779b97f4a7c15ull * (i + 1))) * 1099511628211ull;
        }
    }
    if (b->distance && b->tf_key == key) return 0;
    size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    if (!b->distance && !(b->distance = malloc(n))) return -1;
    if (f->iso) classify_iso(b, f);
    else if (classify_table(b, f)) return -1;
    if (vxl_bricks_chebyshev(b->distance, b->dims)) return -1;
    b->tf_key = key;
    return 1;
}

int vxl_bricks_chebyshev(uint8_t *d, const uint32_t dims[3])
{
    uint32_t maxdim = dims[0] > dims[1] ? dims[0] : dims[1];
    maxdim = maxdim > dims[2] ? maxdim : dims[2];
    uint8_t *scratch = malloc(2 * (size_t)maxdim);
    if (!scratch) return -1;
    for (int axis = 0; axis < 3; axis++) chebyshev_axis(d, dims, axis, scratch, scratch + maxdim);
    free(scratch);
    return 0;
}

void vxl_bricks_free(vxl_bricks *b)
{
    free(b->minmax);
    free(b->distance);
    free(b->gbound);
    memset(b, 0, sizeof *b);
}
