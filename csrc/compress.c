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

/* 256 centres for sorted values s[0..n): quantiles, then Lloyd iterations
 * (each value to its nearest centre, each centre to the mean of its values).
 * Integer stores keep integer centres, so the decoded cache (R8/R16) holds
 * exactly what the palette says. Returns the centres in use (ascending). */
static uint32_t fit_levels(const float *s, uint32_t n, int integer, float *c)
{
    const uint32_t k = VXL_PALETTE_SIZE;
    for (uint32_t j = 0; j < k; j++) c[j] = s[(uint64_t)(2 * j + 1) * n / (2 * k)];
    for (int it = 0; it < LLOYD_ITERATIONS; it++) {
        double sum[VXL_PALETTE_SIZE] = {0};
        uint32_t cnt[VXL_PALETTE_SIZE] = {0};
        uint32_t j = 0;
        for (uint32_t i = 0; i < n; i++) { /* s ascending: the nearest centre only moves up */
            while (j + 1 < k && s[i] > 0.5f * (c[j] + c[j + 1])) j++;
            sum[j] += s[i];
            cnt[j]++;
        }
        for (j = 0; j < k; j++)
            if (cnt[j]) c[j] = integer ? (float)(int64_t)(sum[j] / cnt[j] + 0.5) : (float)(sum[j] / cnt[j]);
        qsort(c, k, sizeof *c, cmp_float);
    }
    uint32_t m = 1; /* drop duplicate centres so the binary search stays well defined */
    for (uint32_t j = 1; j < k; j++)
        if (c[j] != c[m - 1]) c[m++] = c[j];
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
    if (!c->palette || !c->codes || !v) {
        free(v);
        vxl_compressed_free(c);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for %u compressed bricks", pg->n_data);
    }
    float *s = v + n, levels[VXL_PALETTE_SIZE];
    for (uint32_t k = 0; k < c->n; k++) {
        raw_values(pg, pg->data + (size_t)k * n * pg->bytes_per_voxel, n, v);
        memcpy(s, v, (size_t)n * sizeof *s);
        qsort(s, n, sizeof *s, cmp_float);
        uint32_t distinct = 1;
        for (uint32_t i = 1; i < n && distinct <= VXL_PALETTE_SIZE; i++) distinct += s[i] != s[i - 1];
        uint32_t m;
        if (distinct <= VXL_PALETTE_SIZE) { /* exact: the brick's own values */
            m = 1;
            levels[0] = s[0];
            for (uint32_t i = 1; i < n; i++)
                if (s[i] != levels[m - 1]) levels[m++] = s[i];
            c->exact++;
        } else {
            m = fit_levels(s, n, pg->bytes_per_voxel < 4, levels);
        }
        float *pal = c->palette + (size_t)k * VXL_PALETTE_SIZE;
        for (uint32_t j = 0; j < VXL_PALETTE_SIZE; j++) pal[j] = levels[j < m ? j : m - 1] * scale;
        uint8_t *code = c->codes + (size_t)k * n;
        for (uint32_t i = 0; i < n; i++) code[i] = (uint8_t)nearest(levels, m, v[i]);
    }
    free(v);
    return VXL_OK;
}

void vxl_compressed_free(vxl_compressed *c)
{
    free(c->palette);
    free(c->codes);
    memset(c, 0, sizeof *c);
}
