/* test_nifti.c - the NIfTI reader, through the public API.
 *
 * Files are written by tests/nifti_writer.h (which knows the format
 * independently of csrc/io/nifti.c) into a mkdtemp directory that is removed at
 * the end. Voxel values are checked through the volume's texels (layout from
 * volume.h) so byte-order or offset mistakes show up as wrong values, not
 * just as a wrong min/max. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "loader_test_util.h"
#include "nifti_writer.h"
#include "volume.h"
#include "voxlight.h"

#define REAL_FILE "/usr/share/mricron/templates/ch2better.nii.gz"

static char g_dir[64];

static const char *tmp(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
    return buf;
}

static void remove_tmp_dir(void)
{
    DIR *d = opendir(g_dir);
    if (!d) return;
    struct dirent *ent;
    char p[512];
    while ((ent = readdir(d)) != NULL) {
        if (!strcmp(ent->d_name, ".") || !strcmp(ent->d_name, "..")) continue;
        snprintf(p, sizeof p, "%s/%s", g_dir, ent->d_name);
        unlink(p);
    }
    closedir(d);
    rmdir(g_dir);
}

/* ------------------------------------------------------------- datatypes */

typedef struct dtype_case {
    int nifti;
    uint32_t vxl;
    double lo, hi; /* range of the test pattern: the type's extremes for ints */
    const char *name;
} dtype_case;

static const dtype_case k_dtypes[] = {
    {2, VXL_DTYPE_U8, 0, 255, "u8"},
    {256, VXL_DTYPE_I8, -128, 127, "i8"},
    {4, VXL_DTYPE_I16, -32768, 32767, "i16"},
    {512, VXL_DTYPE_U16, 0, 65535, "u16"},
    {8, VXL_DTYPE_I32, -2147483648.0, 2147483647.0, "i32"},
    {768, VXL_DTYPE_U32, 0, 4294967295.0, "u32"},
    {16, VXL_DTYPE_F32, -1234.5, 98765.25, "f32"},
    {64, VXL_DTYPE_F64, -1.5e12, 3.25e11, "f64"},
};
#define N_DTYPES (sizeof k_dtypes / sizeof k_dtypes[0])

static void put_value(void *buf, int dt, size_t i, double v)
{
    switch (dt) {
    case 2: ((uint8_t *)buf)[i] = (uint8_t)v; break;
    case 256: ((int8_t *)buf)[i] = (int8_t)v; break;
    case 4: ((int16_t *)buf)[i] = (int16_t)v; break;
    case 512: ((uint16_t *)buf)[i] = (uint16_t)v; break;
    case 8: ((int32_t *)buf)[i] = (int32_t)v; break;
    case 768: ((uint32_t *)buf)[i] = (uint32_t)v; break;
    case 16: ((float *)buf)[i] = (float)v; break;
    case 64: ((double *)buf)[i] = v; break;
    default: break;
    }
}

static double get_value(const void *buf, int dt, size_t i)
{
    switch (dt) {
    case 2: return ((const uint8_t *)buf)[i];
    case 256: return ((const int8_t *)buf)[i];
    case 4: return ((const int16_t *)buf)[i];
    case 512: return ((const uint16_t *)buf)[i];
    case 8: return ((const int32_t *)buf)[i];
    case 768: return ((const uint32_t *)buf)[i];
    case 16: return ((const float *)buf)[i];
    case 64: return ((const double *)buf)[i];
    default: return 0;
    }
}

/* A scrambled ramp over [lo, hi] that hits both ends exactly: 7 is coprime
 * with the voxel counts used, so k runs over every step once. */
static void fill_pattern(void *buf, const dtype_case *c, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        size_t k = (i * 7) % n;
        double v = c->lo + (c->hi - c->lo) * (double)k / (double)(n - 1);
        if (c->nifti != 16 && c->nifti != 64) v = floor(v + 0.5);
        if (k == n - 1) v = c->hi;
        put_value(buf, c->nifti, i, v);
    }
}

/* The data value voxel i decodes to, from the stored texture. */
static double texel_value(const vxl_volume *v, size_t i)
{
    double t;
    if (v->texture_bits == 8) t = ((const uint8_t *)v->texels)[i] / 255.0;
    else if (v->texture_bits == 16) t = ((const uint16_t *)v->texels)[i] / 65535.0;
    else t = ((const float *)v->texels)[i];
    return v->tex_lo + t * (v->tex_hi - v->tex_lo);
}

/* Checks every voxel of v against the native data the file was written
 * from; tolerance is relative to the span (float textures are 24-bit). */
static int values_match(const vxl_volume *v, const void *data, int dt, size_t n, double lo, double hi)
{
    double tol = (hi - lo) * (v->texture_bits == 32 ? 1e-6 : 1e-9) + 1e-12;
    for (size_t i = 0; i < n; i++) {
        double want = get_value(data, dt, i);
        double got = texel_value(v, i);
        if (!(fabs(got - want) <= tol)) {
            fprintf(stderr, "    voxel %zu: got %.17g, want %.17g\n", i, got, want);
            return 0;
        }
    }
    return 1;
}

static const char *const k_forms[] = {".nii", ".nii.gz", ".hdr", ".hdr.gz"};

/* Writes data as a 5x4x3 volume with non-unit spacing, loads it back and
 * compares everything the reader is responsible for. */
