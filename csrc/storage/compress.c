/* compress.c - per-brick palette + 8-bit codes (see compress.h). */
#include "compress.h"

#include <stdlib.h>
#include <string.h>

#define LLOYD_ITERATIONS 8

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The brick's voxels as raw stored values (integers for 8/16-bit stores). */
static void raw_values(const vxl_pages *pg, const uint8_t *brick, uint32_t n, float *out)
{
    for (uint32_t i = 0; i < n; i++)
        out[i] = pg->bytes_per_voxel == 1   ? (float)brick[i]
                 : pg->bytes_per_voxel == 2 ? (float)((const uint16_t *)brick)[i]
                                            : ((const float *)brick)[i];
}

/* Nearest centre of value v among c[0..k) (ascending). */
static uint32_t nearest(const float *c, uint32_t k, float v)
{
    uint32_t lo = 0, hi = k - 1;
    while (lo < hi) { /* first centre whose upper boundary (midpoint to the next) is >= v */
        uint32_t mid = (lo + hi) / 2;
        if (v <= 0.5f * (c[mid] + c[mid + 1])) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

/* 256 centres for the distinct values d[0..m) (ascending, w[j] voxels
 * each, total n): weighted quantiles, then Lloyd iterations (each value to
 * its nearest centre, each centre to the mean of its values). Integer
 * stores keep integer centres, so the decoded cache (R8/R16) holds exactly
 * what the palette says. Returns the centres in use (ascending). */
static uint32_t fit_levels(const float *d, const uint32_t *w, uint32_t m, uint32_t n, int integer, float *c)
{
    const uint32_t k = VXL_PALETTE_SIZE;
    uint64_t seen = 0;
    for (uint32_t j = 0, i = 0; j < k; j++) {
        const uint64_t target = (uint64_t)(2 * j + 1) * n / (2 * k);
        while (i + 1 < m && seen + w[i] <= target) seen += w[i++];
        c[j] = d[i];
    }
    for (int it = 0; it < LLOYD_ITERATIONS; it++) {
        double sum[VXL_PALETTE_SIZE] = {0};
        uint64_t cnt[VXL_PALETTE_SIZE] = {0};
        uint32_t j = 0;
        for (uint32_t i = 0; i < m; i++) { /* d ascending: the nearest centre only moves up */
            while (j + 1 < k && d[i] > 0.5f * (c[j] + c[j + 1])) j++;
            sum[j] += (double)d[i] * w[i];
            cnt[j] += w[i];
        }
        for (j = 0; j < k; j++)
            if (cnt[j]) c[j] = integer ? (float)(int64_t)(sum[j] / cnt[j] + 0.5) : (float)(sum[j] / cnt[j]);
        qsort(c, k, sizeof *c, cmp_float);
    }
    uint32_t used = 1; /* drop duplicate centres so the binary search stays well defined */
    for (uint32_t j = 1; j < k; j++)
        if (c[j] != c[used - 1]) c[used++] = c[j];
    return used;
}

/* The brick's distinct values (ascending) and their counts: a histogram for
 * 8/16-bit stores (hist: 65536 zeroed counters, left zeroed), a sort for
 * float. Returns how many. */
static uint32_t distinct_values(const vxl_pages *pg, const float *v, uint32_t n, uint32_t *hist, float *d,
                                uint32_t *w)
{
    uint32_t m = 0;
    if (pg->bytes_per_voxel < 4) {
        uint32_t lo = 65535, hi = 0;
        for (uint32_t i = 0; i < n; i++) {
            const uint32_t b = (uint32_t)v[i];
            hist[b]++;
            lo = b < lo ? b : lo;
            hi = b > hi ? b : hi;
        }
        for (uint32_t b = lo; b <= hi; b++)
            if (hist[b]) {
                d[m] = (float)b;
                w[m++] = hist[b];
                hist[b] = 0;
            }
        return m;
    }
    memcpy(d, v, (size_t)n * sizeof *d);
    qsort(d, n, sizeof *d, cmp_float);
    for (uint32_t i = 0; i < n; i++) {
        if (m && d[i] == d[m - 1]) {
            w[m - 1]++;
            continue;
        }
        d[m] = d[i];
        w[m++] = 1;
    }
    return m;
}

int vxl_compress_pages(vxl_compressed *c, const vxl_pages *pg, vxl_err *e)
{
    memset(c, 0, sizeof *c);
    const uint32_t edge = vxl_page_edge(pg), n = edge * edge * edge;
    const float scale = pg->bytes_per_voxel == 1 ? 1.0f / 255 : pg->bytes_per_voxel == 2 ? 1.0f / 65535 : 1.0f;
    c->n = pg->n_data;
    c->voxels = n;
    c->palette = malloc((size_t)c->n * VXL_PALETTE_SIZE * sizeof *c->palette + 1);
    c->codes = malloc((size_t)c->n * n + 1);
    float *v = malloc((size_t)n * 2 * sizeof *v);
    uint32_t *w = malloc((size_t)n * sizeof *w), *hist = calloc(65536, sizeof *hist);
    if (!c->palette || !c->codes || !v || !w || !hist) {
        free(v);
        free(w);
        free(hist);
        vxl_compressed_free(c);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for %u compressed bricks", pg->n_data);
    }
    float *d = v + n, levels[VXL_PALETTE_SIZE];
    for (uint32_t k = 0; k < c->n; k++) {
        raw_values(pg, pg->data + (size_t)k * n * pg->bytes_per_voxel, n, v);
        uint32_t m = distinct_values(pg, v, n, hist, d, w);
        if (m <= VXL_PALETTE_SIZE) { /* exact: the brick's own values */
            memcpy(levels, d, m * sizeof *levels);
            c->exact++;
        } else {
            m = fit_levels(d, w, m, n, pg->bytes_per_voxel < 4, levels);
        }
        float *pal = c->palette + (size_t)k * VXL_PALETTE_SIZE;
        for (uint32_t j = 0; j < VXL_PALETTE_SIZE; j++) pal[j] = levels[j < m ? j : m - 1] * scale;
        uint8_t *code = c->codes + (size_t)k * n;
        for (uint32_t i = 0; i < n; i++) code[i] = (uint8_t)nearest(levels, m, v[i]);
    }
    free(v);
    free(w);
    free(hist);
    return VXL_OK;
}

void vxl_compressed_free(vxl_compressed *c)
{
    free(c->palette);
    free(c->codes);
    memset(c, 0, sizeof *c);
}
