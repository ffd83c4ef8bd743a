/* test_dicom_j2k.c - io/dicom_j2k.c (DICOM's JPEG 2000 frames through the
 * system's OpenJPEG) on images Debian's own encoder, opj_compress
 * (libopenjp2-tools, installed by ./build.sh), writes here at test time from
 * PGM, PPM and raw files of known patterns: lossless J2K and JP2 voxel for
 * voxel (8, 12 and 16 bits, unsigned and signed, grey and colour, one tile
 * and several), lossy within a measured bound and equal to opj_decompress'
 * own output, and cut, damaged and mis-sized frames refused with a reason.
 * No encoder is a failure, not a skip. Linux only: the encoder is a Debian
 * program (the Windows build compiles the decoder with the others). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dicom_j2k.h"
#include "harness.h"
#include "voxlight.h"

static char dir[64]; /* the test's own folder under /tmp */

/* dir/name into out. */
static const char *at(char *out, size_t size, const char *name)
{
    snprintf(out, size, "%s/%s", dir, name);
    return out;
}

/* Runs opj_compress (or opj_decompress) with args; 0 when it succeeded. */
static int opj(const char *tool, const char *args)
{
    char cmd[512];
    snprintf(cmd, sizeof cmd, "cd '%s' && %s %s >/dev/null 2>&1", dir, tool, args);
    return system(cmd);
}

