/* test_dicom_frames.c - the DICOM that hospitals send, through the public
 * API: enhanced multi-frame files (frames shuffled, per-frame and shared
 * functional groups, 4D) written by pydicom; classic multi-frame files; every
 * transfer syntax dcmtk's tools and pydicom's reference files give us
 * (implicit/explicit/big endian, deflated, RLE, JPEG Lossless, JPEG-LS
 * lossless and near-lossless, JPEG Baseline and Extended), colour among
 * them as colour volumes. Each encoding
 * must load voxel for voxel as the uncompressed volume, or within the
 * codec's own bound for the lossy ones. The writers (pydicom, dcmtk's
 * dcmcrle/dcmcjpeg/dcmcjpls/dcmconv) are independent of our decoders. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dicom_test_util.h"
#include "fuzz/dicom_writer.h"
#include "harness.h"

static char g_dir[64];
/* pydicom's own test files, installed with Debian's python3-pydicom (asked
 * of pydicom, so its version's layout does not matter) */
static char g_pydicom_files[512];

static int find_pydicom_files(void)
{
    FILE *p = popen("/usr/bin/python3 -c 'import os, pydicom.data; "
                    "print(os.path.join(os.path.dirname(pydicom.data.__file__), \"test_files\"))'", "r");
    if (!p) return -1;
    const int ok = fgets(g_pydicom_files, sizeof g_pydicom_files, p) != NULL;
    if (pclose(p) != 0 || !ok) return -1;
    g_pydicom_files[strcspn(g_pydicom_files, "\n")] = 0;
    return 0;
}

enum { C = 6, R = 5, K = 7, T = 3 };
static const double k_iop[6] = {0.8, 0.6, 0, 0, 0, -1}; /* oblique: coronal-ish, rotated */
static const double k_origin[3] = {-10, 20, 30};
static const double k_step[3] = {-1.2, 1.6, 0}; /* 2 mm along the normal (-0.6, 0.8, 0) */

/* Slice k of time point t as single-frame files, the classic way, with the
 * enhanced file's geometry and pixels (1000 t + 100 k + 10 j + i). */
static int write_reference(const char *dir, int t)
{
    for (int k = 0; k < K; k++) {
        uint16_t px[C * R];
        for (int j = 0; j < R; j++)
            for (int i = 0; i < C; i++) px[i + C * j] = (uint16_t)(1000 * t + 100 * k + 10 * j + i);
        dcmw_slice d = dcmw_axial("1.2.3.300", C, R, 0, px, sizeof px);
        memcpy(d.iop, k_iop, sizeof d.iop);
        for (int a = 0; a < 3; a++) d.ipp[a] = k_origin[a] + k * k_step[a];
        d.ps[0] = d.ps[1] = 1;
        d.has_rescale = 1;
        d.slope = 1;
        d.inter = -1024;
        d.instance = k;
        char p[512];
        snprintf(p, sizeof p, "%s/IM%04d.dcm", dir, k);
        if (dcmw_write(p, &d)) return -1;
    }
    return 0;
}

/* The enhanced file (tests/make_enhanced_dicom.py) at path; codec "",
 * "j2k" (frames from opj_compress), "htj2k" (pip's imagecodecs) or "rgb". */
static int write_enhanced(const char *path, int times, int seed, const char *codec)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd,
             "/usr/bin/python3 tests/make_enhanced_dicom.py %s %d %d %d %d %g %g %g %g %g %g %g %g %g %g %g %g %d %s",
             path, C, R, K, times, k_iop[0], k_iop[1], k_iop[2], k_iop[3], k_iop[4], k_iop[5], k_origin[0],
             k_origin[1], k_origin[2], k_step[0], k_step[1], k_step[2], seed, codec);
    return system(cmd) == 0 ? 0 : -1;
}

/* `tool IN OUT` (a dcmtk command line) into a fresh folder; its path in out. */
static int convert(const char *in, const char *name, const char *tool, char *out, size_t n)
{
    char dir[256], cmd[1400];
    dicom_folder(g_dir, dir, sizeof dir, name);
    snprintf(out, n, "%s/f.dcm", dir);
    snprintf(cmd, sizeof cmd, "%s %s %s", tool, in, out);
    return system(cmd) == 0 ? 0 : -1;
}

static int same_affine(const vxl_volume *a, const vxl_volume *b)
{
    for (int i = 0; i < 16; i++)
        if (fabs(a->affine[i] - b->affine[i]) > 1e-9) return 0;
    return 1;
}

