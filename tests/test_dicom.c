/* test_dicom.c - DICOM series through the public API (vxl_volume_load,
 * vxl_dicom_list_series): geometry from positions with shuffled files and an
 * oblique orientation, rescale to Hounsfield units, several series, 4D
 * series (time points at every position), RLE and JPEG Lossless against
 * dcmtk's encoders, what is loaded with a note (a missing slice
 * interpolated, a localizer left out, a multi-frame file without spacing)
 * and the refusals (mixed sizes without a majority, mixed spacing, damaged
 * frames, truncated, garbage, over budget). Multi-frame and enhanced files
 * and the other codecs: test_dicom_frames.c. Files come from tests/fuzz/dicom_writer.h, written
 * from the standard independently of dcmtk. Voxel values are read back
 * through the texels (volume.h), so ordering mistakes show as wrong values. */
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dicom_test_util.h"
#include "fuzz/dicom_writer.h"
#include "harness.h"

static char g_dir[64];

/* A fresh folder g_dir/name. */
static const char *folder(char *buf, size_t n, const char *name) { return dicom_folder(g_dir, buf, n, name); }

static vxl_volume *load_series(const char *path, const char *series) { return load_dicom(path, series, 0); }

#define NC 4 /* columns */
#define NR 3 /* rows */
#define NS 5 /* slices */

/* Slice k of a series along normal n from origin o at step dz; pixel value
 * base + i + 10 j + 100 k; file name by perm so files are not in order. */
static int write_stack(const char *dir, const char *uid, const double iop[6], const double o[3], const double step[3],
                       int nslices, const int *perm, int base, const dcmw_slice *tmpl)
{
    uint16_t px[NC * NR];
    for (int k = 0; k < nslices; k++) {
        for (int j = 0; j < NR; j++)
            for (int i = 0; i < NC; i++) px[i + NC * j] = (uint16_t)(base + i + 10 * j + 100 * k);
        dcmw_slice d = tmpl ? *tmpl : dcmw_axial(uid, NC, NR, 0, px, sizeof px);
        d.series_uid = uid;
        d.pixels = px;
        d.pixel_bytes = sizeof px;
        d.instance = k;
        memcpy(d.iop, iop, sizeof d.iop);
        for (int a = 0; a < 3; a++) d.ipp[a] = o[a] + k * step[a];
        char p[512];
        snprintf(p, sizeof p, "%s/IM%04d.dcm", dir, perm ? perm[k] : k);
        if (dcmw_write(p, &d)) return -1;
    }
    return 0;
}

static const double k_axial[6] = {1, 0, 0, 0, 1, 0};

TEST(oblique_shuffled_series_gets_its_affine_and_spacing_from_positions)
{
    char dir[256];
    folder(dir, sizeof dir, "oblique");
    const double a = 30 * M_PI / 180, b = 20 * M_PI / 180;
    const double r[3] = {cos(a), sin(a), 0}, c[3] = {-sin(a) * cos(b), cos(a) * cos(b), sin(b)};
    double n[3] = {r[1] * c[2] - r[2] * c[1], r[2] * c[0] - r[0] * c[2], r[0] * c[1] - r[1] * c[0]};
    const double iop[6] = {r[0], r[1], r[2], c[0], c[1], c[2]};
    const double o[3] = {-12.5, 40.25, 7}, dz = 2.5;
    const double step[3] = {n[0] * dz, n[1] * dz, n[2] * dz};
    const int perm[NS] = {3, 0, 4, 1, 2};
    dcmw_slice t = dcmw_axial("1.2.3.10", NC, NR, 0, NULL, 0);
    t.ps[0] = 0.7; /* row spacing (between rows) */
    t.ps[1] = 0.9; /* column spacing */
    REQUIRE(write_stack(dir, "1.2.3.10", iop, o, step, NS, perm, 0, &t) == 0);
    vxl_volume *v = load_series(dir, NULL);
    REQUIRE(v);
    CHECK(v->dims[0] == NC && v->dims[1] == NR && v->dims[2] == NS);
    for (int k = 0; k < NS; k++)
        for (int j = 0; j < NR; j++)
            for (int i = 0; i < NC; i++) {
                double got = voxel(v, (uint64_t)i + NC * (j + NR * k));
                CHECKF(fabs(got - (i + 10 * j + 100 * k)) < 1e-9, "voxel %d,%d,%d = %g", i, j, k, got);
            }
    /* LPS -> RAS: x and y negated */
    const double sgn[3] = {-1, -1, 1};
    for (int row = 0; row < 3; row++) {
        CHECK(fabs(v->affine[0 * 4 + row] - sgn[row] * r[row] * 0.9) < 1e-6);
        CHECK(fabs(v->affine[1 * 4 + row] - sgn[row] * c[row] * 0.7) < 1e-6);
        CHECK(fabs(v->affine[2 * 4 + row] - sgn[row] * n[row] * dz) < 1e-6);
        CHECK(fabs(v->affine[3 * 4 + row] - sgn[row] * o[row]) < 1e-6);
    }
    CHECK(fabs(v->spacing[0] - 0.9) < 1e-9 && fabs(v->spacing[1] - 0.7) < 1e-9 && fabs(v->spacing[2] - dz) < 1e-6);
    vxl_volume_destroy(v);

    /* naming one file loads its series, the same volume */
    char one[512];
    snprintf(one, sizeof one, "%s/IM0002.dcm", dir);
    v = load_series(one, NULL);
    CHECK(v && v->dims[2] == NS && fabs(v->affine[14] - o[2]) < 1e-6);
    vxl_volume_destroy(v);
}