static int write_file(const char *name, const void *p, size_t n)
{
    char path[128];
    FILE *f = fopen(at(path, sizeof path, name), "wb");
    if (!f) return -1;
    const int ok = fwrite(p, 1, n, f) == n;
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* The file's bytes (malloc'ed, *n its size), or NULL. */
static uint8_t *read_file(const char *name, size_t *n)
{
    char path[128];
    FILE *f = fopen(at(path, sizeof path, name), "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    const long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *p = size > 0 ? malloc((size_t)size) : NULL;
    if (p && fread(p, 1, (size_t)size, f) != (size_t)size) {
        free(p);
        p = NULL;
    }
    fclose(f);
    *n = p ? (size_t)size : 0;
    return p;
}

/* A binary PGM (samples 1) or PPM (3) of w x h values v[], maxval > 255
 * written as 16-bit big-endian samples, as Netpbm has it. */
static int write_pnm(const char *name, const uint16_t *v, int w, int h, int samples, int maxval)
{
    const size_t count = (size_t)w * h * samples, bytes = maxval > 255 ? 2 : 1;
    uint8_t *buf = malloc(64 + count * bytes);
    if (!buf) return -1;
    size_t k = (size_t)sprintf((char *)buf, "P%c\n%d %d\n%d\n", samples == 3 ? '6' : '5', w, h, maxval);
    for (size_t i = 0; i < count; i++) {
        if (bytes == 2) buf[k++] = (uint8_t)(v[i] >> 8);
        buf[k++] = (uint8_t)v[i];
    }
    const int rc = write_file(name, buf, k);
    free(buf);
    return rc;
}

/* Decoded values of a frame (bytes per sample 1 or 2, signed or not) as ints. */
static int32_t sample(const void *px, size_t i, uint32_t bytes, int sgnd)
{
    if (bytes == 1) return sgnd ? ((const int8_t *)px)[i] : ((const uint8_t *)px)[i];
    return sgnd ? ((const int16_t *)px)[i] : ((const uint16_t *)px)[i];
}

/* Decodes file `name` as a rows x cols x samples frame and counts the
 * samples that differ from want[] (-1: it did not decode, with the reason
 * printed). */
static long decode_and_compare(const char *name, uint32_t rows, uint32_t cols, uint32_t bytes, uint32_t samples,
                               int sgnd, const int32_t *want)
{
    size_t n;
    uint8_t *f = read_file(name, &n);
    if (!f) {
        fprintf(stderr, "  %s was not written\n", name);
        return -1;
    }
    const size_t count = (size_t)rows * cols * samples;
    void *px = malloc(count * bytes);
    vxl_err e = {0};
    long wrong = -1;
    if (px && vxl_j2k_decode(f, n, rows, cols, bytes, samples, px, &e) == VXL_OK) {
        wrong = 0;
        for (size_t i = 0; i < count; i++) wrong += sample(px, i, bytes, sgnd) != want[i];
        if (wrong) fprintf(stderr, "  %s: %ld of %zu samples differ\n", name, wrong, count);
    } else {
        fprintf(stderr, "  %s: %s\n", name, e.msg);
    }
    free(px);
    free(f);
    return wrong;
}

/* A pattern with edges, ramps and the full range of `bits` (unsigned). */
static uint32_t pattern(int x, int y, int bits)
{
    const uint32_t top = (1u << bits) - 1;
    if (y == 0) return x & 1 ? top : 0; /* the extremes, side by side */
    return ((uint32_t)x * 2654435761u ^ (uint32_t)y * 40503u) % (top + 1) / ((x / 8 + y / 8) % 3 ? 1 : 7);
}

TEST(the_encoder_is_installed)
{
    /* build.sh installs libopenjp2-tools: without it the tests below would prove nothing */
    CHECKF(system("command -v opj_compress >/dev/null && command -v opj_decompress >/dev/null") == 0,
           "opj_compress/opj_decompress not found: install libopenjp2-tools (./build.sh does)");
}

/* Grey lossless frames of `bits` bits (PGM), as J2K and JP2, in one tile and in several. */
static int grey_lossless_exact(int w, int h, int bits)
{
    const size_t count = (size_t)w * h;
    uint16_t *v = malloc(count * sizeof *v);
    int32_t *want = malloc(count * sizeof *want);
    int bad = !v || !want;
    for (size_t i = 0; !bad && i < count; i++) want[i] = v[i] = (uint16_t)pattern((int)(i % w), (int)(i / w), bits);
    const uint32_t bytes = bits > 8 ? 2 : 1;
    if (!bad) bad = write_pnm("grey.pgm", v, w, h, 1, (1 << bits) - 1) != 0;
    if (!bad) bad = opj("opj_compress", "-i grey.pgm -o grey.j2k") || opj("opj_compress", "-i grey.pgm -o grey.jp2") ||
                    opj("opj_compress", "-i grey.pgm -o tiles.j2k -t 16,16 -n 4");
    if (!bad) bad = decode_and_compare("grey.j2k", h, w, bytes, 1, 0, want) != 0;
    if (!bad) bad = decode_and_compare("grey.jp2", h, w, bytes, 1, 0, want) != 0;
    if (!bad) bad = decode_and_compare("tiles.j2k", h, w, bytes, 1, 0, want) != 0;
    free(v);
    free(want);
    return !bad;
}

TEST(lossless_grey_8_12_and_16_bits_decode_exactly)
{
    CHECK(grey_lossless_exact(61, 47, 8)); /* odd sizes: no edge of a code block falls on the frame's */
    CHECK(grey_lossless_exact(64, 48, 12));
    CHECK(grey_lossless_exact(40, 72, 16));
}

/* Signed frames (raw little-endian input): negative values sign-extended. */
static int signed_lossless_exact(int w, int h, int bits)
{
    const size_t count = (size_t)w * h;
    const uint32_t bytes = bits > 8 ? 2 : 1;
    uint8_t *raw = malloc(count * bytes);
    int32_t *want = malloc(count * sizeof *want);
    int bad = !raw || !want;
    for (size_t i = 0; !bad && i < count; i++) {
        const int32_t half = 1 << (bits - 1);
        want[i] = (int32_t)pattern((int)(i % w), (int)(i / w), bits) - half;
        raw[i * bytes] = (uint8_t)want[i];
        if (bytes == 2) raw[i * bytes + 1] = (uint8_t)((uint32_t)want[i] >> 8);
    }
    char args[128];
    snprintf(args, sizeof args, "-i signed.rawl -o signed.j2k -F %d,%d,1,%d,s", w, h, bits);
    if (!bad) bad = write_file("signed.rawl", raw, count * bytes) || opj("opj_compress", args);
    if (!bad) bad = decode_and_compare("signed.j2k", h, w, bytes, 1, 1, want) != 0;
    free(raw);
    free(want);
    return !bad;
}

TEST(lossless_signed_frames_are_sign_extended)
{
    CHECK(signed_lossless_exact(64, 48, 16));
    CHECK(signed_lossless_exact(64, 48, 12)); /* a 12-bit sign bit in a 16-bit container */
    CHECK(signed_lossless_exact(33, 35, 8));
}

TEST(lossless_colour_decodes_exactly_as_three_interleaved_samples)
{
    const int w = 50, h = 34;
    const size_t count = (size_t)w * h * 3;
    uint16_t v[50 * 34 * 3];
    int32_t want[50 * 34 * 3];
    for (size_t i = 0; i < count; i++) {
        const int p = (int)(i / 3), c = (int)(i % 3);
        want[i] = v[i] = (uint16_t)((pattern(p % w, p / w, 8) + (uint32_t)c * 85 * (uint32_t)(p % 3)) & 255);
    }
    REQUIRE(write_pnm("rgb.ppm", v, w, h, 3, 255) == 0);
    /* opj_compress applies the reversible colour transform to three components: the decoder undoes it */
    REQUIRE(opj("opj_compress", "-i rgb.ppm -o rgb.j2k") == 0);
    REQUIRE(opj("opj_compress", "-i rgb.ppm -o rgb.jp2") == 0);
    CHECK(decode_and_compare("rgb.j2k", h, w, 1, 3, 0, want) == 0);
    CHECK(decode_and_compare("rgb.jp2", h, w, 1, 3, 0, want) == 0);
}

/* The next number of a PNM header from *at, skipping white space and
 * '#' comments (opj_decompress writes one); -1 when there is none. */
static long pnm_number(const uint8_t *f, size_t n, size_t *at)
{
    while (*at < n && (f[*at] == '#' || f[*at] == ' ' || f[*at] == '\n' || f[*at] == '\r' || f[*at] == '\t')) {
        if (f[*at] == '#')
            while (*at < n && f[*at] != '\n') ++*at;
        else
            ++*at;
    }
    long v = -1;
    for (; *at < n && f[*at] >= '0' && f[*at] <= '9' && v < 1000000; ++*at) v = (v < 0 ? 0 : v * 10) + (f[*at] - '0');
    return v;
}

/* The samples of an 8-bit PGM of w x h, or NULL (*file: what to free). */
static const uint8_t *pgm_samples(const char *name, int w, int h, uint8_t **file)
{
    size_t n, at = 2;
    uint8_t *f = read_file(name, &n);
    *file = f;
    if (!f || n < 2 || f[0] != 'P' || f[1] != '5') return NULL;
    const long fw = pnm_number(f, n, &at), fh = pnm_number(f, n, &at), maxval = pnm_number(f, n, &at);
    if (fw != w || fh != h || maxval != 255 || at + 1 + (size_t)w * h != n) return NULL;
    return f + at + 1;
}

TEST(lossy_is_opj_decompress_own_output_within_a_measured_bound)
{
    const int w = 128, h = 96;
    uint16_t v[128 * 96];
    uint32_t noise = 12345;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            noise = noise * 1103515245u + 12345u;
            /* a smooth scan-like field, an edge, and a little noise */
            const double f = 120 + 90 * sin(x / 9.0) * cos(y / 7.0) + (x > 80 ? 30 : 0) + (int)(noise >> 28) - 8;
            v[x + w * y] = (uint16_t)(f < 0 ? 0 : f > 255 ? 255 : f);
        }
    REQUIRE(write_pnm("lossy.pgm", v, w, h, 1, 255) == 0);
    REQUIRE(opj("opj_compress", "-i lossy.pgm -o lossy.j2k -r 20") == 0); /* 20:1, the 9/7 wavelet */
    REQUIRE(opj("opj_decompress", "-i lossy.j2k -o reference.pgm") == 0);
    size_t n;
    uint8_t *f = read_file("lossy.j2k", &n), *ref_file = NULL;
    const uint8_t *ref = pgm_samples("reference.pgm", w, h, &ref_file);
    uint8_t px[128 * 96];
    vxl_err e = {0};
    REQUIRE(f && ref);
    CHECK(n * 10 < (size_t)w * h); /* it is lossy: a tenth of the frame or less */
    REQUIRE(vxl_j2k_decode(f, n, h, w, 1, 1, px, &e) == VXL_OK);
    int max_err = 0, differ = 0;
    double se = 0;
    for (int i = 0; i < w * h; i++) {
        const int d = abs((int)px[i] - (int)v[i]);
        max_err = d > max_err ? d : max_err;
        se += (double)d * d;
        differ += px[i] != ref[i];
    }
    const double psnr = 10 * log10(255.0 * 255.0 / (se / (w * h)));
    fprintf(stderr, "  lossy 20:1, 8-bit %dx%d: max |error| %d, PSNR %.1f dB\n", w, h, max_err, psnr);
    /* the library's own tool is the reference: the same values, so the plumbing loses nothing */
    CHECKF(differ == 0, "%d samples differ from opj_decompress'", differ);
    /* measured with Debian 12's OpenJPEG 2.5.0: max 17, 34.6 dB. The bound
     * (twice the error, 3 dB less) leaves room for another build's rounding
     * yet fails a decoder that shifts, swaps or drops a sample or a tile */
    CHECKF(max_err <= 34 && psnr >= 31.5, "max %d, %.1f dB", max_err, psnr);
    free(f);
    free(ref_file);
}