static void roundtrip_check(vxl_test_ctx *T_, const dtype_case *c, int version, int swap, const char *form,
                            const void *data, size_t N)
{
    enum { NX = 5, NY = 4, NZ = 3 };
    tnw_header h;
    tnw_init(&h, version, c->nifti, NX, NY, NZ);
    h.swap = swap;
    h.pixdim[1] = 0.5; h.pixdim[2] = 2.0; h.pixdim[3] = 3.0;
    char name[64], path[256];
    snprintf(name, sizeof name, "rt_%s_v%d_s%d%s", c->name, version, swap, form);
    tmp(path, sizeof path, name);
    REQUIRE(tnw_write(path, &h, data, N * tnw_dtype_size(c->nifti)) == 0);

    vxl_volume *v = NULL;
    int rc = vxl_volume_load(path, NULL, &v);
    CHECKF(rc == VXL_OK, "%s: rc %d: %s", name, rc, vxl_last_error());
    if (rc != VXL_OK) return;
    vxl_volume_info info;
    REQUIRE(vxl_volume_get_info(v, &info) == VXL_OK);
    CHECKF(info.dims[0] == NX && info.dims[1] == NY && info.dims[2] == NZ, "%s: dims %ux%ux%u", name,
           info.dims[0], info.dims[1], info.dims[2]);
    CHECKF(info.dtype == c->vxl, "%s: dtype %u", name, info.dtype);
    CHECKF(info.nifti_version == (uint32_t)version, "%s: version %u", name, info.nifti_version);
    double want_min = get_value(data, c->nifti, 0), want_max = want_min;
    for (size_t i = 0; i < N; i++) {
        double x = get_value(data, c->nifti, i);
        want_min = x < want_min ? x : want_min;
        want_max = x > want_max ? x : want_max;
    }
    CHECKF(info.value_min == want_min && info.value_max == want_max, "%s: range %.17g..%.17g want %.17g..%.17g",
           name, info.value_min, info.value_max, want_min, want_max);
    CHECKF(values_match(v, data, c->nifti, N, want_min, want_max), "%s: voxel values", name);
    CHECK(info.nan_count == 0 && info.inf_count == 0);
    CHECKF(info.spacing[0] == 0.5 && info.spacing[1] == 2.0 && info.spacing[2] == 3.0, "%s", name);
    CHECK(info.affine_source == 0);
    CHECK(info.affine[0] == 0.5 && info.affine[5] == 2.0 && info.affine[10] == 3.0 && info.affine[15] == 1.0);
    vxl_volume_destroy(v);
}

/* One case of the round trip, with a scrambled full-range pattern. */
static void roundtrip_one(vxl_test_ctx *T_, const dtype_case *c, int version, int swap, const char *form)
{
    enum { NX = 5, NY = 4, NZ = 3, N = NX * NY * NZ };
    /* allocated (not a double[]) so storing any type in it is well defined */
    void *data = malloc(N * sizeof(double));
    REQUIRE(data);
    fill_pattern(data, c, N);
    roundtrip_check(T_, c, version, swap, form, data, N);
    free(data);
}

TEST(every_dtype_roundtrips_in_every_form_order_and_version)
{
    for (size_t d = 0; d < N_DTYPES; d++)
        for (int version = 1; version <= 2; version++)
            for (int swap = 0; swap <= 1; swap++)
                for (size_t f = 0; f < sizeof k_forms / sizeof k_forms[0]; f++)
                    roundtrip_one(T_, &k_dtypes[d], version, swap, k_forms[f]);
}

/* Small helper: write h + data at name, load, return rc; *v on success. */
static int write_and_load(const char *name, const tnw_header *h, const void *data, size_t bytes,
                          const vxl_load_options *opt, vxl_volume **v)
{
    char path[256];
    tmp(path, sizeof path, name);
    *v = NULL;
    if (tnw_write(path, h, data, bytes) != 0) return -1;
    return vxl_volume_load(path, opt, v);
}

static int load_info(const char *name, const tnw_header *h, const void *data, size_t bytes,
                     vxl_volume_info *info)
{
    vxl_volume *v;
    int rc = write_and_load(name, h, data, bytes, NULL, &v);
    if (rc == VXL_OK) {
        vxl_volume_get_info(v, info);
        vxl_volume_destroy(v);
    }
    return rc;
}

TEST(pair_loads_from_hdr_or_img_path_and_mixed_compression)
{
    uint16_t data[24];
    for (int i = 0; i < 24; i++) data[i] = (uint16_t)(1000 + 37 * i);
    tnw_header h;
    tnw_init(&h, 1, 512, 4, 3, 2);
    h.swap = 1;
    char hdr[256], img[256], imggz[256];
    REQUIRE(tnw_write(tmp(hdr, sizeof hdr, "pair.hdr.gz"), &h, data, sizeof data) == 0);
    const char *paths[] = {hdr, tmp(img, sizeof img, "pair.img.gz")};
    for (int p = 0; p < 2; p++) {
        vxl_volume *v = NULL;
        int rc = vxl_volume_load(paths[p], NULL, &v);
        CHECKF(rc == VXL_OK, "%s: %s", paths[p], vxl_last_error());
        if (rc) continue;
        CHECK(v->dims[0] == 4 && v->dims[1] == 3 && v->dims[2] == 2);
        CHECK(values_match(v, data, 512, 24, 1000, 1000 + 37 * 23));
        vxl_volume_destroy(v);
    }

    /* plain .hdr with a gzipped .img (tools that compress only the image) */
    REQUIRE(tnw_write(tmp(hdr, sizeof hdr, "mix.hdr"), &h, data, sizeof data) == 0);
    size_t n;
    unsigned char *raw = read_all(tmp(img, sizeof img, "mix.img"), &n);
    REQUIRE(raw);
    REQUIRE(tnw_write_file(tmp(imggz, sizeof imggz, "mix.img.gz"), 1, raw, n, NULL, 0) == 0);
    free(raw);
    unlink(img);
    vxl_volume *v = NULL;
    int rc = vxl_volume_load(hdr, NULL, &v);
    CHECKF(rc == VXL_OK, "%s", vxl_last_error());
    if (!rc) CHECK(values_match(v, data, 512, 24, 1000, 1000 + 37 * 23));
    vxl_volume_destroy(v);

    /* pair vox_offset is an offset into the .img */
    h.vox_offset = 64;
    h.version = 2;
    rc = write_and_load("off.hdr", &h, data, sizeof data, NULL, &v);
    CHECKF(rc == VXL_OK, "%s", vxl_last_error());
    if (!rc) CHECK(values_match(v, data, 512, 24, 1000, 1000 + 37 * 23));
    vxl_volume_destroy(v);
}