TEST(rescale_slope_intercept_gives_hounsfield_units)
{
    char dir[256];
    folder(dir, sizeof dir, "ct");
    dcmw_slice t = dcmw_axial("1.2.3.20", NC, NR, 0, NULL, 0);
    t.has_rescale = 1;
    t.slope = 1;
    t.inter = -1024;
    const double o[3] = {0, 0, 0}, step[3] = {0, 0, 1.25};
    REQUIRE(write_stack(dir, "1.2.3.20", k_axial, o, step, NS, NULL, 1000, &t) == 0);
    vxl_volume *v = load_series(dir, NULL);
    REQUIRE(v);
    CHECK(v->texture_bits == 16); /* one rescale for all: stored exactly */
    CHECK(fabs(voxel(v, 0) - (1000 - 1024)) < 1e-9);
    CHECK(fabs(voxel(v, 3 + NC * (2 + NR * 4)) - (1000 + 3 + 20 + 400 - 1024)) < 1e-9);
    CHECK(fabs(v->value_min + 24) < 1e-9);
    vxl_volume_destroy(v);

    /* per-slice rescale values (PET): every slice scaled by its own */
    char dir2[256];
    folder(dir2, sizeof dir2, "pet");
    uint16_t px[NC * NR];
    for (int i = 0; i < NC * NR; i++) px[i] = (uint16_t)(i + 1);
    for (int k = 0; k < 3; k++) {
        dcmw_slice d = dcmw_axial("1.2.3.21", NC, NR, 2.0 * k, px, sizeof px);
        d.modality = "PT";
        d.has_rescale = 1;
        d.slope = 0.5 * (k + 1);
        d.inter = 10.0 * k;
        char p[512];
        snprintf(p, sizeof p, "%s/s%d", dir2, k); /* no extension: found by the "DICM" magic */
        REQUIRE(dcmw_write(p, &d) == 0);
    }
    v = load_series(dir2, NULL);
    REQUIRE(v);
    CHECK(v->texture_bits == 32);
    for (int k = 0; k < 3; k++)
        CHECKF(fabs(voxel(v, 5 + (uint64_t)NC * NR * k) - (6 * 0.5 * (k + 1) + 10.0 * k)) < 1e-4, "slice %d", k);
    vxl_volume_destroy(v);
}

TEST(signed_8_bit_and_bits_stored_below_bits_allocated)
{
    char dir[256];
    folder(dir, sizeof dir, "signed12");
    int16_t px[NC * NR];
    for (int i = 0; i < NC * NR; i++) px[i] = (int16_t)(i % 2 ? -(i * 100) : i * 100);
    /* 12 bits stored: set garbage in the top nibble of positive values that
     * the reader must mask off (negatives keep their sign bits) */
    for (int i = 0; i < NC * NR; i++)
        if (px[i] >= 0) px[i] = (int16_t)(px[i] | 0x7000);
    dcmw_slice d = dcmw_axial("1.2.3.30", NC, NR, 0, px, sizeof px);
    d.pixel_rep = 1;
    d.bits_stored = 12;
    char p[512];
    snprintf(p, sizeof p, "%s/a.dcm", dir);
    REQUIRE(dcmw_write(p, &d) == 0);
    vxl_volume *v = load_series(p, NULL);
    REQUIRE(v);
    for (int i = 0; i < NC * NR; i++)
        CHECKF(fabs(voxel(v, (uint64_t)i) - (i % 2 ? -(i * 100) : i * 100)) < 1e-9, "pixel %d = %g", i, voxel(v, (uint64_t)i));
    vxl_volume_destroy(v);

    folder(dir, sizeof dir, "u8");
    uint8_t b[NC * NR];
    for (int i = 0; i < NC * NR; i++) b[i] = (uint8_t)(i * 20);
    d = dcmw_axial("1.2.3.31", NC, NR, 0, b, sizeof b);
    d.bits_alloc = 8;
    snprintf(p, sizeof p, "%s/a.dcm", dir);
    REQUIRE(dcmw_write(p, &d) == 0);
    v = load_series(p, NULL);
    REQUIRE(v);
    CHECK(v->texture_bits == 8 && fabs(voxel(v, 11) - 220) < 1e-9);
    vxl_volume_destroy(v);
}