/* decode fails with `code` and a message holding `says`. */
static int refused(const uint8_t *f, size_t n, uint32_t rows, uint32_t cols, uint32_t bytes, uint32_t samples,
                   const char *says)
{
    void *px = malloc((size_t)rows * cols * samples * 2 + 1);
    vxl_err e = {0};
    const int rc = vxl_j2k_decode(f, n, rows, cols, bytes, samples, px, &e);
    free(px);
    if (rc == VXL_ERR_FORMAT && strstr(e.msg, says)) return 1;
    fprintf(stderr, "  rc %d: %s (wanted \"%s\")\n", rc, e.msg, says);
    return 0;
}

TEST(frames_of_another_shape_are_refused_before_decoding)
{
    uint16_t v[64 * 48];
    for (int i = 0; i < 64 * 48; i++) v[i] = (uint16_t)pattern(i % 64, i / 64, 12);
    REQUIRE(write_pnm("shape.pgm", v, 64, 48, 1, 4095) == 0);
    REQUIRE(opj("opj_compress", "-i shape.pgm -o shape.j2k") == 0);
    size_t n;
    uint8_t *f = read_file("shape.j2k", &n);
    REQUIRE(f);
    CHECK(refused(f, n, 48, 65, 2, 1, "the frame is 65x48, the codestream says 64x48"));
    CHECK(refused(f, n, 4800, 6400, 2, 1, "the frame is 6400x4800")); /* no 60 MB allocated for it */
    CHECK(refused(f, n, 48, 64, 2, 3, "3 samples per pixel, the codestream has 1 components"));
    CHECK(refused(f, n, 48, 64, 1, 1, "12 bits, more than 1-byte samples hold"));
    CHECK(refused(f, n, 48, 64, 4, 1, "4-byte samples"));
    CHECK(refused(f + 1, n - 1, 48, 64, 2, 1, "neither a J2K codestream nor a JP2 file"));
    CHECK(refused(f, 0, 48, 64, 2, 1, "neither"));
    free(f);
}

