/* test_channel_histogram.c - vxl_volume_channel_histogram (docs/channels.md):
 * each channel of a multi-channel volume counted over its own values in its
 * own data units, against counts made here from the raw values: 8- and
 * 16-bit channels exactly, a float channel (stored as 16 bits over its
 * range) on values that quantisation cannot move across a bin edge; the
 * scalar channel's counts equal the scalar's histogram; a volume without
 * channels, a channel it does not have and bad bins are refused. */
#include <string.h>

#include "harness.h"
#include "voxlight.h"

#define N 16
#define NV (N * N * N)

/* The rule of vxl_volume_histogram: bin floor((v - lo) bins / (hi - lo)),
 * hi itself in the last bin, values outside not counted. */
static void reference(const double *v, uint32_t n, uint32_t bins, double lo, double hi, uint64_t *counts)
{
    memset(counts, 0, bins * sizeof *counts);
    for (uint32_t i = 0; i < n; i++) {
        double b = (v[i] - lo) * bins / (hi - lo);
        if (b >= 0 && b <= bins) counts[b >= bins ? bins - 1 : (uint32_t)b]++;
    }
}

static vxl_volume *planar(const void *data, uint32_t dtype, uint32_t channels)
{
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = dtype, .dims = {N, N, N}, .data = data,
                         .channels = channels};
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, NULL, &v) == VXL_OK ? v : NULL;
}

static int same(const uint64_t *a, const uint64_t *b, uint32_t n)
{
    return memcmp(a, b, n * sizeof *a) == 0;
}

TEST(integer_channels_count_exactly)
{
    static uint16_t data[3 * NV];
    static double values[NV];
    for (uint32_t i = 0; i < NV; i++) {
        data[i] = (uint16_t)(i % 97);                  /* channel 0: 0..96 */
        data[NV + i] = (uint16_t)((i * 7919u) % 60000); /* channel 1: 0..59999 */
        data[2 * NV + i] = (uint16_t)(1000 + i % 5);    /* channel 2: 1000..1004 */
    }
    vxl_volume *v = planar(data, VXL_DTYPE_U16, 3);
    REQUIRE(v);
    vxl_volume_info info = {.struct_size = sizeof info};
    REQUIRE(vxl_volume_get_info(v, &info) == VXL_OK);
    uint64_t got[40], want[40];
    for (uint32_t c = 0; c < 3; c++) {
        for (uint32_t i = 0; i < NV; i++) values[i] = data[c * NV + i];
        const double lo = info.channel_min[c], hi = info.channel_max[c];
        CHECK(vxl_volume_channel_histogram(v, c, 40, lo, hi, got) == VXL_OK);
        reference(values, NV, 40, lo, hi, want);
        CHECKF(same(got, want, 40), "channel %u over its range", c);
        /* a narrower range: what lies outside is not counted */
        CHECK(vxl_volume_channel_histogram(v, c, 7, lo + (hi - lo) / 3, hi - (hi - lo) / 5, got) == VXL_OK);
        reference(values, NV, 7, lo + (hi - lo) / 3, hi - (hi - lo) / 5, want);
        CHECKF(same(got, want, 7), "channel %u over part of its range", c);
    }
    /* the scalar is channel 0: its histogram is channel 0's */
    CHECK(vxl_volume_histogram(v, 40, 0, 96, want) == VXL_OK);
    CHECK(vxl_volume_channel_histogram(v, 0, 40, 0, 96, got) == VXL_OK);
    CHECK(same(got, want, 40));
    vxl_volume_destroy(v);
}

TEST(a_float_channel_counts_in_its_data_units)
{
    static float data[2 * NV];
    static double values[NV];
    for (uint32_t i = 0; i < NV; i++) {
        data[i] = (float)(i % 3);
        values[i] = data[NV + i] = (float)(-10.0 + 5.0 * (i % 5)); /* -10, -5, 0, 5, 10 */
    }
    vxl_volume *v = planar(data, VXL_DTYPE_F32, 2);
    REQUIRE(v);
    uint64_t got[5], want[5];
    CHECK(vxl_volume_channel_histogram(v, 1, 5, -12.5, 12.5, got) == VXL_OK);
    reference(values, NV, 5, -12.5, 12.5, want);
    CHECK(same(got, want, 5));
    vxl_volume_destroy(v);
}

TEST(what_has_no_such_channel_is_refused)
{
    static uint8_t data[2 * NV];
    uint64_t counts[4];
    vxl_volume *one = NULL;
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U8, .dims = {N, N, N}, .data = data};
    REQUIRE(vxl_volume_create(&d, NULL, &one) == VXL_OK);
    CHECK(vxl_volume_channel_histogram(one, 0, 4, 0, 1, counts) == VXL_ERR_STATE);
    CHECK(strstr(vxl_last_error(), "not multi-channel") != NULL);
    vxl_volume_destroy(one);
    vxl_volume *two = planar(data, VXL_DTYPE_U8, 2);
    REQUIRE(two);
    CHECK(vxl_volume_channel_histogram(two, 2, 4, 0, 1, counts) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_last_error(), "channels 0..1") != NULL);
    CHECK(vxl_volume_channel_histogram(two, 0, 0, 0, 1, counts) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_volume_channel_histogram(two, 0, 4, 1, 1, counts) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_volume_channel_histogram(NULL, 0, 4, 0, 1, counts) == VXL_ERR_INVALID_ARGUMENT);
    vxl_volume_destroy(two);
}

int main(void)
{
    RUN(integer_channels_count_exactly);
    RUN(a_float_channel_counts_in_its_data_units);
    RUN(what_has_no_such_channel_is_refused);
    return TEST_SUMMARY();
}