TEST(several_series_are_listed_and_one_is_chosen_by_index_or_uid)
{
    char dir[256];
    folder(dir, sizeof dir, "two");
    const double o[3] = {0, 0, 0}, step[3] = {0, 0, 2};
    dcmw_slice a = dcmw_axial("1.2.3.40", NC, NR, 0, NULL, 0);
    a.description = "axial soft tissue";
    dcmw_slice b = dcmw_axial("1.2.3.41", NC, NR, 0, NULL, 0);
    b.modality = "MR";
    const int perm_b[3] = {10, 11, 12};
    REQUIRE(write_stack(dir, "1.2.3.40", k_axial, o, step, NS, NULL, 0, &a) == 0);
    REQUIRE(write_stack(dir, "1.2.3.41", k_axial, o, step, 3, perm_b, 5000, &b) == 0);

    vxl_dicom_series s[4];
    memset(s, 0, sizeof s);
    s[0].struct_size = sizeof s[0];
    uint32_t count = 0;
    REQUIRE(vxl_dicom_list_series(dir, s, 4, &count) == VXL_OK);
    CHECK(count == 2);
    CHECK(!strcmp(s[0].uid, "1.2.3.40") && !strcmp(s[1].uid, "1.2.3.41"));
    CHECK(s[0].slice_count == NS && s[1].slice_count == 3);
    CHECK(s[0].dims[0] == NC && s[0].dims[1] == NR && s[0].dims[2] == NS);
    CHECK(!strcmp(s[0].modality, "CT") && !strcmp(s[1].modality, "MR"));
    CHECK(!strcmp(s[0].description, "axial soft tissue"));
    CHECK(s[0].loadable && s[1].loadable && !s[0].problem[0]);
    /* counting only */
    count = 0;
    CHECK(vxl_dicom_list_series(dir, NULL, 0, &count) == VXL_OK && count == 2);

    vxl_volume *v = NULL;
    CHECK(load_dicom_with(dir, NULL, &v) == VXL_ERR_INVALID_ARGUMENT && !v);
    CHECK(contains(vxl_last_error(), "2 DICOM series") && contains(vxl_last_error(), "1.2.3.40") &&
          contains(vxl_last_error(), "1.2.3.41"));

    v = load_series(dir, "1");
    CHECK(v && v->dims[2] == 3 && fabs(voxel(v, 0) - 5000) < 1e-9);
    vxl_volume_destroy(v);
    v = load_series(dir, "1.2.3.40");
    CHECK(v && v->dims[2] == NS && fabs(voxel(v, 0)) < 1e-9);
    vxl_volume_destroy(v);
    CHECK(load_series(dir, "7") == NULL && contains(vxl_last_error(), "no series '7'"));
    CHECK(load_series(dir, "1.2.9") == NULL && contains(vxl_last_error(), "1.2.3.41"));

    /* a file of series B names B, without a choice */
    char one[512];
    snprintf(one, sizeof one, "%s/IM0011.dcm", dir);
    v = load_series(one, NULL);
    CHECK(v && v->dims[2] == 3);
    vxl_volume_destroy(v);

    /* struct_size smaller than today's: only that much is written */
    vxl_dicom_series small[2];
    memset(small, 0xAB, sizeof small);
    small[0].struct_size = (uint32_t)offsetof(vxl_dicom_series, problem);
    REQUIRE(vxl_dicom_list_series(dir, small, 1, &count) == VXL_OK);
    CHECK(((unsigned char *)&small[0])[offsetof(vxl_dicom_series, problem)] == 0xAB);
    CHECK(!strcmp(small[0].uid, "1.2.3.40"));
}