TEST(vox_offset_with_extension_bytes_is_honoured)
{
    float data[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    for (int version = 1; version <= 2; version++) {
        tnw_header h;
        tnw_init(&h, version, 16, 2, 2, 2);
        h.vox_offset = 1024; /* e.g. a NIfTI extension in between */
        vxl_volume *v = NULL;
        int rc = write_and_load(version == 1 ? "ext1.nii.gz" : "ext2.nii", &h, data, sizeof data, NULL, &v);
        CHECKF(rc == VXL_OK, "%s", vxl_last_error());
        if (!rc) CHECK(values_match(v, data, 16, 8, 1, 8));
        vxl_volume_destroy(v);
    }
}

/* -------------------------------------------------------------- scaling */

TEST(slope_and_intercept_are_applied)
{
    int16_t data[4] = {-100, 0, 50, 200};
    struct { int version; double slope, inter, min, max; } cases[] = {
        {1, 2.0, -10.0, -210.0, 390.0},
        {2, 2.0, -10.0, -210.0, 390.0},
        {1, -0.5, 3.0, -97.0, 53.0},   /* negative slope flips the range */
        {2, -0.5, 3.0, -97.0, 53.0},
        {1, 0.0, 5.0, -100.0, 200.0},  /* slope 0: unscaled, inter ignored */
        {1, NAN, 5.0, -100.0, 200.0},  /* NaN slope: unscaled, not an error */
        {2, INFINITY, 5.0, -100.0, 200.0},
        {2, 3.0, NAN, -300.0, 600.0},  /* NaN intercept with a usable slope: 0 */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        tnw_header h;
        tnw_init(&h, cases[i].version, 4, 4, 1, 1);
        h.swap = (int)(i & 1);
        h.scl_slope = cases[i].slope;
        h.scl_inter = cases[i].inter;
        vxl_volume_info info;
        int rc = load_info("scale.nii", &h, data, sizeof data, &info);
        CHECKF(rc == VXL_OK, "case %zu: %s", i, vxl_last_error());
        if (rc) continue;
        CHECKF(fabs(info.value_min - cases[i].min) < 1e-9 && fabs(info.value_max - cases[i].max) < 1e-9,
               "case %zu: range %g..%g, want %g..%g", i, info.value_min, info.value_max, cases[i].min,
               cases[i].max);
    }

    /* u8 with a fractional slope in NIfTI-2 (doubles) */
    uint8_t u[3] = {0, 255, 7};
    tnw_header h;
    tnw_init(&h, 2, 2, 3, 1, 1);
    h.scl_slope = 0.25;
    h.scl_inter = 1.0;
    vxl_volume_info info;
    REQUIRE(load_info("scale_u8.nii.gz", &h, u, sizeof u, &info) == VXL_OK);
    CHECK(info.value_min == 1.0 && info.value_max == 64.75);
}

TEST(nan_and_inf_voxels_are_counted)
{
    float data[8] = {1.0f, NAN, 2.0f, INFINITY, -INFINITY, NAN, -3.0f, 5.0f};
    for (int swap = 0; swap <= 1; swap++) {
        tnw_header h;
        tnw_init(&h, 1, 16, 4, 2, 1);
        h.swap = swap;
        vxl_volume_info info;
        int rc = load_info(swap ? "nan_s.nii.gz" : "nan.nii", &h, data, sizeof data, &info);
        REQUIRE(rc == VXL_OK);
        CHECKF(info.nan_count == 2, "nan_count %llu", (unsigned long long)info.nan_count);
        CHECKF(info.inf_count == 2, "inf_count %llu", (unsigned long long)info.inf_count);
        CHECK(info.value_min == -3.0 && info.value_max == 5.0);
    }
    /* f64 too */
    double d[4] = {NAN, 1.0, -INFINITY, 2.0};
    tnw_header h;
    tnw_init(&h, 2, 64, 2, 2, 1);
    vxl_volume_info info;
    REQUIRE(load_info("nan64.nii", &h, d, sizeof d, &info) == VXL_OK);
    CHECK(info.nan_count == 1 && info.inf_count == 1);
    CHECK(info.value_min == 1.0 && info.value_max == 2.0);
}

/* --------------------------------------------------------------- affine */

static int affine_close(const double *got, const double want_rowmajor[3][4], double tol)
{
    int ok = 1;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            if (!(fabs(got[c * 4 + r] - want_rowmajor[r][c]) <= tol)) ok = 0;
    if (got[3] != 0 || got[7] != 0 || got[11] != 0 || got[15] != 1) ok = 0;
    if (!ok) {
        for (int r = 0; r < 4; r++)
            fprintf(stderr, "    [%9.5f %9.5f %9.5f %9.5f]\n", got[r], got[4 + r], got[8 + r], got[12 + r]);
    }
    return ok;
}

static const uint8_t k_cube[8] = {1, 2, 3, 4, 5, 6, 7, 8};

TEST(qform_90_degrees_about_z_with_qfac_minus_one)
{
    for (int version = 1; version <= 2; version++) {
        tnw_header h;
        tnw_init(&h, version, 2, 2, 2, 2);
        h.pixdim[0] = -1; /* qfac */
        h.pixdim[1] = 2; h.pixdim[2] = 3; h.pixdim[3] = 4;
        h.qform_code = 1;
        h.quatern[2] = sqrt(0.5); /* d = sin(45 deg): 90 degrees about z */
        h.qoffset[0] = 10; h.qoffset[1] = -20; h.qoffset[2] = 30;
        h.swap = version == 2;
        vxl_volume_info info;
        REQUIRE(load_info("qform.nii", &h, k_cube, sizeof k_cube, &info) == VXL_OK);
        /* R = [[0,-1,0],[1,0,0],[0,0,1]], columns scaled by 2,3,4, z negated */
        const double want[3][4] = {{0, -3, 0, 10}, {2, 0, 0, -20}, {0, 0, -4, 30}};
        CHECKF(affine_close(info.affine, want, version == 1 ? 1e-5 : 1e-12), "version %d", version);
        CHECK(info.affine_source == 1);
        CHECK(info.spacing[0] == 2 && info.spacing[1] == 3 && info.spacing[2] == 4);
    }
}

TEST(qform_180_degrees_about_x_uses_the_a_equals_zero_branch)
{
    tnw_header h;
    tnw_init(&h, 2, 2, 2, 2, 2);
    h.qform_code = 2;
    h.quatern[0] = 1.0; /* b = 1: a = 0 */
    h.qoffset[0] = 1; h.qoffset[1] = 2; h.qoffset[2] = 3;
    vxl_volume_info info;
    REQUIRE(load_info("q180.nii", &h, k_cube, sizeof k_cube, &info) == VXL_OK);
    const double want[3][4] = {{1, 0, 0, 1}, {0, -1, 0, 2}, {0, 0, -1, 3}};
    CHECK(affine_close(info.affine, want, 1e-12));
    CHECK(info.affine_source == 1);
}

/* Rotation by angle about a unit axis (Rodrigues), an independent way to
 * get the matrix a quaternion (cos(angle/2), sin(angle/2) * axis) means. */
static void rodrigues(const double u[3], double angle, double R[3][3])
{
    double c = cos(angle), s = sin(angle);
    double K[3][3] = {{0, -u[2], u[1]}, {u[2], 0, -u[0]}, {-u[1], u[0], 0}};
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) R[r][k] = (r == k ? c : 0) + s * K[r][k] + (1 - c) * u[r] * u[k];
}