/* An enhanced CT whose frames are stored shuffled loads in anatomical order
 * with the affine the same slices get as single-frame files; dcmtk's
 * encoders compress the multi-frame file (one or several fragments per
 * frame, with and without a basic offset table), OpenJPEG's and OpenJPH's
 * (JPEG 2000, HTJ2K) encode its frames, and it still loads the same. */
TEST(enhanced_frames_in_shuffled_order_come_out_in_anatomical_order)
{
    char ref_dir[256], dir[256], path[512];
    dicom_folder(g_dir, ref_dir, sizeof ref_dir, "reference");
    REQUIRE(write_reference(ref_dir, 0) == 0);
    vxl_volume *ref = load_dicom(ref_dir, NULL, 0);
    REQUIRE(ref);
    dicom_folder(g_dir, dir, sizeof dir, "enhanced");
    snprintf(path, sizeof path, "%s/enhanced.dcm", dir);
    REQUIRE(write_enhanced(path, 1, 7, "") == 0);
    vxl_volume *v = load_dicom(path, NULL, 0);
    CHECKF(v && same_volume(ref, v) && same_affine(ref, v), "%s", v ? "voxels or affine differ" : vxl_last_error());
    CHECK(v && v->dims[2] == K && fabs(v->spacing[2] - 2) < 1e-9 && v->value_min == -1024);
    vxl_volume_destroy(v);

    static const char *const encodings[][2] = {
        {"rle", "dcmcrle"},
        {"jpeg_sv1", "dcmcjpeg"},
        {"jpeg_fragments", "dcmcjpeg +fs 1"},         /* several fragments per frame, offset table */
        {"jpeg_no_table", "dcmcjpeg +fs 1 -ot"},      /* ... without the table: frames found by SOI */
        {"jpeg_ls", "dcmcjpls"},
        {"jpeg_ls_no_table", "dcmcjpls -ot"},         /* one fragment per frame, no table */
        {"big_endian", "dcmconv +tb"},
        {"deflated", "dcmconv +td"},
    };
    for (size_t e = 0; e < sizeof encodings / sizeof encodings[0]; e++) {
        char out[512];
        REQUIRE(convert(path, encodings[e][0], encodings[e][1], out, sizeof out) == 0);
        vxl_volume *c = load_dicom(out, NULL, 0);
        CHECKF(c && same_volume(ref, c) && same_affine(ref, c), "%s: %s", encodings[e][1],
               c ? "voxels or affine differ" : vxl_last_error());
        vxl_volume_destroy(c);
    }
    /* JPEG 2000 frames (OpenJPEG's own encoder), with a basic offset table */
    dicom_folder(g_dir, dir, sizeof dir, "enhanced_j2k");
    snprintf(path, sizeof path, "%s/j2k.dcm", dir);
    REQUIRE(write_enhanced(path, 1, 5, "j2k") == 0);
    v = load_dicom(path, NULL, 0);
    CHECKF(v && same_volume(ref, v) && same_affine(ref, v), "j2k: %s", v ? "voxels or affine differ" : vxl_last_error());
    vxl_volume_destroy(v);
    /* HTJ2K Lossless (.201; pip's imagecodecs encodes, OpenJPEG decodes):
     * dcmtk 3.6.7 does not know the syntax, the reader knows it by UID */
    dicom_folder(g_dir, dir, sizeof dir, "enhanced_htj2k");
    snprintf(path, sizeof path, "%s/htj2k.dcm", dir);
    REQUIRE(write_enhanced(path, 1, 3, "htj2k") == 0);
    v = load_dicom(path, NULL, 0);
    CHECKF(v && same_volume(ref, v) && same_affine(ref, v), "htj2k: %s",
           v ? "voxels or affine differ" : vxl_last_error());
    vxl_volume_destroy(v);
    vxl_volume_destroy(ref);
}

/* A damaged basic offset table (an entry that points inside a fragment) or
 * one whose count is not the frame count is one line naming the file. */