TEST(missing_slice_is_interpolated_with_a_note)
{
    char dir[256];
    folder(dir, sizeof dir, "gap");
    const double zs[] = {0, 2, 4, 8, 10};
    uint16_t px[NC * NR];
    for (int k = 0; k < 5; k++) {
        for (int i = 0; i < NC * NR; i++) px[i] = (uint16_t)(100 * k + i);
        dcmw_slice d = dcmw_axial("1.2.3.50", NC, NR, zs[k], px, sizeof px);
        char p[512];
        snprintf(p, sizeof p, "%s/%d.dcm", dir, k);
        REQUIRE(dcmw_write(p, &d) == 0);
    }
    /* six slices every 2 mm; the one at z = 6 is the mean of its neighbours,
     * the others are the files' own */
    vxl_volume *v = load_series(dir, NULL);
    REQUIRE(v);
    vxl_volume_info info;
    const char *notes = volume_notes(v, &info);
    CHECK(v->dims[2] == 6 && fabs(v->spacing[2] - 2) < 1e-9 && fabs(v->affine[14]) < 1e-9);
    const double expect[6] = {0, 100, 200, 250, 300, 400};
    for (int k = 0; k < 6; k++)
        for (int i = 0; i < NC * NR; i++)
            CHECKF(fabs(voxel(v, (uint64_t)(k * NC * NR + i)) - (expect[k] + i)) < 1e-6, "slice %d voxel %d", k, i);
    CHECKF(contains(notes, "uneven slice spacing") && contains(notes, "4 mm") && contains(notes, "2 mm") &&
           contains(notes, "1 of them interpolated"), "%s", notes);
    vxl_volume_destroy(v);
    vxl_dicom_series s = {.struct_size = sizeof s};
    uint32_t n = 0;
    CHECK(vxl_dicom_list_series(dir, &s, 1, &n) == VXL_OK && n == 1 && s.loadable && s.dims[2] == 6);

    /* two slices at one position (4D acquisitions) */
    folder(dir, sizeof dir, "dup");
    for (int k = 0; k < 3; k++) {
        dcmw_slice d = dcmw_axial("1.2.3.51", NC, NR, k == 2 ? 2 : 2.0 * k, px, sizeof px);
        d.instance = k;
        char p[512];
        snprintf(p, sizeof p, "%s/%d.dcm", dir, k);
        REQUIRE(dcmw_write(p, &d) == 0);
    }
    CHECKF(load_series(dir, NULL) == NULL && contains(vxl_last_error(), "time points"), "%s", vxl_last_error());
}

TEST(time_points_at_every_position_make_a_4d_series)
{
    char dir[256], p[512];
    folder(dir, sizeof dir, "cardiac");
    enum { K = 3, T = 4 };
    uint16_t px[NC * NR];
    const int perm[K * T] = {7, 2, 11, 0, 5, 9, 1, 10, 3, 8, 6, 4};
    for (int k = 0; k < K; k++)
        for (int t = 0; t < T; t++) {
            for (int i = 0; i < NC * NR; i++) px[i] = (uint16_t)(1000 * t + 100 * k + i);
            dcmw_slice d = dcmw_axial("1.2.3.95", NC, NR, 5.0 * k, px, sizeof px);
            d.temporal_position = t + 1;
            d.instance = (T - 1 - t) * K + k; /* instance order disagrees with time: the time tag wins */
            snprintf(p, sizeof p, "%s/f%02d.dcm", dir, perm[k * T + t]);
            REQUIRE(dcmw_write(p, &d) == 0);
        }
    vxl_dicom_series s = {.struct_size = sizeof s};
    uint32_t n = 0;
    REQUIRE(vxl_dicom_list_series(dir, &s, 1, &n) == VXL_OK && n == 1);
    CHECKF(s.loadable && s.frame_count == T && s.dims[2] == K && s.slice_count == K * T, "%s", s.problem);
    for (uint32_t t = 0; t < T; t++) {
        vxl_load_options opt = {.struct_size = sizeof opt, .frame = t};
        vxl_volume *v = NULL;
        REQUIRE(load_dicom_with(dir, &opt, &v) == VXL_OK);
        vxl_volume_info info = {.struct_size = sizeof info};
        vxl_volume_get_info(v, &info);
        CHECK(info.frame_count == T && info.frame == t && info.dims[2] == K);
        CHECK(fabs(v->affine[10] - 5.0) < 1e-9);
        for (int k = 0; k < K; k++)
            CHECKF(fabs(voxel(v, 7 + (uint64_t)NC * NR * k) - (1000.0 * t + 100 * k + 7)) < 1e-9, "t %u k %d", t, k);
        vxl_volume_destroy(v);
    }
    vxl_load_options opt = {.struct_size = sizeof opt, .frame = T};
    vxl_volume *v = NULL;
    CHECK(load_dicom_with(dir, &opt, &v) == VXL_ERR_INVALID_ARGUMENT && contains(vxl_last_error(), "has 4"));

    /* two files at one position with the same time are duplicates */
    folder(dir, sizeof dir, "dup_time");
    for (int f = 0; f < 4; f++) {
        dcmw_slice d = dcmw_axial("1.2.3.96", NC, NR, 5.0 * (f / 2), px, sizeof px);
        d.temporal_position = f == 1 ? 1 : f % 2 + 1;
        snprintf(p, sizeof p, "%s/%d.dcm", dir, f);
        REQUIRE(dcmw_write(p, &d) == 0);
    }
    CHECKF(load_series(dir, NULL) == NULL && contains(vxl_last_error(), "duplicates"), "%s", vxl_last_error());
}

