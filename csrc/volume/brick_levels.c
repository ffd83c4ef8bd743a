/* brick_levels.c - coarser levels of a brick source, bit for bit as
 * storage/lod.c's vxl_volume_downsample2 (brick_levels.h). */
#include "brick_levels.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double vxl_texel_at(uint32_t bits, const void *t, size_t i)
{
    if (bits == 8) return ((const uint8_t *)t)[i] / 255.0;
    if (bits == 16) return ((const uint16_t *)t)[i] / 65535.0;
    return ((const float *)t)[i];
}

void vxl_texel_store(uint32_t bits, void *t, size_t i, double s)
{
    if (bits == 8) ((uint8_t *)t)[i] = (uint8_t)lround(s * 255);
    else if (bits == 16) ((uint16_t *)t)[i] = (uint16_t)lround(s * 65535);
    else ((float *)t)[i] = (float)s;
}

/* The stored texel of s, read back as a double: what the next level sums. */
static double rounded(uint32_t bits, double s)
{
    uint8_t t[4];
    vxl_texel_store(bits, t, 0, s);
    return vxl_texel_at(bits, t, 0);
}

double vxl_downsample2_const(uint32_t bits, double a, double b)
{
    double s = 0;
    for (int k = 0; k < 8; k++) s += (k & 4) ? b : a; /* lod.c's corner order: x, y, then z */
    return rounded(bits, s / 8);
}

/* Tap i of a slice as vxl_texel_at reads it; 8-bit codes through a table
 * of the same quotients (no division per tap: the same doubles, so the same
 * sums and bytes). */
static inline double tap(uint32_t bits, const double *u8, const void *t, size_t i)
{
    return bits == 8 ? u8[((const uint8_t *)t)[i]] : vxl_texel_at(bits, t, i);
}

/* Whether the eight integer codes at a, b, c, d of slices s0 and s1 are equal. */
static inline int same8(uint32_t bits, const void *s0, const void *s1, size_t a, size_t b, size_t c, size_t d)
{
    if (bits == 8) {
        const uint8_t *p = s0, *q = s1, v = p[a];
        return p[b] == v && p[c] == v && p[d] == v && q[a] == v && q[b] == v && q[c] == v && q[d] == v;
    }
    const uint16_t *p = s0, *q = s1, v = p[a];
    return p[b] == v && p[c] == v && p[d] == v && q[a] == v && q[b] == v && q[c] == v && q[d] == v;
}

static inline void copy_code(uint32_t bits, const void *src, size_t i, void *out, size_t o)
{
    if (bits == 8) ((uint8_t *)out)[o] = ((const uint8_t *)src)[i];
    else ((uint16_t *)out)[o] = ((const uint16_t *)src)[i];
}

void vxl_downsample2_slice(uint32_t bits, const void *s0, const void *s1, uint32_t w, uint32_t h, void *out)
{
    double u8[256];
    if (bits == 8)
        for (int i = 0; i < 256; i++) u8[i] = i / 255.0;
    const uint32_t ow = (w + 1) / 2, oh = (h + 1) / 2;
    for (uint32_t y = 0; y < oh; y++) {
        const size_t y0 = (size_t)w * (2 * y), y1 = (size_t)w * (2 * y + 1 < h ? 2 * y + 1 : h - 1);
        for (uint32_t x = 0; x < ow; x++) {
            const size_t x0 = 2 * (size_t)x, x1 = 2 * x + 1 < w ? 2 * (size_t)x + 1 : w - 1;
            if (bits != 32 && same8(bits, s0, s1, x0 + y0, x1 + y0, x0 + y1, x1 + y1)) {
                /* eight equal codes: their mean rounds back to the code (the
                 * double sum is within a few ulp of 8 c / (2^bits - 1)), so
                 * the result is lod.c's without the sum; most of a sparse
                 * volume is such blocks */
                copy_code(bits, s0, x0 + y0, out, x + (size_t)ow * y);
                continue;
            }
            /* the corners in vxl_volume_downsample2's order (bit 0 x, bit 1 y, bit 2 z), summed in double */
            double s = 0;
            s += tap(bits, u8, s0, x0 + y0);
            s += tap(bits, u8, s0, x1 + y0);
            s += tap(bits, u8, s0, x0 + y1);
            s += tap(bits, u8, s0, x1 + y1);
            s += tap(bits, u8, s1, x0 + y0);
            s += tap(bits, u8, s1, x1 + y0);
            s += tap(bits, u8, s1, x0 + y1);
            s += tap(bits, u8, s1, x1 + y1);
            vxl_texel_store(bits, out, x + (size_t)ow * y, s / 8);
        }
    }
}

void vxl_downsample2_box(uint32_t bits, const void *src, const uint32_t dims[3], void *out)
{
    const size_t bpv = bits / 8, slice = (size_t)dims[0] * dims[1] * bpv;
    const size_t oslice = (size_t)((dims[0] + 1) / 2) * ((dims[1] + 1) / 2) * bpv;
    for (uint32_t z = 0; z < (dims[2] + 1) / 2; z++) {
        const uint32_t z1 = 2 * z + 1 < dims[2] ? 2 * z + 1 : dims[2] - 1;
        vxl_downsample2_slice(bits, (const uint8_t *)src + slice * 2 * z, (const uint8_t *)src + slice * z1, dims[0],
                              dims[1], (uint8_t *)out + oslice * z);
    }
}