TEST(qform_general_rotation_matches_rodrigues)
{
    double u[3] = {1, -2, 3}, norm = sqrt(14.0), angle = 70.0 * M_PI / 180.0;
    for (int i = 0; i < 3; i++) u[i] /= norm;
    double R[3][3];
    rodrigues(u, angle, R);
    const double sp[3] = {0.75, 1.5, 2.25};
    for (int version = 1; version <= 2; version++)
        for (int qfac = -1; qfac <= 1; qfac += 2) {
            tnw_header h;
            tnw_init(&h, version, 2, 2, 2, 2);
            h.qform_code = 1;
            h.pixdim[0] = qfac;
            for (int i = 0; i < 3; i++) {
                h.pixdim[i + 1] = sp[i];
                h.quatern[i] = sin(angle / 2) * u[i];
                h.qoffset[i] = 5.0 * (i + 1);
            }
            vxl_volume_info info;
            REQUIRE(load_info("qgen.nii", &h, k_cube, sizeof k_cube, &info) == VXL_OK);
            double want[3][4];
            for (int r = 0; r < 3; r++) {
                for (int k = 0; k < 3; k++) want[r][k] = R[r][k] * sp[k] * (k == 2 ? qfac : 1);
                want[r][3] = 5.0 * (r + 1);
            }
            CHECKF(affine_close(info.affine, want, version == 1 ? 2e-6 : 1e-12), "version %d qfac %d", version,
                   qfac);
            CHECK(info.affine_source == 1);
        }

    /* |(b,c,d)| a hair over 1 (float rounding in real files): the standard
     * renormalises to a 180 degree turn, R = 2uu^T - I, rather than NaN. */
    tnw_header h;
    tnw_init(&h, 2, 2, 2, 2, 2);
    h.qform_code = 1;
    h.quatern[0] = 0.6;
    h.quatern[1] = 0.8000001;
    vxl_volume_info info;
    REQUIRE(load_info("q_over.nii", &h, k_cube, sizeof k_cube, &info) == VXL_OK);
    double n = sqrt(0.36 + 0.8000001 * 0.8000001), w[3] = {0.6 / n, 0.8000001 / n, 0};
    double want[3][4] = {{0}};
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) want[r][k] = 2 * w[r] * w[k] - (r == k);
    CHECK(affine_close(info.affine, want, 1e-12));
    CHECK(info.affine_source == 1);
}

TEST(sform_wins_over_qform)
{
    const double srow[3][4] = {{0.5, 0.125, 0, -5}, {0, -2, 0, 7}, {0.25, 0, 3, 9}};
    for (int version = 1; version <= 2; version++) {
        tnw_header h;
        tnw_init(&h, version, 2, 2, 2, 2);
        h.qform_code = 1;
        h.quatern[0] = 1.0;
        h.sform_code = 4;
        memcpy(h.srow, srow, sizeof srow);
        h.swap = version == 1;
        vxl_volume_info info;
        REQUIRE(load_info(version == 1 ? "sform1.nii.gz" : "sform2.hdr", &h, k_cube, sizeof k_cube, &info) ==
                VXL_OK);
        CHECK(affine_close(info.affine, srow, 0)); /* all exactly representable */
        CHECK(info.affine_source == 2);
    }
}