TEST(gantry_tilt_loads_with_a_sheared_affine_and_is_reported)
{
    char dir[256];
    folder(dir, sizeof dir, "tilt");
    const double tilt = 20 * M_PI / 180, dz = 2;
    const double o[3] = {0, 0, 0}, step[3] = {0, dz * tan(tilt), dz};
    REQUIRE(write_stack(dir, "1.2.3.60", k_axial, o, step, NS, NULL, 0, NULL) == 0);
    vxl_dicom_series s = {.struct_size = sizeof s};
    uint32_t n = 0;
    REQUIRE(vxl_dicom_list_series(dir, &s, 1, &n) == VXL_OK);
    CHECK(s.loadable && fabs(s.gantry_tilt_deg - 20) < 1e-6);
    vxl_volume *v = load_series(dir, NULL);
    REQUIRE(v);
    CHECK(fabs(v->affine[8]) < 1e-9 && fabs(v->affine[9] + dz * tan(tilt)) < 1e-9 && fabs(v->affine[10] - dz) < 1e-9);
    vxl_volume_destroy(v);
    /* an orthogonal stack reports no tilt */
    folder(dir, sizeof dir, "notilt");
    const double straight[3] = {0, 0, dz};
    REQUIRE(write_stack(dir, "1.2.3.61", k_axial, o, straight, NS, NULL, 0, NULL) == 0);
    REQUIRE(vxl_dicom_list_series(dir, &s, 1, &n) == VXL_OK);
    CHECK(s.loadable && s.gantry_tilt_deg == 0);
}

/* A series with a stray image (a localizer of another size) keeps the
 * majority and says what it left out; equal numbers are refused; other
 * mismatches, a damaged JPEG frame and a classic multi-frame file without
 * spacing are handled as the notes and errors say. */
TEST(localizers_mixed_sizes_damaged_jpeg_and_classic_multiframe)
{
    char dir[256], p[512];
    uint16_t px[NC * NR * 2] = {0};
    vxl_volume_info info;
    folder(dir, sizeof dir, "mixed");
    for (int k = 0; k < 3; k++) {
        dcmw_slice d = dcmw_axial("1.2.3.70", NC, k == 1 ? NR + 1 : NR, 2.0 * k, px, NC * (k == 1 ? NR + 1 : NR) * 2);
        snprintf(p, sizeof p, "%s/%d.dcm", dir, k);
        REQUIRE(dcmw_write(p, &d) == 0);
    }
    vxl_volume *v = load_series(dir, NULL);
    CHECKF(v && v->dims[2] == 2 && fabs(v->spacing[2] - 4) < 1e-9, "%s", v ? "wrong size" : vxl_last_error());
    const char *notes = v ? volume_notes(v, &info) : "";
    CHECKF(contains(notes, "left out 1 image") && contains(notes, "'1.dcm' (4x4)"), "%s", notes);
    vxl_volume_destroy(v);

    folder(dir, sizeof dir, "tie");
    for (int k = 0; k < 4; k++) {
        dcmw_slice d = dcmw_axial("1.2.3.74", NC, k % 2 ? NR + 1 : NR, 2.0 * k, px, NC * (k % 2 ? NR + 1 : NR) * 2);
        snprintf(p, sizeof p, "%s/%d.dcm", dir, k);
        REQUIRE(dcmw_write(p, &d) == 0);
    }
    CHECK(load_series(dir, NULL) == NULL);
    CHECKF(contains(vxl_last_error(), "no majority") && contains(vxl_last_error(), "4x3") &&
           contains(vxl_last_error(), "4x4"), "%s", vxl_last_error());

    folder(dir, sizeof dir, "spacing");
    for (int k = 0; k < 2; k++) {
        dcmw_slice d = dcmw_axial("1.2.3.73", NC, NR, 2.0 * k, px, NC * NR * 2);
        d.ps[1] = k ? 0.5 : 1.0;
        snprintf(p, sizeof p, "%s/%d.dcm", dir, k);
        REQUIRE(dcmw_write(p, &d) == 0);
    }
    CHECKF(load_series(dir, NULL) == NULL && contains(vxl_last_error(), "mixed PixelSpacing"), "%s", vxl_last_error());

    /* 17 bytes that are not a JPEG stream: dcmtk's decoder refuses them */
    folder(dir, sizeof dir, "jpeg");
    dcmw_slice d = dcmw_axial("1.2.3.71", NC, NR, 0, px, 17);
    d.transfer_syntax = DCMW_JPEG_BASELINE;
    snprintf(p, sizeof p, "%s/j.dcm", dir);
    REQUIRE(dcmw_write(p, &d) == 0);
    CHECK(load_series(p, NULL) == NULL);
    CHECKF(contains(vxl_last_error(), "j.dcm") && contains(vxl_last_error(), "JPEG Baseline"), "%s",
           vxl_last_error());

    /* two frames, one position, no spacing: stacked 1 mm apart, with a note */
    folder(dir, sizeof dir, "multiframe");
    for (int i = 0; i < NC * NR * 2; i++) px[i] = (uint16_t)i;
    d = dcmw_axial("1.2.3.72", NC, NR, 0, px, sizeof px);
    d.frames = 2;
    snprintf(p, sizeof p, "%s/m.dcm", dir);
    REQUIRE(dcmw_write(p, &d) == 0);
    v = load_series(p, NULL);
    CHECKF(v && v->dims[2] == 2 && fabs(v->spacing[2] - 1) < 1e-9 && fabs(voxel(v, NC * NR) - NC * NR) < 1e-6, "%s",
           v ? "wrong volume" : vxl_last_error());
    notes = v ? volume_notes(v, &info) : "";
    CHECKF(contains(notes, "2 frames stacked along the normal every 1 mm (assumed"), "%s", notes);
    vxl_volume_destroy(v);
}