TEST(damaged_offset_tables_are_clear_errors)
{
    char dir[256], path[512], out[512];
    dicom_folder(g_dir, dir, sizeof dir, "table_source");
    snprintf(path, sizeof path, "%s/e.dcm", dir);
    REQUIRE(write_enhanced(path, 1, 3, "") == 0);
    REQUIRE(convert(path, "damaged_table", "dcmcjpeg +fs 1", out, sizeof out) == 0);
    size_t n = 0;
    unsigned char *f = read_all(out, &n);
    REQUIRE(f);
    /* PixelData (7FE0,0010) OB of undefined length, then the table's item */
    static const unsigned char pixel_data[12] = {0xE0, 0x7F, 0x10, 0x00, 'O', 'B', 0, 0, 0xFF, 0xFF, 0xFF, 0xFF};
    unsigned char *at = NULL;
    for (size_t i = 0; i + 12 + 8 + 4 * K <= n && !at; i++)
        if (!memcmp(f + i, pixel_data, 12)) at = f + i + 12;
    REQUIRE(at && at[0] == 0xFE && at[1] == 0xFF && at[2] == 0x00 && at[3] == 0xE0 && at[4] == 4 * K);
    unsigned char *entry1 = at + 8 + 4;
    REQUIRE(entry1[0] || entry1[1] || entry1[2]);
    entry1[0] = (unsigned char)(entry1[0] + 2); /* two bytes into a fragment */
    REQUIRE(write_all(out, f, n) == 0);
    free(f);
    CHECK(load_dicom(out, NULL, 0) == NULL);
    CHECKF(contains(vxl_last_error(), "f.dcm") && contains(vxl_last_error(), "basic offset table entry 1"), "%s",
           vxl_last_error());
}

/* Time points of an enhanced file (TemporalPositionIndex) become frames,
 * each the same as its single-frame series. */
TEST(enhanced_time_points_become_frames)
{
    char dir[256], path[512];
    dicom_folder(g_dir, dir, sizeof dir, "enhanced_4d");
    snprintf(path, sizeof path, "%s/e.dcm", dir);
    REQUIRE(write_enhanced(path, T, 11, "") == 0);
    for (int t = 0; t < T; t++) {
        char ref_dir[256], name[32];
        snprintf(name, sizeof name, "reference_t%d", t);
        dicom_folder(g_dir, ref_dir, sizeof ref_dir, name);
        REQUIRE(write_reference(ref_dir, t) == 0);
        vxl_volume *ref = load_dicom(ref_dir, NULL, 0);
        vxl_volume *v = load_dicom(path, NULL, (uint32_t)t);
        CHECKF(ref && v && same_volume(ref, v) && same_affine(ref, v), "time point %d: %s", t,
               v ? "voxels or affine differ" : vxl_last_error());
        CHECK(v && v->frame_count == T && v->frame == (uint32_t)t);
        vxl_volume_destroy(ref);
        vxl_volume_destroy(v);
    }
    vxl_dicom_series s = {.struct_size = sizeof s};
    uint32_t n = 0;
    CHECK(vxl_dicom_list_series(path, &s, 1, &n) == VXL_OK && n == 1 && s.loadable && s.dims[2] == K &&
          s.frame_count == T && s.slice_count == K * T);
}

/* One enhanced file holding two stacks: two series, each its own volume;
 * naming the file alone asks which. */
TEST(stacks_of_one_enhanced_file_are_series_of_their_own)
{
    char dir[256], path[512];
    dicom_folder(g_dir, dir, sizeof dir, "enhanced_stacks");
    snprintf(path, sizeof path, "%s/s.dcm", dir);
    REQUIRE(write_enhanced(path, 2, 13, "stacks") == 0);
    vxl_dicom_series s[2] = {{.struct_size = sizeof s[0]}};
    uint32_t n = 0;
    REQUIRE(vxl_dicom_list_series(path, s, 2, &n) == VXL_OK);
    CHECK(n == 2 && s[0].loadable && s[1].loadable && s[0].dims[2] == K && s[1].dims[2] == K &&
          contains(s[0].description, "(stack 1)") && contains(s[1].description, "(stack 2)"));
    CHECKF(load_dicom(path, NULL, 0) == NULL && contains(vxl_last_error(), "holds 2 DICOM series"), "%s",
           vxl_last_error());
    for (int t = 0; t < 2; t++) {
        char ref_dir[256], name[32], index[12];
        snprintf(name, sizeof name, "stack_reference_%d", t);
        dicom_folder(g_dir, ref_dir, sizeof ref_dir, name);
        REQUIRE(write_reference(ref_dir, t) == 0);
        snprintf(index, sizeof index, "%d", t);
        vxl_volume *ref = load_dicom(ref_dir, NULL, 0), *v = load_dicom(path, index, 0);
        CHECKF(ref && v && same_volume(ref, v) && same_affine(ref, v), "stack %d: %s", t,
               v ? "voxels or affine differ" : vxl_last_error());
        vxl_volume_destroy(ref);
        vxl_volume_destroy(v);
    }
}