TEST(unusable_sform_falls_back_and_no_transform_gives_spacing)
{
    tnw_header h;
    vxl_volume_info info;
    /* sform code set but rows left zero (seen in the wild) -> qform */
    tnw_init(&h, 1, 2, 2, 2, 2);
    h.sform_code = 1;
    h.qform_code = 1;
    h.quatern[0] = 1.0;
    REQUIRE(load_info("zero_sform.nii", &h, k_cube, sizeof k_cube, &info) == VXL_OK);
    CHECK(info.affine_source == 1);
    const double q180[3][4] = {{1, 0, 0, 0}, {0, -1, 0, 0}, {0, 0, -1, 0}};
    CHECK(affine_close(info.affine, q180, 1e-6));

    /* NaN in the sform, no qform -> spacing */
    tnw_init(&h, 2, 2, 2, 2, 2);
    h.sform_code = 1;
    h.srow[0][0] = NAN; h.srow[1][1] = 1; h.srow[2][2] = 1;
    REQUIRE(load_info("nan_sform.nii", &h, k_cube, sizeof k_cube, &info) == VXL_OK);
    CHECK(info.affine_source == 0);
    for (int i = 0; i < 16; i++) CHECK(isfinite(info.affine[i]));

    /* no transform: diag(|pixdim|); 0 and NaN pixdim mean 1 */
    tnw_init(&h, 1, 2, 2, 2, 2);
    h.pixdim[1] = -2.5; h.pixdim[2] = NAN; h.pixdim[3] = 0;
    REQUIRE(load_info("plain.nii", &h, k_cube, sizeof k_cube, &info) == VXL_OK);
    const double diag[3][4] = {{2.5, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
    CHECK(affine_close(info.affine, diag, 0));
    CHECK(info.spacing[0] == 2.5 && info.spacing[1] == 1 && info.spacing[2] == 1);
    CHECK(info.affine_source == 0);
    h.pixdim[1] = INFINITY; h.pixdim[2] = -INFINITY; h.pixdim[3] = 4;
    REQUIRE(load_info("plain_inf.nii", &h, k_cube, sizeof k_cube, &info) == VXL_OK);
    CHECK(info.spacing[0] == 1 && info.spacing[1] == 1 && info.spacing[2] == 4);
    const double diag2[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 4, 0}};
    CHECK(affine_close(info.affine, diag2, 0));

    /* infinite quaternion parameters: qform unusable -> spacing */
    tnw_init(&h, 2, 2, 2, 2, 2);
    h.qform_code = 1;
    h.quatern[1] = INFINITY;
    REQUIRE(load_info("inf_q.nii", &h, k_cube, sizeof k_cube, &info) == VXL_OK);
    CHECK(info.affine_source == 0);
}

/* ------------------------------------------------------------ dimensions */

TEST(four_d_loads_the_first_volume_and_low_dim_counts_fill_with_one)
{
    enum { N3 = 3 * 2 * 2 };
    uint16_t data[N3 * 3];
    for (int t = 0; t < 3; t++)
        for (int i = 0; i < N3; i++) data[t * N3 + i] = (uint16_t)(1000 * t + i);
    tnw_header h;
    tnw_init(&h, 1, 512, 3, 2, 2);
    h.dim[0] = 4;
    h.dim[4] = 3;
    h.dim[5] = 0; /* beyond dim[0]: ignored */
    vxl_volume *v = NULL;
    int rc = write_and_load("4d.nii.gz", &h, data, sizeof data, NULL, &v);
    REQUIRE(rc == VXL_OK);
    CHECK(v->dims[0] == 3 && v->dims[1] == 2 && v->dims[2] == 2);
    CHECK(v->value_min == 0 && v->value_max == N3 - 1);
    CHECK(values_match(v, data, 512, N3, 0, N3 - 1));
    vxl_volume_destroy(v);

    /* dim[0] = 2: a single slice, whatever dim[3] says */
    tnw_init(&h, 2, 512, 3, 2, 7);
    h.dim[0] = 2;
    rc = write_and_load("2d.nii", &h, data, 6 * sizeof *data, NULL, &v);
    REQUIRE(rc == VXL_OK);
    CHECK(v->dims[0] == 3 && v->dims[1] == 2 && v->dims[2] == 1);
    vxl_volume_destroy(v);

    /* dim[0] = 1 */
    tnw_init(&h, 1, 512, 5, 9, 9);
    h.dim[0] = 1;
    rc = write_and_load("1d.nii", &h, data, 5 * sizeof *data, NULL, &v);
    REQUIRE(rc == VXL_OK);
    CHECK(v->dims[0] == 5 && v->dims[1] == 1 && v->dims[2] == 1);
    vxl_volume_destroy(v);
}

/* --------------------------------------------------------------- errors */

/* Whether msg contains any of the '|'-separated alternatives in needles. */
static int mentions_any(const char *msg, const char *needles)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", needles);
    char *save = NULL;
    for (char *w = strtok_r(buf, "|", &save); w; w = strtok_r(NULL, "|", &save))
        if (strstr(msg, w)) return 1;
    return 0;
}

/* Loads path and checks it fails with code, returns no volume, and says one
 * of the '|'-separated needles (case-sensitive; NULL = anything). */
static void expect_fail_path(vxl_test_ctx *T_, int line, const char *path, const vxl_load_options *opt,
                             int code, const char *needle)
{
    vxl_volume *v = (vxl_volume *)&v; /* non-NULL: the loader must clear it */
    int rc = vxl_volume_load(path, opt, &v);
    const char *msg = vxl_last_error();
    CHECKF(rc == code, "line %d: %s: rc %d, want %d (%s)", line, path, rc, code, msg);
    CHECKF(v == NULL, "line %d: %s: volume returned on failure", line, path);
    if (rc == VXL_OK) vxl_volume_destroy(v);
    if (needle) CHECKF(mentions_any(msg, needle), "line %d: message \"%s\" lacks \"%s\"", line, msg, needle);
}

static void expect_fail(vxl_test_ctx *T_, int line, const char *name, const tnw_header *h, const void *data,
                        size_t bytes, const vxl_load_options *opt, int code, const char *needle)
{
    char path[256];
    tmp(path, sizeof path, name);
    if (tnw_write(path, h, data, bytes) != 0) {
        CHECKF(0, "line %d: cannot write %s", line, path);
        return;
    }
    expect_fail_path(T_, line, path, opt, code, needle);
}

#define EXPECT_FAIL(name, h, data, bytes, opt, code, needle) \
    expect_fail(T_, __LINE__, name, h, data, bytes, opt, code, needle)

static uint16_t g_zeros[4096];

TEST(missing_files_are_io_errors)
{
    char p[256];
    expect_fail_path(T_, __LINE__, "/nonexistent-dir/x.nii", NULL, VXL_ERR_IO, "/nonexistent-dir/x.nii");
    expect_fail_path(T_, __LINE__, tmp(p, sizeof p, "nothing.nii.gz"), NULL, VXL_ERR_IO, "nothing.nii.gz");
    /* .img given but there is no header: name the header looked for */
    expect_fail_path(T_, __LINE__, tmp(p, sizeof p, "orphan.img"), NULL, VXL_ERR_IO, "orphan.hdr");

    /* header present, image missing */
    tnw_header h;
    tnw_init(&h, 1, 2, 4, 4, 4);
    REQUIRE(tnw_write(tmp(p, sizeof p, "lonely.hdr"), &h, g_zeros, 64) == 0);
    char img[256];
    unlink(tmp(img, sizeof img, "lonely.img"));
    expect_fail_path(T_, __LINE__, p, NULL, VXL_ERR_IO, "lonely.img");

    vxl_volume *v;
    CHECK(vxl_volume_load(NULL, NULL, &v) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_volume_load("", NULL, &v) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_volume_load(p, NULL, NULL) == VXL_ERR_INVALID_ARGUMENT);
}