TEST(cut_and_damaged_frames_are_refused_or_decoded_never_a_crash)
{
    uint16_t v[64 * 48];
    for (int i = 0; i < 64 * 48; i++) v[i] = (uint16_t)pattern(i % 64, i / 64, 16);
    REQUIRE(write_pnm("cut.pgm", v, 64, 48, 1, 65535) == 0);
    REQUIRE(opj("opj_compress", "-i cut.pgm -o cut.j2k") == 0);
    REQUIRE(opj("opj_compress", "-i cut.pgm -o cut.jp2") == 0);
    const char *files[2] = {"cut.j2k", "cut.jp2"};
    uint16_t px[64 * 48];
    for (int k = 0; k < 2; k++) {
        size_t n;
        uint8_t *f = read_file(files[k], &n);
        REQUIRE(f && n > 200);
        /* every cut short of the end marker is an error with OpenJPEG's reason (strict mode) */
        int accepted = 0, silent = 0;
        for (size_t cut = 0; cut + 2 < n; cut += cut < 300 ? 1 : 7) {
            uint8_t *c = malloc(cut ? cut : 1); /* its own block: ASan sees the exact end */
            REQUIRE(c);
            memcpy(c, f, cut);
            vxl_err e = {0};
            const int rc = vxl_j2k_decode(c, cut, 48, 64, 2, 1, px, &e);
            accepted += rc == VXL_OK;
            silent += rc != VXL_OK && (rc != VXL_ERR_FORMAT || !strstr(e.msg, "JPEG 2000 frame: "));
            free(c);
        }
        CHECKF(accepted == 0 && silent == 0, "%s: %d cut copies decoded, %d refused without a reason", files[k],
               accepted, silent);
        /* a byte changed anywhere: decoded (tile data has no checksum) or refused, never a crash */
        uint8_t *d = malloc(n);
        REQUIRE(d);
        int refusals = 0;
        for (size_t i = 0; i < n; i += i < 300 ? 1 : 5) { /* the headers, then a sample of the tile data */
            memcpy(d, f, n);
            d[i] ^= (uint8_t)(0x5A + i);
            vxl_err e = {0};
            const int rc = vxl_j2k_decode(d, n, 48, 64, 2, 1, px, &e);
            CHECK(rc == VXL_OK || (rc == VXL_ERR_FORMAT && e.msg[0]));
            refusals += rc != VXL_OK;
        }
        CHECK(refusals > 0); /* the header's bytes at least */
        free(d);
        free(f);
    }
}