/* The reference file at name under pydicom's test files, copied alone
 * into its own folder (a file names its folder's series). */
static vxl_volume *load_reference_file(const char *name)
{
    char dir[256], cmd[1024], path[512];
    dicom_folder(g_dir, dir, sizeof dir, name);
    snprintf(cmd, sizeof cmd, "cp '%s/%s' %s/", g_pydicom_files, name, dir);
    if (system(cmd) != 0) return NULL;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return load_dicom(path, NULL, 0);
}

/* pydicom's reference files: one MR image and one 15-frame RT dose (32-bit,
 * frames placed by GridFrameOffsetVector) in each encoding pydicom ships;
 * every encoding reads voxel for voxel as the first. */
TEST(reference_files_read_the_same_in_every_encoding)
{
    static const char *const sets[][6] = {
        {"MR_small.dcm", "MR_small_implicit.dcm", "MR_small_bigendian.dcm", "MR_small_RLE.dcm",
         "MR_small_jpeg_ls_lossless.dcm", "MR_small_jp2klossless.dcm"},
        /* the RLE copy also stores most elements as UN (unknown VR) */
        {"rtdose.dcm", "rtdose_expb.dcm", "rtdose_rle.dcm", NULL, NULL, NULL},
    };
    REQUIRE(find_pydicom_files() == 0);
    for (size_t s = 0; s < sizeof sets / sizeof sets[0]; s++) {
        vxl_volume *first = load_reference_file(sets[s][0]);
        CHECKF(first, "%s: %s", sets[s][0], vxl_last_error());
        if (!first) continue;
        for (size_t i = 1; i < 6 && sets[s][i]; i++) {
            vxl_volume *v = load_reference_file(sets[s][i]);
            CHECKF(v && same_volume(first, v) && same_affine(first, v), "%s: %s", sets[s][i],
                   v ? "voxels or affine differ" : vxl_last_error());
            vxl_volume_destroy(v);
        }
        vxl_volume_destroy(first);
    }
    /* deflated, and without PixelSpacing: 1 mm with a note, the same voxels
     * as dcmtk's inflated copy */
    vxl_volume *deflated = load_reference_file("image_dfl.dcm");
    char inflated[512], src[600];
    snprintf(src, sizeof src, "%s/image_dfl.dcm", g_pydicom_files);
    REQUIRE(convert(src, "inflated", "dcmconv +te", inflated, sizeof inflated) == 0);
    vxl_volume *plain = load_dicom(inflated, NULL, 0);
    vxl_volume_info info;
    CHECKF(deflated && plain && same_volume(deflated, plain) && deflated->spacing[0] == 1, "%s", vxl_last_error());
    const char *notes = deflated ? volume_notes(deflated, &info) : "";
    CHECKF(contains(notes, "PixelSpacing missing or zero in 1 of 1 image(s): 1 mm assumed"), "%s", notes);
    vxl_volume_destroy(deflated);
    vxl_volume_destroy(plain);

    vxl_volume *dose = load_reference_file("rtdose.dcm");
    REQUIRE(dose);
    CHECK(dose->dims[0] == 10 && dose->dims[2] == 15 && fabs(dose->spacing[2] - 5) < 1e-9 &&
          dose->src_dtype == VXL_DTYPE_U32 && !strcmp(volume_notes(dose, &info), ""));
    vxl_volume_destroy(dose);
}

/* A smooth series of `bits` stored bits (8: 8-bit unsigned), for the lossy
 * codecs: noise would only measure the codec's worst case. */
static int write_smooth(const char *dir, int bits)
{
    enum { W = 64, H = 48, S = 4 };
    static uint16_t px[W * H];
    static uint8_t px8[W * H];
    const double top = (double)((1 << bits) - 1);
    for (int k = 0; k < S; k++) {
        for (int j = 0; j < H; j++)
            for (int i = 0; i < W; i++) {
                const double v = 0.5 + 0.4 * sin(i * 0.15 + k) * cos(j * 0.11 - k * 0.5);
                px[i + W * j] = (uint16_t)lround(v * top);
                px8[i + W * j] = (uint8_t)px[i + W * j];
            }
        dcmw_slice d = dcmw_axial("1.2.3.310", W, H, 2.0 * k, bits == 8 ? (const void *)px8 : (const void *)px,
                                  (size_t)W * H * (bits == 8 ? 1 : 2));
        d.bits_alloc = bits == 8 ? 8 : 16;
        d.bits_stored = (uint16_t)bits;
        d.instance = k;
        char p[512];
        snprintf(p, sizeof p, "%s/IM%04d.dcm", dir, k);
        if (dcmw_write(p, &d)) return -1;
    }
    return 0;
}

