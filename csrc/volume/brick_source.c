/* brick_source.c - what every brick source shares (brick_source.h): the
 * level grid, the index built slice by slice, progress. */
#include "brick_source.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

int vxl_brick_source_check_box(const vxl_brick_source *s, uint32_t level, const uint32_t lo[3],
                               const uint32_t size[3], vxl_err *e)
{
    if (level >= s->n_levels) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "level %u of %u", level, s->n_levels);
    const uint32_t *d = s->level_dims[level];
    for (int a = 0; a < 3; a++)
        if (size[a] == 0 || lo[a] >= d[a] || size[a] > d[a] - lo[a])
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "box %u+%u on axis %d is outside level %u (%u voxels)",
                            lo[a], size[a], a, level, d[a]);
    return VXL_OK;
}

void vxl_brick_source_retain(vxl_brick_source *s)
{
    if (s) __atomic_fetch_add(&s->refs, 1, __ATOMIC_ACQ_REL);
}

void vxl_brick_source_free(vxl_brick_source *s)
{
    if (!s) return;
    /* other holders remain: one of them closes it */
    uint32_t r = __atomic_load_n(&s->refs, __ATOMIC_ACQUIRE);
    while (r)
        if (__atomic_compare_exchange_n(&s->refs, &r, r - 1, 0, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE)) return;
    if (s->ops && s->ops->close) s->ops->close(s);
    free(s->minmax);
    free(s);
}

uint32_t vxl_source_index_brick(const uint32_t dims[3])
{
    uint32_t b = VXL_SOURCE_INDEX_BRICK;
    for (;;) {
        uint64_t n = 1;
        for (int a = 0; a < 3; a++) n *= (dims[a] + (uint64_t)b - 1) / b;
        if (n * 2 * sizeof(float) <= VXL_SOURCE_INDEX_MAX_BYTES || b >= (1u << 30)) return b;
        b *= 2;
    }
}

uint32_t vxl_source_level_count(const uint32_t dims[3])
{
    uint32_t m = dims[0] > dims[1] ? dims[0] : dims[1], n = 1;
    m = m > dims[2] ? m : dims[2];
    for (; m > 32 && n < VXL_SOURCE_MAX_LEVELS; n++) m = (m + 1) / 2;
    return n;
}

void vxl_brick_source_set_levels(vxl_brick_source *s, const uint32_t dims[3], uint32_t n_levels)
{
    s->n_levels = n_levels < 1 ? 1 : n_levels > VXL_SOURCE_MAX_LEVELS ? VXL_SOURCE_MAX_LEVELS : n_levels;
    for (uint32_t k = 0; k < s->n_levels; k++)
        for (int a = 0; a < 3; a++) s->level_dims[k][a] = k ? (s->level_dims[k - 1][a] + 1) / 2 : dims[a];
}

int vxl_source_progress(const vxl_load_options *opt, double fraction, const char *stage, vxl_err *e)
{
    const size_t need = offsetof(vxl_load_options, progress_user) + sizeof opt->progress_user;
    if (!opt || (opt->struct_size && opt->struct_size < need) || !opt->progress) return VXL_OK;
    if (opt->progress(opt->progress_user, fraction < 0 ? 0 : fraction > 1 ? 1 : fraction, stage))
        return vxl_fail(e, VXL_ERR_CANCELLED, "cancelled by the progress callback during %s",
                        stage ? stage : "a long pass");
    return VXL_OK;
}

/* ----------------------------------------------------------------- index */

int vxl_index_build_begin(vxl_index_build *b, const uint32_t dims[3], uint32_t bits, uint32_t brick, vxl_err *e)
{
    memset(b, 0, sizeof *b);
    memcpy(b->dims, dims, sizeof b->dims);
    b->texture_bits = bits;
    b->brick = brick;
    for (int a = 0; a < 3; a++) b->grid[a] = (dims[a] + brick - 1) / brick;
    const size_t n = (size_t)b->grid[0] * b->grid[1] * b->grid[2], layer = (size_t)b->grid[0] * b->grid[1];
    b->minmax = malloc(n * 2 * sizeof(float));
    b->slice = malloc(layer * 2 * sizeof(float));
    if (!b->minmax || !b->slice) {
        vxl_index_build_free(b);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the brick index of a %ux%ux%u volume", dims[0],
                        dims[1], dims[2]);
    }
    for (size_t i = 0; i < n; i++) {
        b->minmax[2 * i] = 1e30f;
        b->minmax[2 * i + 1] = -1e30f;
    }
    return VXL_OK;
}

/* Bricks c whose box plus apron, [c*B - 1, c*B + B], holds coordinate v. */
static void bricks_holding(uint32_t v, uint32_t B, uint32_t grid, uint32_t *lo, uint32_t *hi)
{
    *lo = v > 0 ? (v - 1) / B : 0;
    *hi = (v + 1) / B < grid ? (v + 1) / B : grid - 1;
}

static void fold(float *mm, float lo, float hi)
{
    if (lo < mm[0]) mm[0] = lo;
    if (hi > mm[1]) mm[1] = hi;
}