TEST(truncated_files_are_format_errors)
{
    tnw_header h;
    const char *forms[] = {"trunc.nii", "trunc.nii.gz", "trunc.hdr", "trunc.hdr.gz"};
    for (int version = 1; version <= 2; version++)
        for (int f = 0; f < 4; f++) {
            tnw_init(&h, version, 512, 10, 10, 10);
            h.swap = f & 1;
            EXPECT_FAIL(forms[f], &h, g_zeros, 1000, NULL, VXL_ERR_FORMAT, "truncated");
        }
    /* message states expected and actual counts */
    tnw_init(&h, 1, 512, 10, 10, 10);
    EXPECT_FAIL("trunc_msg.nii", &h, g_zeros, 1000, NULL, VXL_ERR_FORMAT, "expected 2000 bytes");
    /* uncompressed files are measured before the voxel buffer is allocated,
     * so a header claiming 1.7 GB over a tiny file costs nothing */
    tnw_init(&h, 1, 2, 1200, 1200, 1200);
    EXPECT_FAIL("trunc_big.nii", &h, g_zeros, 1000, NULL, VXL_ERR_FORMAT, "voxel data at offset 352, got 1000");

    /* vox_offset past the end of the data (but not absurd) */
    tnw_init(&h, 1, 2, 4, 4, 4);
    h.vox_offset = 5e6;
    EXPECT_FAIL("past_end.nii", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "truncated");
    EXPECT_FAIL("past_end.nii.gz", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "truncated");

    /* header cut short, and an empty file */
    char p[256];
    tnw_init(&h, 2, 2, 4, 4, 4);
    REQUIRE(tnw_write(tmp(p, sizeof p, "short_hdr.nii"), &h, g_zeros, 64) == 0);
    REQUIRE(truncate(p, 400) == 0);
    expect_fail_path(T_, __LINE__, p, NULL, VXL_ERR_FORMAT, "truncated header");
    REQUIRE(write_all(tmp(p, sizeof p, "empty.nii"), "", 0) == 0);
    expect_fail_path(T_, __LINE__, p, NULL, VXL_ERR_FORMAT, "not a NIfTI");
    REQUIRE(write_all(tmp(p, sizeof p, "text.nii"), "hello, world\n", 13) == 0);
    expect_fail_path(T_, __LINE__, p, NULL, VXL_ERR_FORMAT, "not a NIfTI");
}

TEST(every_prefix_of_a_file_fails_cleanly)
{
    uint16_t data[24];
    for (int i = 0; i < 24; i++) data[i] = (uint16_t)i;
    for (int version = 1; version <= 2; version++) {
        tnw_header h;
        tnw_init(&h, version, 512, 4, 3, 2);
        char full[256], cut[256];
        REQUIRE(tnw_write(tmp(full, sizeof full, "whole.nii"), &h, data, sizeof data) == 0);
        size_t n;
        unsigned char *bytes = read_all(full, &n);
        REQUIRE(bytes);
        tmp(cut, sizeof cut, "prefix.nii");
        int bad = 0;
        for (size_t len = 0; len < n; len++) {
            vxl_volume *v = NULL;
            if (write_all(cut, bytes, len) != 0) { bad++; continue; }
            int rc = vxl_volume_load(cut, NULL, &v);
            if (rc != VXL_ERR_FORMAT || v) bad++;
            vxl_volume_destroy(v);
        }
        CHECKF(bad == 0, "version %d: %d prefixes did not fail with VXL_ERR_FORMAT", version, bad);
        free(bytes);

        /* gzip streams cut anywhere: never a crash, never another code;
         * cuts inside the voxel data must fail. */
        REQUIRE(tnw_write(tmp(full, sizeof full, "whole.nii.gz"), &h, data, sizeof data) == 0);
        bytes = read_all(full, &n);
        REQUIRE(bytes);
        tmp(cut, sizeof cut, "prefix.nii.gz");
        int odd = 0, failed = 0;
        for (size_t len = 0; len < n; len++) {
            vxl_volume *v = NULL;
            if (write_all(cut, bytes, len) != 0) { odd++; continue; }
            int rc = vxl_volume_load(cut, NULL, &v);
            if (rc == VXL_OK) CHECK(values_match(v, data, 512, 24, 0, 23));
            else if (rc == VXL_ERR_FORMAT && !v) failed++;
            else odd++;
            vxl_volume_destroy(v);
        }
        CHECKF(odd == 0, "version %d: %d gz prefixes gave an unexpected result", version, odd);
        CHECKF(failed >= (int)n - 16, "version %d: only %d of %zu gz prefixes failed", version, failed, n);
        free(bytes);
    }
}

TEST(corrupt_magic_and_headers_are_format_errors)
{
    tnw_header h;
    tnw_init(&h, 1, 2, 4, 4, 4);
    h.patch_at = 344; h.patch_len = 4; memcpy(h.patch, "xyz", 4);
    EXPECT_FAIL("magic1.nii", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "magic");
    memset(h.patch, 0, 4); /* Analyze 7.5: no magic */
    EXPECT_FAIL("analyze.hdr", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "magic");
    memcpy(h.patch, "n+2", 4); /* version 2 magic in a 348-byte header */
    EXPECT_FAIL("magic_mix.nii", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "magic");

    tnw_init(&h, 2, 2, 4, 4, 4);
    h.swap = 1;
    h.patch_at = 8; h.patch_len = 4; memcpy(h.patch, "\n\032\n\0", 4); /* CRLF -> LF damage */
    EXPECT_FAIL("magic2.nii", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "magic");

    /* sizeof_hdr neither 348 nor 540 in either order */
    tnw_init(&h, 1, 2, 4, 4, 4);
    h.patch_at = 0; h.patch_len = 4;
    int32_t s = 349;
    memcpy(h.patch, &s, 4);
    EXPECT_FAIL("sizeof.nii", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "sizeof_hdr");

    /* pair magic in a .nii: there is no .img name to derive */
    tnw_init(&h, 1, 2, 4, 4, 4);
    h.patch_at = 344; h.patch_len = 4; memcpy(h.patch, "ni1", 4);
    EXPECT_FAIL("pairmagic.nii", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, ".img");

    /* corrupt gzip stream (unknown compression method) */
    char p[256];
    tnw_init(&h, 1, 2, 4, 4, 4);
    REQUIRE(tnw_write(tmp(p, sizeof p, "badgz.nii.gz"), &h, g_zeros, 64) == 0);
    size_t n;
    unsigned char *bytes = read_all(p, &n);
    REQUIRE(bytes && n > 10);
    bytes[2] = 9;
    REQUIRE(write_all(p, bytes, n) == 0);
    free(bytes);
    expect_fail_path(T_, __LINE__, p, NULL, VXL_ERR_FORMAT, "badgz.nii.gz");
}