/* The lossy codecs stay within their bounds: JPEG-LS near-lossless within
 * its NEAR parameter exactly (the standard guarantees it), JPEG Baseline (8
 * bits) and Extended (12 bits) at quality 90 within 2% and 0.5% of the
 * range, bounds set from what dcmtk's encoder gives on this smooth series
 * (observed: 3 of 255 and 6 of 4095); each differs somewhere, so the lossy
 * path really ran. */
TEST(lossy_codecs_stay_within_their_bounds)
{
    static const struct {
        int bits;
        const char *name, *tool;
        double bound;
    } cases[] = {
        {8, "baseline", "dcmcjpeg +eb", 0.02 * 255},
        {12, "extended", "dcmcjpeg +ee", 0.005 * 4095},
        {12, "near_lossless", "dcmcjpls +en +md 3", 3},
        {16, "near_lossless16", "dcmcjpls +en +md 5", 5},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        char src[256], dir[256], name[64];
        snprintf(name, sizeof name, "smooth_%s", cases[c].name);
        dicom_folder(g_dir, src, sizeof src, name);
        REQUIRE(write_smooth(src, cases[c].bits) == 0);
        vxl_volume *a = load_dicom(src, NULL, 0);
        REQUIRE(a);
        snprintf(name, sizeof name, "lossy_%s", cases[c].name);
        REQUIRE(convert_series(g_dir, src, 4, name, cases[c].tool, dir, sizeof dir) == 0);
        vxl_volume *b = load_dicom(dir, NULL, 0);
        const double d = b ? max_difference(a, b) : -1;
        CHECKF(b && d > 0 && d <= cases[c].bound + 1e-6, "%s: max difference %g (bound %g) %s", cases[c].tool, d,
               cases[c].bound, b ? "" : vxl_last_error());
        vxl_volume_destroy(a);
        vxl_volume_destroy(b);
    }
}

/* Channel c (0 R, 1 G, 2 B) of tests/make_colour_dicom.py's pattern at
 * (i, j) of frame k. */
static int pattern(int i, int j, int k, int c)
{
    return c == 0 ? (40 * i + 10 * k) % 256 : c == 1 ? (50 * j + 30) % 256 : (7 * i * j + k) % 256;
}

/* Full-range YCbCr of the pattern's pixel (PS3.3 C.7.6.3.1.2), rounded to
 * 8 bits as tests/make_colour_dicom.py rounds it (numpy's rint: half to
 * even, as nearbyint). */
static double ycbcr(int i, int j, int k, int c)
{
    const double r = pattern(i, j, k, 0), g = pattern(i, j, k, 1), b = pattern(i, j, k, 2);
    const double v = c == 0 ? 0.299 * r + 0.587 * g + 0.114 * b
                   : c == 1 ? -0.168736 * r - 0.331264 * g + 0.5 * b + 128
                            : 0.5 * r - 0.418688 * g - 0.081312 * b + 128;
    return fmin(255, fmax(0, nearbyint(v)));
}

/* What YBR_FULL_422 of the pattern holds, back in RGB as the reader turns
 * it: the pixel's own Y with the chroma its pair of pixels shares (their
 * mean, rounded as the writer does), then PS3.3's inverse, rounded and
 * clamped to 8 bits. The reference for the subsampled encodings. */
static int pattern_422(int i, int j, int k, int c)
{
    const int i0 = i & ~1;
    const double y = ycbcr(i, j, k, 0);
    const double cb = nearbyint((ycbcr(i0, j, k, 1) + ycbcr(i0 + 1, j, k, 1)) / 2) - 128;
    const double cr = nearbyint((ycbcr(i0, j, k, 2) + ycbcr(i0 + 1, j, k, 2)) / 2) - 128;
    const double v = c == 0 ? y + 1.402 * cr : c == 1 ? y - 0.344136 * cb - 0.714136 * cr : y + 1.772 * cb;
    return (int)lround(fmin(255, fmax(0, v)));
}

/* Largest channel difference of v's colour from the pattern (or from its
 * 4:2:2 subsampling, subsampled), and of its scalar from the luminance of
 * v's own colour (the opacity source as vxl_volume_build_colour rounds
 * it); -1 when v is not an 8x6 RGB colour volume. */