/* Run as a child with VOXLIGHT_LIBOPENJP2 naming no library: the one line
 * the user gets. 0 when it is right. */
static int missing_library_child(void)
{
    static const uint8_t soc_siz[8] = {0xFF, 0x4F, 0xFF, 0x51, 0, 0, 0, 0};
    uint8_t px[4];
    vxl_err e = {0};
    const int rc = vxl_j2k_decode(soc_siz, sizeof soc_siz, 2, 2, 1, 1, px, &e);
    fprintf(stderr, "  without OpenJPEG: %s\n", e.msg);
    return rc == VXL_ERR_IO && strstr(e.msg, "JPEG 2000 needs OpenJPEG: install libopenjp2-7") ? 0 : 1;
}

TEST(a_missing_openjpeg_is_one_line_naming_the_package)
{
    char self[256], cmd[400];
    const ssize_t k = readlink("/proc/self/exe", self, sizeof self - 1);
    REQUIRE(k > 0);
    self[k] = 0;
    snprintf(cmd, sizeof cmd, "VOXLIGHT_LIBOPENJP2=libopenjp2-absent.so.7 '%s' --missing-library", self);
    CHECK(system(cmd) == 0);
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--missing-library")) return missing_library_child();
    snprintf(dir, sizeof dir, "/tmp/vxl_j2k_XXXXXX");
    if (!mkdtemp(dir)) return 1;
    RUN(the_encoder_is_installed);
    RUN(lossless_grey_8_12_and_16_bits_decode_exactly);
    RUN(lossless_signed_frames_are_sign_extended);
    RUN(lossless_colour_decodes_exactly_as_three_interleaved_samples);
    RUN(lossy_is_opj_decompress_own_output_within_a_measured_bound);
    RUN(frames_of_another_shape_are_refused_before_decoding);
    RUN(cut_and_damaged_frames_are_refused_or_decoded_never_a_crash);
    RUN(a_missing_openjpeg_is_one_line_naming_the_package);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "  %s was not removed\n", dir);
    return TEST_SUMMARY();
}
