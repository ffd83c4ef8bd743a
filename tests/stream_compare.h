/* stream_compare.h - checks that a streamed volume (a brick source) tells
 * and reads exactly what the same file read whole does: info, value
 * mapping, every level whole and in boxes, the brick index, the histogram.
 * Shared by the tests of the raw source (test_brick_source.c) and of TIFF
 * streaming (test_tiff_stream.c). */
#ifndef VXL_STREAM_COMPARE_H
#define VXL_STREAM_COMPARE_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "voxlight_dev.h"

static uint32_t level_dim(uint32_t d, uint32_t k)
{
    for (uint32_t i = 0; i < k; i++) d = (d + 1) / 2;
    return d;
}

/* Every level whole, then boxes at the edges and inside, equal byte for byte. */
static int same_levels(vxl_test_ctx *T_, const vxl_volume *whole, const vxl_volume *streamed, uint32_t levels)
{
    const size_t bpv = whole->texture_bits / 8;
    int bad = 0;
    for (uint32_t k = 0; k < levels; k++) {
        uint32_t d[3];
        for (int a = 0; a < 3; a++) d[a] = level_dim(whole->dims[a], k);
        const uint32_t zero[3] = {0, 0, 0};
        const size_t n = (size_t)d[0] * d[1] * d[2] * bpv;
        uint8_t *a = malloc(n), *b = malloc(n);
        if (!a || !b) { free(a); free(b); return 1; }
        CHECK(vxl_volume_read_level(whole, k, zero, d, a) == VXL_OK);
        memset(b, 0xAB, n);
        CHECK(vxl_volume_read_level(streamed, k, zero, d, b) == VXL_OK);
        CHECKF(memcmp(a, b, n) == 0, "level %u differs (%ux%ux%u, %u bits)", k, d[0], d[1], d[2],
               whole->texture_bits);
        bad |= memcmp(a, b, n) != 0;
        /* boxes: the far corner, a one-voxel box, an inner box of odd size,
         * and whole rows (a source may read those as one run) */
        const uint32_t boxes[4][6] = {{d[0] > 3 ? d[0] - 3 : 0, d[1] > 2 ? d[1] - 2 : 0, d[2] > 1 ? d[2] - 1 : 0, 0, 0, 0},
                                      {d[0] / 2, d[1] / 3, d[2] - 1, 1, 1, 1},
                                      {d[0] / 4, d[1] / 4, d[2] / 4, 0, 0, 0},
                                      {0, d[1] / 3, 0, d[0], (d[1] + 1) / 2, d[2]}};
        for (int bi = 0; bi < 4; bi++) {
            uint32_t lo[3], size[3];
            for (int ax = 0; ax < 3; ax++) {
                lo[ax] = boxes[bi][ax];
                size[ax] = boxes[bi][3 + ax] ? boxes[bi][3 + ax] : (d[ax] - lo[ax] + 1) / 2 + (bi == 0 ? d[ax] - lo[ax] : 0);
                if (size[ax] > d[ax] - lo[ax]) size[ax] = d[ax] - lo[ax];
            }
            uint8_t *box = malloc((size_t)size[0] * size[1] * size[2] * bpv);
            if (!box) continue;
            CHECK(vxl_volume_read_level(streamed, k, lo, size, box) == VXL_OK);
            int same = 1;
            for (uint32_t z = 0; z < size[2]; z++)
                for (uint32_t y = 0; y < size[1]; y++)
                    same &= !memcmp(box + bpv * (size_t)size[0] * (y + (size_t)size[1] * z),
                                    a + bpv * (lo[0] + (size_t)d[0] * (lo[1] + y + (size_t)d[1] * (lo[2] + z))),
                                    bpv * size[0]);
            CHECKF(same, "level %u box %d (%u,%u,%u)+(%u,%u,%u) differs", k, bi, lo[0], lo[1], lo[2], size[0], size[1],
                   size[2]);
            free(box);
        }
        free(a);
        free(b);
    }
    return bad;
}

/* The source's index equals vxl_bricks_minmax_cpu on the whole volume, float for float. */
static void same_index(vxl_test_ctx *T_, const vxl_volume *whole, const vxl_volume *streamed)
{
    uint32_t brick = 0, sd[3], wd[3];
    REQUIRE(vxl_volume_brick_index(streamed, &brick, sd, NULL, 0) == VXL_OK);
    REQUIRE(brick >= 8);
    const size_t n = (size_t)sd[0] * sd[1] * sd[2] * 2;
    float *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    REQUIRE(a && b);
    uint32_t wb = brick;
    CHECK(vxl_volume_brick_index(streamed, &brick, sd, a, n) == VXL_OK);
    CHECK(vxl_volume_brick_index(whole, &wb, wd, b, n) == VXL_OK);
    CHECK(!memcmp(sd, wd, sizeof sd));
    CHECKF(!memcmp(a, b, n * sizeof *a), "index differs from vxl_bricks_minmax_cpu (brick %u)", brick);
    free(a);
    free(b);
}

static void info_of(const vxl_volume *v, vxl_volume_info *i)
{
    memset(i, 0, sizeof *i);
    i->struct_size = sizeof *i;
    vxl_volume_get_info(v, i);
}

/* Everything a streamed volume tells equals the whole load's: info, value
 * mapping, every level, the index, the histogram. */
static void same_volume(vxl_test_ctx *T_, const vxl_volume *whole, const vxl_volume *streamed, const char *what)
{
    vxl_volume_info wi, si;
    info_of(whole, &wi);
    info_of(streamed, &si);
    CHECKF(si.streamed == 1 && wi.streamed == 0, "%s: streamed %u/%u", what, si.streamed, wi.streamed);
    CHECKF(si.value_min == wi.value_min && si.value_max == wi.value_max, "%s: range %g..%g vs %g..%g", what,
           si.value_min, si.value_max, wi.value_min, wi.value_max);
    CHECKF(si.nan_count == wi.nan_count && si.inf_count == wi.inf_count, "%s: nan/inf %llu/%llu vs %llu/%llu", what,
           (unsigned long long)si.nan_count, (unsigned long long)si.inf_count, (unsigned long long)wi.nan_count,
           (unsigned long long)wi.inf_count);
    CHECKF(streamed->tex_lo == whole->tex_lo && streamed->tex_hi == whole->tex_hi, "%s: texture mapping", what);
    CHECK(si.storage_bytes == wi.storage_bytes && si.texture_bits == wi.texture_bits && si.dtype == wi.dtype);
    CHECK(!memcmp(si.dims, wi.dims, sizeof si.dims) && !memcmp(si.affine, wi.affine, sizeof si.affine));
    CHECKF(!memcmp(si.spacing, wi.spacing, sizeof si.spacing), "%s: spacing", what);
    CHECK(si.affine_source == wi.affine_source && si.nifti_version == wi.nifti_version);
    CHECKF(!same_levels(T_, whole, streamed, si.level_count), "%s: levels differ", what);
    same_index(T_, whole, streamed);
    uint64_t hw[64], hs[64];
    const double lo = wi.value_min, hi = wi.value_max > wi.value_min ? wi.value_max : wi.value_min + 1;
    CHECK(vxl_volume_histogram(whole, 64, lo, hi, hw) == VXL_OK);
    CHECK(vxl_volume_histogram(streamed, 64, lo, hi, hs) == VXL_OK);
    CHECKF(!memcmp(hw, hs, sizeof hw), "%s: histograms differ", what);
}

#endif