static double colour_error(const vxl_volume *v, int subsampled, double *scalar_error)
{
    if (!v || v->dims[0] != 8 || v->dims[1] != 6 || !v->colour || v->components != 3) return -1;
    double worst = 0;
    *scalar_error = 0;
    for (uint32_t k = 0; k < v->dims[2]; k++)
        for (int j = 0; j < 6; j++)
            for (int i = 0; i < 8; i++) {
                const uint64_t at = (uint64_t)i + 8 * j + 48 * k;
                const uint8_t *rgb = v->colour + 3 * at;
                for (int c = 0; c < 3; c++) {
                    const int want = subsampled ? pattern_422(i, j, (int)k, c) : pattern(i, j, (int)k, c);
                    worst = fmax(worst, fabs((double)rgb[c] - want));
                }
                const double lum = floor(0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2] + 0.5);
                *scalar_error = fmax(*scalar_error, fabs(voxel(v, at) - lum));
            }
    return worst;
}

/* The volume at path with an opacity source; NULL on failure. */
static vxl_volume *load_with_opacity(const char *path, uint32_t source, uint32_t channel)
{
    vxl_load_options opt = {.struct_size = sizeof opt, .opacity_source = source, .opacity_channel = channel};
    vxl_volume *v = NULL;
    return load_dicom_with(path, &opt, &v) == VXL_OK ? v : NULL;
}

/* Colour DICOM (RGB by pixel and by plane, YBR_FULL, YBR_FULL_422, JPEG
 * 2000 and HTJ2K (.203 and .202) with their colour transform, and dcmtk's
 * RLE, lossless JPEG, JPEG-LS and Baseline of the RGB file; PALETTE COLOR with 16-bit and packed 8-bit
 * tables, and its RLE) loads as a colour volume through the reader helper:
 * its RGB8 colour is the pattern, exactly where the encoding is lossless
 * and RGB or palette; within 2 of the YCbCr the writer rounded to 8 bits
 * (half a step in Y and in Cr is 1.2 in red before the reader rounds;
 * measured 1); YBR_FULL_422 exactly as its shared chroma gives it
 * (pattern_422); Baseline at quality 90, which subsamples chroma the same
 * way, within 40 of that (measured 23: the pattern jumps by up to 220 from
 * one pixel to the next where it wraps). The scalar is the colour's
 * luminance (the default opacity source) and the note says what was
 * decided. */
