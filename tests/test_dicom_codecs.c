/* test_dicom_codecs.c - the DICOM codecs written in our own C, alone:
 * io/dicom_rle.c on frames built here byte by byte from PS3.5 Annex G
 * (literal and replicate runs, the -128 no-op, a segment padded to even
 * length, two segments making 16-bit pixels) and broken ones;
 * io/dicom_jpeg_lossless.c on a frame dcmtk's encoder wrote (kept here as
 * bytes) and damaged copies of it. Each refusal has a reason. Whole series
 * against dcmtk's encoders: tests/test_dicom.c. Built for Windows too: the
 * decoders are our C alone. */
#include <stdint.h>
#include <string.h>

#include "dicom_jpeg_lossless.h"
#include "dicom_rle.h"
#include "harness.h"
#include "voxlight.h"

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
    vxl_err e = {0};
    REQUIRE(vxl_dicom_rle_decode(f, n, 2, 4, 1, px, &e) == VXL_OK);
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
    vxl_err e = {0};
    REQUIRE(vxl_dicom_rle_decode(f, n, 1, 3, 2, px, &e) == VXL_OK);
    CHECK(px[0] == 0x1234 && px[1] == 0x12ff && px[2] == 0x8000);
}

/* decode fails as a format error whose message holds `says`. */
static int refused(const uint8_t *f, size_t n, uint32_t rows, uint32_t cols, uint32_t bytes, const char *says)
{
    uint16_t px[64];
    vxl_err e = {0};
    return vxl_dicom_rle_decode(f, n, rows, cols, bytes, px, &e) == VXL_ERR_FORMAT && strstr(e.msg, says) != NULL;
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

/* A 16 x 12 frame of 16-bit samples x * 900 + y * 400, as `dcmcjpeg +el
 * +sv 4` (dcmtk 3.6.7, predictor 4: Ra + Rb - Rc) encoded it, its one
 * fragment (tests/fuzz/jpeg_seeds.py writes the same). */
static const uint8_t jpeg_sv4[] = {
    0xff, 0xd8, 0xff, 0xe0, 0x00, 0x10, 0x4a, 0x46, 0x49, 0x46, 0x00, 0x01, 0x01, 0x00, 0x00, 0x01,
    0x00, 0x01, 0x00, 0x00, 0xff, 0xc3, 0x00, 0x0b, 0x10, 0x00, 0x0c, 0x00, 0x10, 0x01, 0x01, 0x11,
    0x00, 0xff, 0xc4, 0x00, 0x17, 0x00, 0x01, 0x01, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x0a, 0x09, 0x10, 0xff, 0xda, 0x00, 0x08, 0x01, 0x01,
    0x00, 0x04, 0x00, 0x00, 0xeb, 0x84, 0xb8, 0x4b, 0x84, 0xb8, 0x4b, 0x84, 0xb8, 0x4b, 0x84, 0xb8,
    0x4b, 0x84, 0xb8, 0x4b, 0x84, 0xb8, 0x4b, 0x84, 0xb8, 0x4b, 0x84, 0xd9, 0x00, 0x00, 0x1b, 0x20,
    0x00, 0x03, 0x64, 0x00, 0x00, 0x6c, 0x80, 0x00, 0x0d, 0x90, 0x00, 0x01, 0xb2, 0x00, 0x00, 0x36,
    0x40, 0x00, 0x06, 0xc8, 0x00, 0x00, 0xd9, 0x00, 0x00, 0x1b, 0x20, 0x00, 0x03, 0x64, 0x00, 0x00,
    0x7f, 0xff, 0xff, 0xd9,
};

TEST(lossless_jpeg_from_dcmtk_decodes_exactly)
{
    uint16_t px[12 * 16];
    vxl_err e = {0};
    REQUIRE(vxl_jpeg_lossless_decode(jpeg_sv4, sizeof jpeg_sv4, 12, 16, 2, px, &e) == VXL_OK);
    int wrong = 0;
    for (int y = 0; y < 12; y++)
        for (int x = 0; x < 16; x++) wrong += px[x + 16 * y] != x * 900 + y * 400;
    CHECKF(wrong == 0, "%d of 192 samples differ", wrong);
}

/* decode of a changed copy fails as a format error whose message holds `says`. */
static int jpeg_refused(const uint8_t *f, size_t n, uint32_t rows, uint32_t cols, const char *says)
{
    uint16_t px[12 * 16];
    vxl_err e = {0};
    return vxl_jpeg_lossless_decode(f, n, rows, cols, 2, px, &e) == VXL_ERR_FORMAT && strstr(e.msg, says) != NULL;
}

TEST(damaged_lossless_jpeg_is_refused_with_a_reason)
{
    uint8_t f[sizeof jpeg_sv4];
    memcpy(f, jpeg_sv4, sizeof f);
    CHECK(jpeg_refused(f, sizeof f, 12, 17, "frame is 16x12, the file says 17x12"));
    CHECK(jpeg_refused(f, 1, 12, 16, "no SOI"));
    CHECK(jpeg_refused(f, 40, 12, 16, "runs past the data")); /* cut inside the Huffman table */
    size_t sos = 0;
    for (size_t i = 0; i + 1 < sizeof f && !sos; i++)
        if (f[i] == 0xFF && f[i + 1] == 0xDA) sos = i;
    REQUIRE(sos);
    CHECK(jpeg_refused(f, sos + 14 + 6, 12, 16, "data ends")); /* cut a few bytes into the scan */
    size_t sof = 0;
    for (size_t i = 0; i + 1 < sizeof f && !sof; i++)
        if (f[i] == 0xFF && f[i + 1] == 0xC3) sof = i;
    REQUIRE(sof);
    f[sof + 1] = 0xC1; /* extended sequential, a lossy process */
    CHECK(jpeg_refused(f, sizeof f, 12, 16, "not lossless"));
    f[sof + 1] = 0xC3;
    f[sof + 9] = 3; /* three components */
    CHECK(jpeg_refused(f, sizeof f, 12, 16, "3 components"));
}

int main(void)
{
    RUN(literal_replicate_and_noop_runs_of_one_byte_pixels);
    RUN(two_segments_make_sixteen_bit_pixels_high_byte_first);
    RUN(broken_frames_are_refused_with_a_reason);
    RUN(lossless_jpeg_from_dcmtk_decodes_exactly);
    RUN(damaged_lossless_jpeg_is_refused_with_a_reason);
    return TEST_SUMMARY();
}