TEST(bad_dimensions_are_format_errors)
{
    struct { int version, dim0, axis; int64_t value; } cases[] = {
        {1, 3, 2, -4}, {2, 3, 2, -4}, {1, 3, 1, 0}, {2, 3, 3, 0},
        {1, 0, 0, 0}, {2, 0, 0, 0}, {1, 8, 0, 0}, {2, 8, 0, 0}, {1, -1, 0, 0},
        {1, 4, 4, 0}, {2, 5, 5, -1}, /* axes past 3 are validated too */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        tnw_header h;
        tnw_init(&h, cases[i].version, 2, 4, 4, 4);
        h.swap = (int)(i & 1);
        h.dim[0] = cases[i].dim0;
        if (cases[i].axis) h.dim[cases[i].axis] = cases[i].value;
        char name[64];
        snprintf(name, sizeof name, "baddim%zu.nii", i);
        EXPECT_FAIL(name, &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "dim");
    }
}

TEST(absurd_sizes_are_limit_errors_before_allocation)
{
    tnw_header h;
    /* 100000^3 (NIfTI-2: NIfTI-1 dims are 16-bit) */
    tnw_init(&h, 2, 2, 100000, 100000, 100000);
    EXPECT_FAIL("huge2.nii", &h, g_zeros, 64, NULL, VXL_ERR_LIMIT, "budget|limit");
    /* under the per-axis limit but far over the memory budget */
    tnw_init(&h, 1, 16, 32767, 32767, 32767);
    h.swap = 1;
    EXPECT_FAIL("huge1.nii.gz", &h, g_zeros, 64, NULL, VXL_ERR_LIMIT, "budget");
    /* an axis beyond 32 bits */
    tnw_init(&h, 2, 64, (int64_t)1 << 40, 1, 1);
    EXPECT_FAIL("huge_axis.nii", &h, g_zeros, 64, NULL, VXL_ERR_LIMIT, "limit");
    /* 65536^3 f64: product fits 64 bits, budget says no */
    tnw_init(&h, 2, 64, 65536, 65536, 65536);
    EXPECT_FAIL("huge64.hdr", &h, g_zeros, 64, NULL, VXL_ERR_LIMIT, "budget");

    /* caller's options */
    vxl_load_options opt = {.struct_size = sizeof opt, .max_dim = 0, .memory_budget_bytes = 1000};
    tnw_init(&h, 1, 16, 16, 16, 16);
    EXPECT_FAIL("budget.nii", &h, g_zeros, 64, &opt, VXL_ERR_LIMIT, "budget");
    vxl_load_options opt2 = {.struct_size = sizeof opt2, .max_dim = 8, .memory_budget_bytes = 0};
    EXPECT_FAIL("maxdim.nii", &h, g_zeros, 64, &opt2, VXL_ERR_LIMIT, "limit");

    /* exactly at the budget: loads (16^3 u8 = 4096 bytes) */
    vxl_load_options opt3 = {.struct_size = sizeof opt3, .max_dim = 16, .memory_budget_bytes = 4096};
    tnw_init(&h, 1, 2, 16, 16, 16);
    vxl_volume *v = NULL;
    CHECKF(write_and_load("at_budget.nii", &h, g_zeros, 4096, &opt3, &v) == VXL_OK, "%s", vxl_last_error());
    vxl_volume_destroy(v);
}

TEST(bad_vox_offset_and_datatype_are_format_errors)
{
    tnw_header h;
    double offsets1[] = {1e12, 3e38, 100, 348, -16, NAN, INFINITY, 352.5};
    for (size_t i = 0; i < sizeof offsets1 / sizeof offsets1[0]; i++) {
        tnw_init(&h, 1, 2, 4, 4, 4);
        h.vox_offset = offsets1[i];
        h.swap = (int)(i & 1);
        EXPECT_FAIL("voxoff1.nii", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "vox_offset");
    }
    double offsets2[] = {9.3e18 /* INT64_MAX */, 1e15, 540, -1};
    for (size_t i = 0; i < sizeof offsets2 / sizeof offsets2[0]; i++) {
        tnw_init(&h, 2, 2, 4, 4, 4);
        h.vox_offset = offsets2[i];
        EXPECT_FAIL("voxoff2.nii.gz", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "vox_offset");
    }
    /* a pair's .img offset may be 0 but not negative */
    tnw_init(&h, 1, 2, 4, 4, 4);
    h.vox_offset = -4;
    EXPECT_FAIL("voxoff.hdr", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "vox_offset");

    /* RGB24 loads as colour (test_colour.c): 3 bytes a voxel, so 64 bytes are a truncated file */
    tnw_init(&h, 1, 128, 4, 4, 4);
    EXPECT_FAIL("rgb.nii", &h, g_zeros, 64, NULL, VXL_ERR_FORMAT, "truncated");
    int others[] = {0, 1, 32, 1024, 1280, 1536, 1792, 2048, 3, -1};
    for (size_t i = 0; i < sizeof others / sizeof others[0]; i++) {
        char want[48];
        snprintf(want, sizeof want, "datatype %d", others[i]);
        tnw_init(&h, 2, others[i], 4, 4, 4);
        h.swap = (int)(i & 1);
        EXPECT_FAIL("dtype.nii", &h, g_zeros, 1024, NULL, VXL_ERR_FORMAT, want);
    }
}