/* Folds the slice's per-brick row (b->slice) into the layers slice z touches. */
static void fold_slice(vxl_index_build *b, uint32_t z)
{
    uint32_t z0, z1;
    bricks_holding(z, b->brick, b->grid[2], &z0, &z1);
    const size_t layer = (size_t)b->grid[0] * b->grid[1];
    for (uint32_t bz = z0; bz <= z1; bz++) {
        float *dst = b->minmax + 2 * layer * bz;
        for (size_t i = 0; i < layer; i++) fold(dst + 2 * i, b->slice[2 * i], b->slice[2 * i + 1]);
    }
}

/* Min and max of texels [x0, x1] of a row, as the float the index stores
 * (integer codes through code / (2^bits - 1) in double, as vxl_unorm_value). */
static void run_range(uint32_t bits, const void *row, uint32_t x0, uint32_t x1, float *lo, float *hi)
{
    if (bits == 8) {
        const uint8_t *t = row;
        uint8_t a = t[x0], c = t[x0];
        for (uint32_t x = x0 + 1; x <= x1; x++) { a = t[x] < a ? t[x] : a; c = t[x] > c ? t[x] : c; }
        *lo = (float)(a / 255.0);
        *hi = (float)(c / 255.0);
    } else if (bits == 16) {
        const uint16_t *t = row;
        uint16_t a = t[x0], c = t[x0];
        for (uint32_t x = x0 + 1; x <= x1; x++) { a = t[x] < a ? t[x] : a; c = t[x] > c ? t[x] : c; }
        *lo = (float)(a / 65535.0);
        *hi = (float)(c / 65535.0);
    } else {
        const float *t = row;
        float a = t[x0], c = t[x0];
        for (uint32_t x = x0 + 1; x <= x1; x++) { a = t[x] < a ? t[x] : a; c = t[x] > c ? t[x] : c; }
        *lo = a;
        *hi = c;
    }
}

void vxl_index_build_slice_rows(vxl_index_build *b, uint32_t z, const void *texels, const uint8_t *data,
                                double value)
{
    const uint32_t B = b->brick, gx = b->grid[0], w = b->dims[0];
    const size_t layer = (size_t)gx * b->grid[1], bpv = b->texture_bits / 8;
    for (size_t i = 0; i < layer; i++) {
        b->slice[2 * i] = 1e30f;
        b->slice[2 * i + 1] = -1e30f;
    }
    const float v = (float)value;
    for (uint32_t y = 0; y < b->dims[1]; y++) {
        const uint8_t *row = (const uint8_t *)texels + (size_t)w * y * bpv;
        uint32_t y0, y1;
        bricks_holding(y, B, b->grid[1], &y0, &y1);
        for (uint32_t bx = 0; bx < gx; bx++) {
            const uint32_t x0 = bx * B > 0 ? bx * B - 1 : 0, x1 = bx * B + B < w ? bx * B + B : w - 1;
            float lo = v, hi = v;
            if (!data || data[y]) run_range(b->texture_bits, row, x0, x1, &lo, &hi);
            for (uint32_t by = y0; by <= y1; by++) fold(b->slice + 2 * (bx + (size_t)gx * by), lo, hi);
        }
    }
    fold_slice(b, z);
}

void vxl_index_build_slice(vxl_index_build *b, uint32_t z, const void *texels)
{
    vxl_index_build_slice_rows(b, z, texels, NULL, 0);
}

void vxl_index_build_const(vxl_index_build *b, uint32_t z, double value)
{
    const size_t layer = (size_t)b->grid[0] * b->grid[1];
    for (size_t i = 0; i < layer; i++) b->slice[2 * i] = b->slice[2 * i + 1] = (float)value;
    fold_slice(b, z);
}

void vxl_index_build_finish(vxl_index_build *b, vxl_brick_source *s)
{
    free(s->minmax);
    s->index_brick = b->brick;
    memcpy(s->index_dims, b->grid, sizeof s->index_dims);
    s->minmax = b->minmax;
    s->resident_bytes += (uint64_t)b->grid[0] * b->grid[1] * b->grid[2] * 2 * sizeof(float);
    b->minmax = NULL;
    vxl_index_build_free(b);
}

void vxl_index_build_free(vxl_index_build *b)
{
    free(b->minmax);
    free(b->slice);
    b->minmax = b->slice = NULL;
}

int vxl_brick_source_build_index(vxl_brick_source *s, const vxl_load_options *opt, vxl_err *e)
{
    const uint32_t *d = s->level_dims[0];
    vxl_index_build b;
    int rc = vxl_index_build_begin(&b, d, s->texture_bits, vxl_source_index_brick(d), e);
    if (rc) return rc;
    const size_t slice = (size_t)d[0] * d[1] * (s->texture_bits / 8);
    void *buf = malloc(slice);
    if (!buf) rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for a slice of %ux%u voxels", d[0], d[1]);
    for (uint32_t z = 0; z < d[2] && !rc; z++) {
        const uint32_t lo[3] = {0, 0, z}, size[3] = {d[0], d[1], 1};
        rc = s->ops->read(s, 0, lo, size, buf, e);
        if (!rc) vxl_index_build_slice(&b, z, buf);
        if (!rc && (z % 16 == 15 || z + 1 == d[2])) rc = vxl_source_progress(opt, (z + 1.0) / d[2], "indexing bricks", e);
    }
    free(buf);
    if (rc) {
        vxl_index_build_free(&b);
        return rc;
    }
    vxl_index_build_finish(&b, s);
    return VXL_OK;
}
