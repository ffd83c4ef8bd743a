/* paging.c - cuts a CPU volume into page bricks with ghost borders, finds
 * the constant ones, and decides which bricks a classification needs. */
#include "paging.h"

#include <stdlib.h>
#include <string.h>

static uint32_t clampi(int64_t i, uint32_t n) { return i < 0 ? 0 : i >= (int64_t)n ? n - 1 : (uint32_t)i; }

/* Range of n consecutive stored values from index i, in typed loops: this
 * runs over every voxel of volumes of billions. */
static void row_range(const void *texels, uint32_t bits, size_t i, uint32_t n, double *lo, double *hi)
{
    double mn = *lo, mx = *hi;
    if (bits == 8) {
        const uint8_t *t = (const uint8_t *)texels + i;
        uint8_t a = t[0], b = t[0];
        for (uint32_t k = 1; k < n; k++) { a = t[k] < a ? t[k] : a; b = t[k] > b ? t[k] : b; }
        mn = vxl_unorm_value(a, 8) < mn ? vxl_unorm_value(a, 8) : mn;
        mx = vxl_unorm_value(b, 8) > mx ? vxl_unorm_value(b, 8) : mx;
    } else if (bits == 16) {
        const uint16_t *t = (const uint16_t *)texels + i;
        uint16_t a = t[0], b = t[0];
        for (uint32_t k = 1; k < n; k++) { a = t[k] < a ? t[k] : a; b = t[k] > b ? t[k] : b; }
        mn = vxl_unorm_value(a, 16) < mn ? vxl_unorm_value(a, 16) : mn;
        mx = vxl_unorm_value(b, 16) > mx ? vxl_unorm_value(b, 16) : mx;
    } else {
        const float *t = (const float *)texels + i;
        float a = t[0], b = t[0];
        for (uint32_t k = 1; k < n; k++) { a = t[k] < a ? t[k] : a; b = t[k] > b ? t[k] : b; }
        mn = a < mn ? a : mn;
        mx = b > mx ? b : mx;
    }
    *lo = mn;
    *hi = mx;
}

void vxl_pages_copy_brick(const void *texels, const uint32_t dims[3], uint32_t bytes_per_voxel, uint32_t brick,
                          const uint32_t b[3], uint8_t *dst)
{
    const uint32_t e = brick + 2 * VXL_PAGE_GHOST, bpv = bytes_per_voxel;
    const uint8_t *src = texels;
    const int64_t x0 = (int64_t)b[0] * brick - VXL_PAGE_GHOST;
    /* the run of x inside the volume, copied in one go */
    const uint32_t in0 = clampi(x0, dims[0]), in1 = clampi(x0 + e - 1, dims[0]);
    const uint32_t pre = (uint32_t)((int64_t)in0 - x0), run = in1 - in0 + 1;
    for (uint32_t z = 0; z < e; z++) {
        uint32_t vz = clampi((int64_t)b[2] * brick + z - VXL_PAGE_GHOST, dims[2]);
        for (uint32_t y = 0; y < e; y++, dst += (size_t)e * bpv) {
            uint32_t vy = clampi((int64_t)b[1] * brick + y - VXL_PAGE_GHOST, dims[1]);
            size_t row = (size_t)dims[0] * (vy + (size_t)dims[1] * vz);
            for (uint32_t x = 0; x < pre; x++) memcpy(dst + (size_t)x * bpv, src + (row + in0) * bpv, bpv);
            memcpy(dst + (size_t)pre * bpv, src + (row + in0) * bpv, (size_t)run * bpv);
            for (uint32_t x = pre + run; x < e; x++) memcpy(dst + (size_t)x * bpv, src + (row + in1) * bpv, bpv);
        }
    }
}

/* Brick b of v with its ghost into dst, and the range of what was copied
 * (the clamped copies repeat values of the volume, so it is the range of
 * the voxels the brick's samples read). */
static void gather(const vxl_volume *v, const vxl_pages *pg, const uint32_t b[3], uint8_t *dst, double *lo,
                   double *hi)
{
    const uint32_t e = vxl_page_edge(pg);
    vxl_pages_copy_brick(v->texels, v->dims, pg->bytes_per_voxel, pg->brick, b, dst);
    *lo = 1e300;
    *hi = -1e300;
    for (uint32_t r = 0; r < e * e; r++) row_range(dst, v->texture_bits, (size_t)r * e, e, lo, hi);
}