TEST(truncated_garbage_and_oversized_files_are_refused)
{
    char dir[256], p[512];
    folder(dir, sizeof dir, "trunc");
    uint16_t px[NC * NR] = {0};
    dcmw_slice d = dcmw_axial("1.2.3.80", NC, NR, 0, px, sizeof px);
    unsigned char buf[4096];
    size_t n = dcmw_encode(&d, buf, sizeof buf);
    REQUIRE(n > 64);
    /* cut inside the pixel data, and inside the header */
    const size_t cuts[] = {n - 7, n / 2, 140, 100};
    for (size_t c = 0; c < sizeof cuts / sizeof cuts[0]; c++) {
        snprintf(p, sizeof p, "%s/cut%zu.dcm", dir, c);
        FILE *f = fopen(p, "wb");
        REQUIRE(f);
        fwrite(buf, 1, cuts[c], f);
        fclose(f);
        vxl_volume *v = NULL;
        int rc = load_dicom_with(p, NULL, &v);
        CHECKF(rc != VXL_OK && !v && contains(vxl_last_error(), "cut"), "cut at %zu: rc %d: %s", cuts[c], rc,
               vxl_last_error());
        unlink(p);
    }
    /* a pixel element shorter than rows*cols says so */
    d.pixel_bytes = sizeof px - 6;
    snprintf(p, sizeof p, "%s/short.dcm", dir);
    REQUIRE(dcmw_write(p, &d) == 0);
    CHECK(load_series(p, NULL) == NULL && contains(vxl_last_error(), "PixelData"));
    unlink(p);

    folder(dir, sizeof dir, "garbage");
    snprintf(p, sizeof p, "%s/noise.dcm", dir);
    FILE *f = fopen(p, "wb");
    REQUIRE(f);
    for (int i = 0; i < 3000; i++) fputc((i * 7919) & 0xFF, f);
    fclose(f);
    CHECK(load_series(p, NULL) == NULL && contains(vxl_last_error(), "noise.dcm"));
    /* a folder without any DICOM image */
    CHECK(vxl_dicom_list_series(dir, NULL, 0, &(uint32_t){0}) != VXL_OK);

    /* sizes are checked against the budget before pixels are read */
    folder(dir, sizeof dir, "big");
    d = dcmw_axial("1.2.3.81", 4096, 4096, 0, px, sizeof px); /* header says 4096^2, pixels absent */
    snprintf(p, sizeof p, "%s/big.dcm", dir);
    REQUIRE(dcmw_write(p, &d) == 0);
    vxl_load_options opt = {.struct_size = sizeof opt, .memory_budget_bytes = 1u << 20};
    vxl_volume *v = NULL;
    CHECK(load_dicom_with(p, &opt, &v) == VXL_ERR_LIMIT && !v && contains(vxl_last_error(), "memory budget"));
}