/* Random header damage: whatever happens, only OK/FORMAT/LIMIT, no volume
 * on failure, and a sane volume on success. ASan/UBSan do the rest. */
TEST(random_header_damage_never_crashes)
{
    uint32_t seed = 12345u;
#define RND() (seed = seed * 1664525u + 1013904223u, seed >> 8)
    static const unsigned char interesting[] = {0x00, 0xff, 0x80, 0x7f, 0x01, 0xfe};
    vxl_load_options opt = {.struct_size = sizeof opt, .max_dim = 0, .memory_budget_bytes = 16u << 20};
    int ok = 0, failed = 0;
    for (int iter = 0; iter < 3000; iter++) {
        int version = 1 + (iter & 1);
        tnw_header h;
        tnw_init(&h, version, 16, 4, 3, 2);
        h.swap = (iter >> 1) & 1;
        h.qform_code = 1; h.quatern[1] = 0.3; h.pixdim[0] = -1;
        h.sform_code = 1; h.srow[0][0] = h.srow[1][1] = h.srow[2][2] = 1;
        h.scl_slope = 2;
        size_t hsize = version == 1 ? 348 : 540;
        h.patch_at = RND() % (hsize - 4);
        h.patch_len = 1 + RND() % 4;
        for (size_t k = 0; k < h.patch_len; k++)
            h.patch[k] = (RND() & 1) ? interesting[RND() % sizeof interesting] : (unsigned char)RND();
        float data[24];
        for (int i = 0; i < 24; i++) data[i] = (float)i;
        vxl_volume *v = NULL;
        int rc = write_and_load("fuzz.nii", &h, data, sizeof data, &opt, &v);
        if (rc == VXL_OK) {
            ok++;
            vxl_volume_info info;
            vxl_volume_get_info(v, &info);
            CHECK(info.dims[0] >= 1 && info.dims[1] >= 1 && info.dims[2] >= 1);
            CHECK(info.value_min <= info.value_max);
            for (int i = 0; i < 16; i++) CHECK(isfinite(info.affine[i]));
            for (int a = 0; a < 3; a++) CHECK(info.spacing[a] > 0 && isfinite(info.spacing[a]));
        } else {
            failed++;
            CHECKF(rc == VXL_ERR_FORMAT || rc == VXL_ERR_LIMIT, "iter %d: rc %d (%s)", iter, rc,
                   vxl_last_error());
            CHECK(v == NULL);
        }
        vxl_volume_destroy(v);
    }
#undef RND
    fprintf(stderr, "  fuzz: %d loaded, %d rejected\n", ok, failed);
    CHECK(ok > 0 && failed > 0);
}

/* ------------------------------------------------------------ real file */

TEST(real_file_ch2better)
{
    if (access(REAL_FILE, R_OK) != 0) {
        fprintf(stderr, "  SKIP: %s not present\n", REAL_FILE);
        return;
    }
    vxl_volume *v = NULL;
    int rc = vxl_volume_load(REAL_FILE, NULL, &v);
    CHECKF(rc == VXL_OK, "%s", vxl_last_error());
    if (rc) return;
    vxl_volume_info info;
    REQUIRE(vxl_volume_get_info(v, &info) == VXL_OK);
    fprintf(stderr, "  %s: %ux%ux%u dtype %u NIfTI-%u spacing %g,%g,%g range %g..%g nan %llu\n", REAL_FILE,
            info.dims[0], info.dims[1], info.dims[2], info.dtype, info.nifti_version, info.spacing[0],
            info.spacing[1], info.spacing[2], info.value_min, info.value_max,
            (unsigned long long)info.nan_count);
    fprintf(stderr, "  affine (source %u):\n", info.affine_source);
    for (int r = 0; r < 4; r++)
        fprintf(stderr, "    [%8.3f %8.3f %8.3f %9.3f]\n", info.affine[r], info.affine[4 + r],
                info.affine[8 + r], info.affine[12 + r]);
    CHECK(info.dims[0] == 301 && info.dims[1] == 370 && info.dims[2] == 316);
    CHECK(info.dtype == VXL_DTYPE_U8);
    CHECK(info.nifti_version == 1);
    CHECK(info.affine_source == 1 || info.affine_source == 2);
    CHECK(info.spacing[0] == 0.5 && info.spacing[1] == 0.5 && info.spacing[2] == 0.5);
    /* voxel (0,0,0) sits at (-75, -107, -69.5) mm in this template */
    CHECK(info.affine[12] == -75 && info.affine[13] == -107 && info.affine[14] == -69.5);
    CHECK(info.value_max > info.value_min);
    CHECK(info.storage_bytes == 301ull * 370 * 316);
    vxl_volume_destroy(v);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_test_nifti_XXXXXX");
    if (!mkdtemp(g_dir)) {
        fprintf(stderr, "mkdtemp: %s\n", strerror(errno));
        return 1;
    }
    RUN(every_dtype_roundtrips_in_every_form_order_and_version);
    RUN(pair_loads_from_hdr_or_img_path_and_mixed_compression);
    RUN(vox_offset_with_extension_bytes_is_honoured);
    RUN(slope_and_intercept_are_applied);
    RUN(nan_and_inf_voxels_are_counted);
    RUN(qform_90_degrees_about_z_with_qfac_minus_one);
    RUN(qform_180_degrees_about_x_uses_the_a_equals_zero_branch);
    RUN(qform_general_rotation_matches_rodrigues);
    RUN(sform_wins_over_qform);
    RUN(unusable_sform_falls_back_and_no_transform_gives_spacing);
    RUN(four_d_loads_the_first_volume_and_low_dim_counts_fill_with_one);
    RUN(missing_files_are_io_errors);
    RUN(truncated_files_are_format_errors);
    RUN(every_prefix_of_a_file_fails_cleanly);
    RUN(corrupt_magic_and_headers_are_format_errors);
    RUN(bad_dimensions_are_format_errors);
    RUN(absurd_sizes_are_limit_errors_before_allocation);
    RUN(bad_vox_offset_and_datatype_are_format_errors);
    RUN(random_header_damage_never_crashes);
    RUN(real_file_ch2better);
    remove_tmp_dir();
    return TEST_SUMMARY();
}