int vxl_pages_build(vxl_pages *pg, const vxl_volume *v, uint32_t brick, vxl_err *e)
{
    memset(pg, 0, sizeof *pg);
    if (brick != 8 && brick != 16 && brick != 32 && brick != 64)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "page brick %u: use 8, 16, 32 or 64 voxels", brick);
    pg->brick = brick;
    pg->bytes_per_voxel = v->texture_bits / 8;
    for (int a = 0; a < 3; a++) pg->grid[a] = (v->dims[a] + brick - 1) / brick;
    const uint64_t n = vxl_page_count(pg);
    const size_t brick_bytes = (size_t)vxl_page_edge(pg) * vxl_page_edge(pg) * vxl_page_edge(pg) * pg->bytes_per_voxel;
    pg->data_index = malloc(n * sizeof *pg->data_index);
    pg->low = malloc(n * sizeof *pg->low);
    uint8_t *scratch = malloc(brick_bytes);
    size_t cap = 0;
    int rc = VXL_OK;
    if (!pg->data_index || !pg->low || !scratch) rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the page table");
    for (uint64_t i = 0; i < n && !rc; i++) {
        const uint32_t b[3] = {(uint32_t)(i % pg->grid[0]), (uint32_t)(i / pg->grid[0] % pg->grid[1]),
                               (uint32_t)(i / ((uint64_t)pg->grid[0] * pg->grid[1]))};
        double lo, hi;
        gather(v, pg, b, scratch, &lo, &hi);
        pg->low[i] = (float)lo;
        if (lo == hi) { /* trilinear filtering of one value is that value */
            pg->data_index[i] = -1;
            continue;
        }
        if (pg->n_data == cap) { /* grows geometrically: sparse volumes never pay for the dense size */
            size_t ncap = cap ? 2 * cap : 64;
            uint8_t *d = realloc(pg->data, ncap * brick_bytes);
            if (!d) {
                rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for %zu bricks of %zu bytes", ncap, brick_bytes);
                break;
            }
            pg->data = d;
            cap = ncap;
        }
        memcpy(pg->data + (size_t)pg->n_data * brick_bytes, scratch, brick_bytes);
        pg->data_index[i] = (int32_t)pg->n_data++;
    }
    free(scratch);
    if (rc) vxl_pages_free(pg);
    return rc;
}

void vxl_pages_free(vxl_pages *pg)
{
    free(pg->data_index);
    free(pg->low);
    free(pg->data);
    memset(pg, 0, sizeof *pg);
}

int vxl_bricks_minmax_cpu(vxl_bricks *b, const vxl_volume *v, uint32_t size, vxl_err *e)
{
    b->size = size;
    for (int a = 0; a < 3; a++) b->dims[a] = (v->dims[a] + size - 1) / size;
    const size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    if (!(b->minmax = malloc(n * 2 * sizeof(float))))
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the brick grid");
    for (size_t i = 0; i < n; i++) {
        const uint32_t c[3] = {(uint32_t)(i % b->dims[0]), (uint32_t)(i / b->dims[0] % b->dims[1]),
                               (uint32_t)(i / ((size_t)b->dims[0] * b->dims[1]))};
        uint32_t lo[3], hi[3];
        for (int a = 0; a < 3; a++) { /* the brick plus a one-voxel apron, inside the volume */
            lo[a] = clampi((int64_t)c[a] * size - 1, v->dims[a]);
            hi[a] = clampi((int64_t)c[a] * size + size, v->dims[a]);
        }
        double mn = 1e300, mx = -1e300;
        for (uint32_t z = lo[2]; z <= hi[2]; z++)
            for (uint32_t y = lo[1]; y <= hi[1]; y++)
                row_range(v->texels, v->texture_bits, lo[0] + (size_t)v->dims[0] * (y + (size_t)v->dims[1] * z),
                          hi[0] - lo[0] + 1, &mn, &mx);
        b->minmax[2 * i] = (float)mn;
        b->minmax[2 * i + 1] = (float)mx;
    }
    return VXL_OK;
}

int vxl_pages_flat_around(const vxl_pages *pg, uint64_t i, uint32_t voxels)
{
    if (pg->data_index[i] >= 0) return 0;
    const int64_t k = (voxels + pg->brick - 1) / pg->brick; /* bricks that far reach `voxels` */
    const int64_t c[3] = {(int64_t)(i % pg->grid[0]), (int64_t)(i / pg->grid[0] % pg->grid[1]),
                          (int64_t)(i / ((uint64_t)pg->grid[0] * pg->grid[1]))};
    int64_t lo[3], hi[3];
    for (int a = 0; a < 3; a++) { /* beyond the volume its edge repeats, which the bricks inside hold */
        lo[a] = c[a] - k < 0 ? 0 : c[a] - k;
        hi[a] = c[a] + k >= pg->grid[a] ? pg->grid[a] - 1 : c[a] + k;
    }
    for (int64_t z = lo[2]; z <= hi[2]; z++)
        for (int64_t y = lo[1]; y <= hi[1]; y++)
            for (int64_t x = lo[0]; x <= hi[0]; x++) {
                size_t j = (size_t)x + pg->grid[0] * ((size_t)y + (size_t)pg->grid[1] * z);
                if (pg->data_index[j] >= 0 || pg->low[j] != pg->low[i]) return 0;
            }
    return 1;
}