void vxl_level_copy_box(uint32_t bits, const uint8_t *level, const uint32_t ld[3], const uint32_t lo[3],
                        const uint32_t size[3], void *out)
{
    const size_t bpv = bits / 8, run = (size_t)size[0] * bpv;
    uint8_t *o = out;
    for (uint32_t z = 0; z < size[2]; z++)
        for (uint32_t y = 0; y < size[1]; y++, o += run)
            memcpy(o, level + bpv * (lo[0] + (size_t)ld[0] * ((lo[1] + y) + (size_t)ld[1] * (lo[2] + z))), run);
}

/* ------------------------------------------------------------- the pyramid */

static size_t slice_bytes(const vxl_level_build *b, uint32_t k)
{
    return (size_t)b->dims[k][0] * b->dims[k][1] * (b->texture_bits / 8);
}

static void fill_const(uint32_t bits, void *t, size_t n, double value)
{
    for (size_t i = 0; i < n; i++) vxl_texel_store(bits, t, i, value);
}

int vxl_level_build_begin(vxl_level_build *b, const uint32_t dims[3], uint32_t bits, uint32_t n_levels,
                          uint64_t keep_bytes, vxl_err *e)
{
    memset(b, 0, sizeof *b);
    b->texture_bits = bits;
    b->n_levels = n_levels < 1 ? 1 : n_levels > VXL_SOURCE_MAX_LEVELS ? VXL_SOURCE_MAX_LEVELS : n_levels;
    for (uint32_t k = 0; k < b->n_levels; k++)
        for (int a = 0; a < 3; a++) b->dims[k][a] = k ? (b->dims[k - 1][a] + 1) / 2 : dims[a];
    for (uint32_t k = 0; k < b->n_levels; k++) {
        const size_t sb = slice_bytes(b, k);
        if (k + 1 < b->n_levels) { /* a level with a coarser one after it pairs its slices */
            if (!(b->pending[k].texels = malloc(sb))) goto oom;
            b->bytes += sb;
        }
        if (!(b->scratch[k] = malloc(sb))) goto oom; /* level k's output, or where a constant is spelled out */
        b->bytes += sb;
        if (k == 0) continue;
        const uint64_t lb = (uint64_t)sb * b->dims[k][2];
        if (lb <= keep_bytes) {
            if (!(b->kept[k] = malloc((size_t)lb))) goto oom;
            b->bytes += lb;
        }
    }
    return VXL_OK;
oom:
    vxl_level_build_free(b);
    return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the coarser levels of a %ux%ux%u volume", dims[0],
                    dims[1], dims[2]);
}

static void feed(vxl_level_build *b, uint32_t k, const void *texels, int is_const, double value);

/* Level k's pending slice and (texels | constant) make level k+1's next slice. */
static void pair(vxl_level_build *b, uint32_t k, const void *texels, int is_const, double value)
{
    vxl_level_slice *p = &b->pending[k];
    const uint32_t bits = b->texture_bits;
    p->full = 0;
    if (p->is_const && is_const) {
        feed(b, k + 1, NULL, 1, vxl_downsample2_const(bits, p->value, value));
        return;
    }
    const size_t n = (size_t)b->dims[k][0] * b->dims[k][1];
    if (p->is_const) fill_const(bits, p->texels, n, p->value);
    if (is_const) { /* the caller passed no texels, so this level's scratch slice is free */
        fill_const(bits, b->scratch[k], n, value);
        texels = b->scratch[k];
    }
    vxl_downsample2_slice(bits, p->texels, texels, b->dims[k][0], b->dims[k][1], b->scratch[k + 1]);
    feed(b, k + 1, b->scratch[k + 1], 0, 0);
}

/* Slice b->pending[k].z of level k arrives. */
static void feed(vxl_level_build *b, uint32_t k, const void *texels, int is_const, double value)
{
    vxl_level_slice *p = &b->pending[k];
    const size_t sb = slice_bytes(b, k);
    const uint32_t z = p->z++;
    if (b->kept[k]) {
        uint8_t *dst = b->kept[k] + sb * z;
        if (is_const) fill_const(b->texture_bits, dst, sb / (b->texture_bits / 8), value);
        else memcpy(dst, texels, sb);
    }
    if (k + 1 >= b->n_levels) return;
    if (!p->full) { /* an even slice: wait for its partner */
        p->full = 1;
        p->is_const = is_const;
        p->value = value;
        if (!is_const) memcpy(p->texels, texels, sb);
        return;
    }
    pair(b, k, texels, is_const, value);
}

void vxl_level_build_slice(vxl_level_build *b, const void *texels, int is_const, double value)
{
    feed(b, 0, texels, is_const, value);
}

void vxl_level_build_finish(vxl_level_build *b)
{
    for (uint32_t k = 0; k + 1 < b->n_levels; k++) {
        vxl_level_slice *p = &b->pending[k];
        if (!p->full) continue;
        /* an odd count of slices: the last pairs with itself, as lod.c clamps */
        if (p->is_const) pair(b, k, NULL, 1, p->value);
        else pair(b, k, p->texels, 0, 0); /* pair() reads it as both slices */
    }
}

void vxl_level_build_free(vxl_level_build *b)
{
    for (uint32_t k = 0; k < VXL_SOURCE_MAX_LEVELS; k++) {
        free(b->kept[k]);
        free(b->pending[k].texels);
        free(b->scratch[k]);
    }
    memset(b, 0, sizeof *b);
}