TEST(dispatch_finds_dicom_folders_files_and_dicomdir)
{
    char dir[256], p[512];
    folder(dir, sizeof dir, "dispatch");
    char sub[300];
    snprintf(sub, sizeof sub, "%s/SE0", dir);
    mkdir(sub, 0755);
    const double o[3] = {0, 0, 0}, step[3] = {0, 0, 3};
    REQUIRE(write_stack(sub, "1.2.3.90", k_axial, o, step, NS, NULL, 0, NULL) == 0);
    /* a DICOMDIR at the top: the tree under it is searched */
    snprintf(p, sizeof p, "%s/DICOMDIR", dir);
    FILE *f = fopen(p, "wb");
    REQUIRE(f);
    fputs("not parsed: the folder under it is searched", f);
    fclose(f);
    vxl_volume *v = load_series(p, NULL);
    CHECKF(v && v->dims[2] == NS, "%s", vxl_last_error());
    vxl_volume_destroy(v);
    v = load_series(dir, NULL); /* the folder holding the DICOMDIR */
    CHECK(v && v->dims[2] == NS && fabs(v->spacing[2] - 3) < 1e-9);
    vxl_volume_destroy(v);
    /* a file of frames asked for frame 1: a DICOM series has one */
    vxl_load_options opt = {.struct_size = sizeof opt, .frame = 1};
    CHECK(load_dicom_with(sub, &opt, &v) == VXL_ERR_INVALID_ARGUMENT && contains(vxl_last_error(), "has 1"));
}

/* A 64 x 48 x 5 series of 16-bit (or signed 8-bit) values over the whole
 * range, smooth and noisy in turns, so every predictor and code length is
 * used; file IMkkkk.dcm per slice. */
#define CW 64
#define CH 48
static int write_busy_series(const char *dir, const char *uid, int eight_bit)
{
    static uint16_t px[CW * CH];
    uint32_t x = 12345;
    for (int k = 0; k < NS; k++) {
        for (int j = 0; j < CH; j++)
            for (int i = 0; i < CW; i++) {
                x = x * 1103515245u + 12345u;
                const unsigned smooth = (unsigned)(i * 900 + j * 400 + k * 5000);
                const unsigned v = (j / 8 + k) % 2 ? smooth : (x >> 8);
                px[i + CW * j] = (uint16_t)(eight_bit ? (v >> 8) & 0xFF : v);
            }
        dcmw_slice d = dcmw_axial(uid, CW, CH, 2.0 * k, px, CW * CH * (eight_bit ? 1u : 2u));
        if (eight_bit) {
            static uint8_t px8[CW * CH];
            for (int n = 0; n < CW * CH; n++) px8[n] = (uint8_t)px[n];
            d.pixels = px8;
            d.bits_alloc = 8;
            d.pixel_rep = 1;
        }
        d.instance = k;
        char p[512];
        snprintf(p, sizeof p, "%s/IM%04d.dcm", dir, k);
        if (dcmw_write(p, &d)) return -1;
    }
    return 0;
}

/* Every file of src compressed by `tool` (a dcmtk command: its encoders are
 * independent of our decoders) into a fresh folder g_dir/name. */
static int compress_series(const char *src, const char *name, const char *tool, char *out, size_t n)
{
    return convert_series(g_dir, src, NS, name, tool, out, n);
}

/* The same series in RLE Lossless and in JPEG Lossless (SV1, every other
 * predictor, a frame split over several fragments), as dcmtk's own
 * encoders write them, reads voxel for voxel as the uncompressed files:
 * our decoders (io/dicom_rle.c, io/dicom_jpeg_lossless.c) against
 * independent encoders, for 16-bit unsigned and 8-bit signed pixels. */