/* Whether page brick c (of `scale` full-resolution voxels per voxel) widened
 * by reach_k of its own voxels overlaps an occupied skip brick. */
static int near_occupied(const vxl_pages *pg, const vxl_bricks *b, const uint32_t c[3], int64_t reach_k,
                         uint32_t scale)
{
    uint32_t lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        int64_t v0 = ((int64_t)c[a] * pg->brick - reach_k) * scale,
                v1 = ((int64_t)c[a] * pg->brick + pg->brick + reach_k) * scale - 1;
        lo[a] = clampi(v0 < 0 ? 0 : v0 / b->size, b->dims[a]);
        hi[a] = clampi(v1 / b->size, b->dims[a]);
    }
    for (uint32_t z = lo[2]; z <= hi[2]; z++)
        for (uint32_t y = lo[1]; y <= hi[1]; y++)
            for (uint32_t x = lo[0]; x <= hi[0]; x++)
                if (b->distance[x + (size_t)b->dims[0] * (y + (size_t)b->dims[1] * z)] == 0) return 1;
    return 0;
}

uint32_t vxl_pages_needed(const vxl_pages *pg, const vxl_bricks *b, uint32_t reach, uint32_t scale, int all,
                          const uint8_t *candidate, uint8_t *need)
{
    const uint64_t n = vxl_page_count(pg);
    /* a coarse trilinear footprint reaches one more coarse voxel */
    const int64_t reach_k = scale > 1 ? (reach + scale - 1) / scale + 1 : reach;
    uint32_t count = 0;
    for (uint64_t i = 0; i < n; i++) {
        const uint32_t c[3] = {(uint32_t)(i % pg->grid[0]), (uint32_t)(i / pg->grid[0] % pg->grid[1]),
                               (uint32_t)(i / ((uint64_t)pg->grid[0] * pg->grid[1]))};
        need[i] = (candidate ? candidate[i] : pg->data_index[i] >= 0) && (all || near_occupied(pg, b, c, reach_k, scale));
        count += need[i];
    }
    return count;
}

/* Normalised value of texel t of a store's texels. */
static float texel_value(const vxl_brick_store *s, size_t t)
{
    switch (s->bytes_per_voxel) {
    case 1: return s->texels[t] / 255.0f;
    case 2: return ((const uint16_t *)(const void *)s->texels)[t] / 65535.0f;
    default: return ((const float *)(const void *)s->texels)[t];
    }
}

void vxl_pages_gather(const vxl_pages *pg, const vxl_brick_store *s, const uint32_t dims[3], const int64_t lo[3],
                      const uint32_t size[3], float *out)
{
    const uint32_t e = s->edge, P = pg->brick;
    const size_t row = (size_t)s->slots[0] * e, slice = row * s->slots[1] * e;
    for (uint32_t z = 0; z < size[2]; z++) {
        const uint32_t gz = clampi(lo[2] + z, dims[2]), bz = gz / P, lz = gz - bz * P + VXL_PAGE_GHOST;
        for (uint32_t y = 0; y < size[1]; y++) {
            const uint32_t gy = clampi(lo[1] + y, dims[1]), by = gy / P, ly = gy - by * P + VXL_PAGE_GHOST;
            const size_t brow = pg->grid[0] * ((size_t)by + (size_t)pg->grid[1] * bz);
            for (uint32_t x = 0; x < size[0];) {
                /* a run of x inside one page brick */
                const uint32_t gx = clampi(lo[0] + x, dims[0]), bx = gx / P;
                uint32_t run = 1;
                if (lo[0] + x >= 0 && lo[0] + x < dims[0]) {
                    const uint32_t brick_end = (bx + 1) * P < dims[0] ? (bx + 1) * P : dims[0];
                    run = brick_end - gx;
                    run = run < size[0] - x ? run : size[0] - x;
                }
                const size_t bi = bx + brow;
                const int32_t d = pg->data_index[bi];
                if (d < 0) {
                    for (uint32_t k = 0; k < run; k++) out[x + k] = pg->low[bi];
                } else {
                    const size_t sx = d % s->slots[0], sy = d / s->slots[0] % s->slots[1], sz = d / ((size_t)s->slots[0] * s->slots[1]);
                    const size_t t = (sx * e + gx - bx * P + VXL_PAGE_GHOST) + row * (sy * e + ly) + slice * (sz * e + lz);
                    for (uint32_t k = 0; k < run; k++) out[x + k] = texel_value(s, t + k);
                }
                x += run;
            }
            out += size[0];
        }
    }
}