TEST(colour_in_every_encoding_loads_as_colour)
{
    static const struct {
        const char *mode, *tool; /* tool: a dcmtk encoder run on the mode's file, or NULL */
        double bound;
        int subsampled; /* the encoding shares chroma between two pixels: held against pattern_422 */
        const char *note;
    } cases[] = {
        {"rgb", NULL, 0, 0, "DICOM RGB: colour from the data"},
        {"rgb-planar", NULL, 0, 0, "DICOM RGB: colour from the data"},
        {"ybr", NULL, 2, 0, "DICOM YBR_FULL: colour from the data"},
        {"ybr422", NULL, 0, 1, "DICOM YBR_FULL_422: colour from the data"},
        {"j2k", NULL, 0, 0, "DICOM YBR_RCT: colour from the data"},
        {"htj2k", NULL, 0, 0, "DICOM YBR_RCT: colour from the data"},
        {"htj2k-rpcl", NULL, 0, 0, "DICOM YBR_RCT: colour from the data"},
        {"rgb", "dcmcrle", 0, 0, "DICOM RGB: colour"},
        {"rgb-planar", "dcmcrle", 0, 0, "DICOM RGB: colour"},
        {"rgb", "dcmcjpeg", 0, 0, "DICOM RGB: colour"},
        {"rgb", "dcmcjpls", 0, 0, "DICOM RGB: colour"},
        {"rgb", "dcmcjpeg +eb", 40, 1, "DICOM YBR_FULL_422: colour"},
        {"palette", NULL, 0, 0, "DICOM PALETTE COLOR: colour from the data, opacity and gradients from luminance"},
        {"palette8", NULL, 0, 0, "DICOM PALETTE COLOR: colour"},
        {"palette", "dcmcrle", 0, 0, "DICOM PALETTE COLOR: colour"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        char dir[256], path[512], cmd[1024], name[64];
        snprintf(name, sizeof name, "colour_%zu", c);
        dicom_folder(g_dir, dir, sizeof dir, name);
        snprintf(path, sizeof path, "%s/c.dcm", dir);
        snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/make_colour_dicom.py %s %s", path, cases[c].mode);
        REQUIRE(system(cmd) == 0);
        if (cases[c].tool) {
            char out[512];
            snprintf(name, sizeof name, "colour_%zu_coded", c);
            REQUIRE(convert(path, name, cases[c].tool, out, sizeof out) == 0);
            snprintf(path, sizeof path, "%s", out);
        }
        const char *tool = cases[c].tool ? cases[c].tool : "";
        vxl_volume *v = load_dicom(path, NULL, 0);
        double scalar_error = 0;
        const double worst = colour_error(v, cases[c].subsampled, &scalar_error);
        CHECKF(v && v->dims[2] == 2 && worst >= 0, "%s %s: %s", cases[c].mode, tool,
               v ? "not a 8x6x2 colour volume" : vxl_last_error());
        CHECKF(worst <= cases[c].bound, "%s %s: colour off by %g (bound %g)", cases[c].mode, tool, worst,
               cases[c].bound);
        CHECKF(scalar_error == 0, "%s %s: scalar off the colour's luminance by %g", cases[c].mode, tool, scalar_error);
        vxl_volume_info info;
        CHECKF(v && contains(volume_notes(v, &info), cases[c].note), "%s %s: notes '%s'", cases[c].mode, tool,
               v ? info.notes : "");
        CHECK(v && info.components == 3 && info.color_bytes == 8 * 6 * 2 * 3);
        vxl_volume_destroy(v);
    }
}

/* The opacity source is the caller's: a channel's values exactly, and alpha
 * of RGB data refused with the reason, through the helper as in process. */
TEST(colour_dicom_opacity_source_is_the_load_option)
{
    char dir[256], path[512], cmd[1024];
    dicom_folder(g_dir, dir, sizeof dir, "colour_opacity");
    snprintf(path, sizeof path, "%s/c.dcm", dir);
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/make_colour_dicom.py %s rgb-planar", path);
    REQUIRE(system(cmd) == 0);
    for (uint32_t ch = 0; ch < 3; ch++) {
        vxl_volume *v = load_with_opacity(path, VXL_OPACITY_SOURCE_CHANNEL, ch);
        REQUIRE(v);
        double worst = 0;
        for (int k = 0; k < 2; k++)
            for (int j = 0; j < 6; j++)
                for (int i = 0; i < 8; i++)
                    worst = fmax(worst, fabs(voxel(v, (uint64_t)(i + 8 * j + 48 * k)) - pattern(i, j, k, (int)ch)));
        vxl_volume_info info;
        CHECKF(worst == 0, "channel %u: scalar off by %g", ch, worst);
        CHECK(contains(volume_notes(v, &info), ch == 0 ? "from the red channel" : ch == 1 ? "from the green channel"
                                                                                        : "from the blue channel"));
        CHECK(info.opacity_source == VXL_OPACITY_SOURCE_CHANNEL && v->colour && v->colour[0] == pattern(0, 0, 0, 0));
        vxl_volume_destroy(v);
    }
    CHECK(load_with_opacity(path, VXL_OPACITY_SOURCE_ALPHA, 0) == NULL);
    CHECKF(contains(vxl_last_error(), "opacity source alpha needs RGBA data; this has 3 channels"), "%s",
           vxl_last_error());
    CHECK(load_with_opacity(path, VXL_OPACITY_SOURCE_CHANNEL, 3) == NULL);
    CHECKF(contains(vxl_last_error(), "opacity channel 3: the data has channels 0..2"), "%s", vxl_last_error());
    /* the colour's 3 bytes a voxel count against the budget: 8x6x2 RGB is
     * 96 bytes of raw channels but 4 a voxel once built (the scalar and its
     * colour), 384 */
    vxl_load_options opt = {.struct_size = sizeof opt, .memory_budget_bytes = 300};
    vxl_volume *v = NULL;
    CHECK(load_dicom_with(path, &opt, &v) == VXL_ERR_LIMIT && !v);
    CHECKF(contains(vxl_last_error(), "colour volumes are read whole"), "%s", vxl_last_error());
}

/* A series of single-frame colour files, named and numbered out of order
 * with a slice missing, goes through the slice plan as grey series do:
 * sorted by position, the missing slice blended channel by channel from
 * its two neighbours. */
TEST(colour_series_is_sorted_and_its_missing_slice_blended)
{
    char dir[256], cmd[1024];
    dicom_folder(g_dir, dir, sizeof dir, "colour_series");
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/make_colour_dicom.py %s series", dir);
    REQUIRE(system(cmd) == 0);
    vxl_volume *v = load_dicom(dir, NULL, 0);
    REQUIRE(v);
    CHECKF(v->dims[0] == 8 && v->dims[1] == 6 && v->dims[2] == 5 && v->colour, "%ux%ux%u", v->dims[0], v->dims[1],
           v->dims[2]);
    double worst = 0;
    for (int k = 0; k < 5 && v->dims[2] == 5 && v->colour; k++)
        for (int j = 0; j < 6; j++)
            for (int i = 0; i < 8; i++)
                for (int c = 0; c < 3; c++) {
                    /* slice 3 is missing: half of 2 and half of 4, as the plan rounds */
                    const double want = k == 3 ? (double)lround(pattern(i, j, 2, c) +
                                                                0.5 * (pattern(i, j, 4, c) - pattern(i, j, 2, c)))
                                               : pattern(i, j, k, c);
                    worst = fmax(worst, fabs((double)v->colour[3 * (i + 8 * j + 48 * k) + c] - want));
                }
    CHECKF(worst == 0, "colour off by %g", worst);
    CHECK(fabs(v->spacing[2] - 2) < 1e-9 && fabs(v->affine[14] - 0) < 1e-9);
    vxl_volume_destroy(v);
}

/* An enhanced multi-frame RGB file, frames shuffled, 2 time points: each
 * time point a colour volume whose slices come out in the order (and with
 * the affine) the grey file of the same geometry gets. */
TEST(enhanced_colour_frames_follow_the_slice_plan)
{
    char dir[256], grey[512], rgb[512];
    dicom_folder(g_dir, dir, sizeof dir, "enhanced_rgb");
    snprintf(grey, sizeof grey, "%s/grey.dcm", dir);
    snprintf(rgb, sizeof rgb, "%s/rgb.dcm", dir);
    REQUIRE(write_enhanced(grey, 2, 11, "") == 0 && write_enhanced(rgb, 2, 13, "rgb") == 0);
    for (uint32_t t = 0; t < 2; t++) {
        vxl_volume *g = load_dicom(grey, NULL, t), *v = load_dicom(rgb, NULL, t);
        CHECKF(g && v && v->colour && v->components == 3 && v->frame_count == 2, "time %u: %s", t,
               v ? "not a colour volume of 2 frames" : vxl_last_error());
        if (!g || !v || !v->colour) {
            vxl_volume_destroy(g);
            vxl_volume_destroy(v);
            continue;
        }
        CHECK(!memcmp(v->dims, g->dims, sizeof v->dims) && same_affine(g, v));
        double worst = 0;
        for (uint32_t s = 0; s < v->dims[2]; s++)
            for (int j = 0; j < R; j++)
                for (int i = 0; i < C; i++) {
                    const uint64_t at = (uint64_t)i + C * (j + (uint64_t)R * s);
                    /* the grey file's value says which slice k landed here */
                    const int k = (int)lround((voxel(g, at) + 1024 - 1000.0 * t - 10 * j - i) / 100);
                    const int want[3] = {(10 * j + i) % 256, (40 * k + 5) % 256, (90 * (int)t + 7 * k) % 256};
                    for (int c = 0; c < 3; c++) worst = fmax(worst, fabs((double)v->colour[3 * at + c] - want[c]));
                }
        CHECKF(worst == 0, "time %u: colour off by %g", t, worst);
        vxl_volume_destroy(g);
        vxl_volume_destroy(v);
    }
}

OWN_PARSER_TEST

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_dicom_frames_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(enhanced_frames_in_shuffled_order_come_out_in_anatomical_order);
    RUN(enhanced_time_points_become_frames);
    RUN(stacks_of_one_enhanced_file_are_series_of_their_own);
    RUN(damaged_offset_tables_are_clear_errors);
    RUN(reference_files_read_the_same_in_every_encoding);
    RUN(lossy_codecs_stay_within_their_bounds);
    RUN(colour_in_every_encoding_loads_as_colour);
    RUN(colour_dicom_opacity_source_is_the_load_option);
    RUN(colour_series_is_sorted_and_its_missing_slice_blended);
    RUN(enhanced_colour_frames_follow_the_slice_plan);
    RUN(own_parser_agrees_with_dcmtk);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