TEST(lossless_compressed_series_read_as_the_uncompressed_one)
{
    static const char *const variants[][2] = {
        {"rle", "dcmcrle"},
        {"jpeg_sv1", "dcmcjpeg"},
        {"jpeg_sv1_fragments", "dcmcjpeg +fs 1"},
        {"jpeg_sv2", "dcmcjpeg +el +sv 2"},
        {"jpeg_sv3", "dcmcjpeg +el +sv 3"},
        {"jpeg_sv4", "dcmcjpeg +el +sv 4"},
        {"jpeg_sv5", "dcmcjpeg +el +sv 5"},
        {"jpeg_sv6", "dcmcjpeg +el +sv 6"},
        {"jpeg_sv7", "dcmcjpeg +el +sv 7"},
    };
    for (int eight = 0; eight < 2; eight++) {
        char src[256], dir[256], name[64];
        snprintf(name, sizeof name, "busy%d", eight);
        folder(src, sizeof src, name);
        REQUIRE(write_busy_series(src, eight ? "1.2.3.96" : "1.2.3.95", eight) == 0);
        vxl_volume *a = load_series(src, NULL);
        REQUIRE(a);
        for (size_t v = 0; v < sizeof variants / sizeof variants[0]; v++) {
            snprintf(name, sizeof name, "%s_%d", variants[v][0], eight);
            REQUIRE(compress_series(src, name, variants[v][1], dir, sizeof dir) == 0);
            vxl_volume *b = load_series(dir, NULL);
            CHECKF(b && same_volume(a, b), "%s, %s pixels: %s", variants[v][1], eight ? "8-bit" : "16-bit",
                   b ? "voxels differ" : vxl_last_error());
            vxl_volume_destroy(b);
        }
        vxl_volume_destroy(a);
    }
}

/* A damaged frame is one clear line naming the file: an RLE header claiming
 * 3 segments for 2-byte pixels; a JPEG frame cut inside its scan. */
TEST(damaged_compressed_frames_are_clear_errors)
{
    char src[256], dir[256], p[512];
    folder(src, sizeof src, "damage_source");
    REQUIRE(write_busy_series(src, "1.2.3.97", 0) == 0);
    REQUIRE(compress_series(src, "damaged_rle", "dcmcrle", dir, sizeof dir) == 0);
    snprintf(p, sizeof p, "%s/IM0000.dcm", dir);
    size_t n = 0;
    unsigned char *f = read_all(p, &n);
    REQUIRE(f);
    static const unsigned char header[8] = {2, 0, 0, 0, 64, 0, 0, 0}; /* 2 segments, the first at 64 */
    unsigned char *at = NULL;
    for (size_t i = 0; i + 8 <= n && !at; i++)
        if (!memcmp(f + i, header, 8)) at = f + i;
    REQUIRE(at);
    at[0] = 3;
    REQUIRE(write_all(p, f, n) == 0);
    free(f);
    CHECK(load_series(dir, NULL) == NULL);
    CHECKF(contains(vxl_last_error(), "IM0000.dcm") && contains(vxl_last_error(), "3 segments"), "%s",
           vxl_last_error());

    /* the scan's second half zeroed: the codes then run into nonsense or past the data */
    REQUIRE(compress_series(src, "damaged_jpeg", "dcmcjpeg", dir, sizeof dir) == 0);
    snprintf(p, sizeof p, "%s/IM0002.dcm", dir);
    f = read_all(p, &n);
    REQUIRE(f);
    static const unsigned char sos[2] = {0xFF, 0xDA};
    unsigned char *scan = NULL;
    for (size_t i = 0; i + 2 <= n && !scan; i++)
        if (!memcmp(f + i, sos, 2)) scan = f + i;
    REQUIRE(scan);
    const size_t from = (size_t)(scan - f) + 16, to = n - 8;
    REQUIRE(to > from);
    for (size_t i = from + (to - from) / 2; i < to; i++) f[i] = 0xFF; /* fill bytes, then no EOI: cut short */
    REQUIRE(write_all(p, f, n) == 0);
    free(f);
    CHECK(load_series(dir, NULL) == NULL);
    CHECKF(contains(vxl_last_error(), "IM0002.dcm") && contains(vxl_last_error(), "JPEG"), "%s", vxl_last_error());
}

OWN_PARSER_TEST

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_dicom_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(oblique_shuffled_series_gets_its_affine_and_spacing_from_positions);
    RUN(rescale_slope_intercept_gives_hounsfield_units);
    RUN(signed_8_bit_and_bits_stored_below_bits_allocated);
    RUN(several_series_are_listed_and_one_is_chosen_by_index_or_uid);
    RUN(missing_slice_is_interpolated_with_a_note);
    RUN(time_points_at_every_position_make_a_4d_series);
    RUN(gantry_tilt_loads_with_a_sheared_affine_and_is_reported);
    RUN(localizers_mixed_sizes_damaged_jpeg_and_classic_multiframe);
    RUN(truncated_garbage_and_oversized_files_are_refused);
    RUN(dispatch_finds_dicom_folders_files_and_dicomdir);
    RUN(lossless_compressed_series_read_as_the_uncompressed_one);
    RUN(damaged_compressed_frames_are_clear_errors);
    RUN(own_parser_agrees_with_dcmtk);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
