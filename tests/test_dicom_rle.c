/* test_dicom_rle.c - io/dicom_rle.c on frames built here byte by byte from
 * PS3.5 Annex G (literal and replicate runs, the -128 no-op, a segment
 * padded to even length, two segments making 16-bit pixels) and on broken
 * ones, each a clear refusal. Whole series against dcmtk's encoder:
 * tests/test_dicom.c. Built for Windows too: the decoder is our C alone. */
#include <stdint.h>
#include <string.h>

#include "dicom_rle.h"
#include "harness.h"

/* A frame: the header for `count` segments at offsets[], then body. */
static size_t frame(uint8_t *out, uint32_t count, const uint32_t *offsets, const uint8_t *body, size_t n)
{
    memset(out, 0, 64);
    out[0] = (uint8_t)count;
    for (uint32_t s = 0; s < count; s++)
        for (int b = 0; b < 4; b++) out[4 + 4 * s + b] = (uint8_t)(offsets[s] >> (8 * b));
    memcpy(out + 64, body, n);
    return 64 + n;
}

TEST(literal_replicate_and_noop_runs_of_one_byte_pixels)
{
    /* 2 x 4 pixels: literal 3 (1 2 3), no-op, replicate 4 x 9, literal 1 (7), then a pad byte */
    const uint8_t body[] = {2, 1, 2, 3, 0x80, (uint8_t)-3, 9, 0, 7, 0};
    const uint32_t off[1] = {64};
    uint8_t f[128], px[8];
    const size_t n = frame(f, 1, off, body, sizeof body);
    char why[200] = "";
    REQUIRE(vxl_dicom_rle_decode(f, n, 2, 4, 1, px, why, sizeof why) == 0);
    const uint8_t want[8] = {1, 2, 3, 9, 9, 9, 9, 7};
    CHECK(!memcmp(px, want, 8));
}

TEST(two_segments_make_sixteen_bit_pixels_high_byte_first)
{
    /* high bytes 0x12 0x12 0x80, low bytes 0x34 0xff 0x00 */
    const uint8_t body[] = {(uint8_t)-1, 0x12, 0, 0x80, 2, 0x34, 0xff, 0x00};
    const uint32_t off[2] = {64, 68};
    uint8_t f[128];
    uint16_t px[3];
    const size_t n = frame(f, 2, off, body, sizeof body);
    char why[200] = "";
    REQUIRE(vxl_dicom_rle_decode(f, n, 1, 3, 2, px, why, sizeof why) == 0);
    CHECK(px[0] == 0x1234 && px[1] == 0x12ff && px[2] == 0x8000);
}

/* decode fails with why holding `says`. */
static int refused(const uint8_t *f, size_t n, uint32_t rows, uint32_t cols, uint32_t bytes, const char *says)
{
    uint16_t px[64];
    char why[200] = "";
    return vxl_dicom_rle_decode(f, n, rows, cols, bytes, px, why, sizeof why) == -1 && strstr(why, says) != NULL;
}

TEST(broken_frames_are_refused_with_a_reason)
{
    const uint8_t body[] = {3, 1, 2, 3, 4};
    uint32_t off[2] = {64, 64};
    uint8_t f[128];
    size_t n = frame(f, 1, off, body, sizeof body);
    CHECK(refused(f, 40, 1, 4, 1, "shorter than its 64-byte header"));
    CHECK(refused(f, n, 1, 4, 2, "1 segments, expected 2"));
    CHECK(refused(f, n, 1, 4, 3, "3-byte pixels"));
    CHECK(refused(f, n, 1, 8, 1, "does not decode to 8 bytes")); /* the segment ends early */
    CHECK(refused(f, n, 1, 2, 1, "does not decode to 2 bytes")); /* a run past the frame's pixels */
    off[0] = 200;
    n = frame(f, 1, off, body, sizeof body);
    CHECK(refused(f, n, 1, 4, 1, "outside its frame"));
    off[0] = 10;
    n = frame(f, 1, off, body, sizeof body);
    CHECK(refused(f, n, 1, 4, 1, "outside its frame")); /* inside the header */
    const uint8_t cut[] = {(uint8_t)-5};                 /* a replicate run without its byte */
    off[0] = 64;
    n = frame(f, 1, off, cut, sizeof cut);
    CHECK(refused(f, n, 1, 6, 1, "does not decode"));
}

int main(void)
{
    RUN(literal_replicate_and_noop_runs_of_one_byte_pixels);
    RUN(two_segments_make_sixteen_bit_pixels_high_byte_first);
    RUN(broken_frames_are_refused_with_a_reason);
    return TEST_SUMMARY();
}
