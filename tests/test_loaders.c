/* test_loaders.c - the NRRD, MetaImage and TIFF/PNG stack loaders and the
 * loader dispatch, through the public API (vxl_volume_load).
 *
 * Files are written by tests/fuzz/writers.h, which knows the formats
 * independently of the readers, into a mkdtemp directory removed at the
 * end. Voxel values are checked through the texels (layout from volume.h),
 * so byte-order, offset or row-order mistakes show up as wrong values. The
 * crash corpus tests/crashers/ is replayed at the end. */
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fuzz/writers.h"
#include "harness.h"
#include "loader_test_util.h"
#include "volume.h"
#include "voxlight.h"

static char g_dir[64];

static const char *tmp(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
    return buf;
}

static int near(double a, double b, double tol) { return fabs(a - b) <= tol * (1.0 + fabs(b)); }

typedef struct dtype_case {
    uint32_t dtype;
    const char *nrrd, *met;
    size_t size;
} dtype_case;

static const dtype_case k_types[] = {
    {VXL_DTYPE_U8, "uchar", "MET_UCHAR", 1},      {VXL_DTYPE_I8, "signed char", "MET_CHAR", 1},
    {VXL_DTYPE_U16, "ushort", "MET_USHORT", 2},   {VXL_DTYPE_I16, "short", "MET_SHORT", 2},
    {VXL_DTYPE_U32, "uint", "MET_UINT", 4},       {VXL_DTYPE_I32, "int32", "MET_INT", 4},
    {VXL_DTYPE_F32, "float", "MET_FLOAT", 4},     {VXL_DTYPE_F64, "double", "MET_DOUBLE", 8},
};

/* 3x2x2 voxels with values distinct in every byte order: v[i] = f(i). */
#define NX 3
#define NY 2
#define NZ 2
#define NV (NX * NY * NZ)

static double expected(uint32_t dtype, int i)
{
    switch (dtype) {
    case VXL_DTYPE_U8: return 3 + 17 * i;
    case VXL_DTYPE_I8: return -100 + 15 * i;
    case VXL_DTYPE_U16: return 258 + 4099 * i;
    case VXL_DTYPE_I16: return -30000 + 4099 * i;
    case VXL_DTYPE_U32: return 70000 + 1234567 * (double)i;
    case VXL_DTYPE_I32: return -7000000 + 1234567 * (double)i;
    default: return -2.5 + 0.75 * i;
    }
}

static void fill(uint32_t dtype, void *buf)
{
    for (int i = 0; i < NV; i++) {
        double x = expected(dtype, i);
        switch (dtype) {
        case VXL_DTYPE_U8: ((uint8_t *)buf)[i] = (uint8_t)x; break;
        case VXL_DTYPE_I8: ((int8_t *)buf)[i] = (int8_t)x; break;
        case VXL_DTYPE_U16: ((uint16_t *)buf)[i] = (uint16_t)x; break;
        case VXL_DTYPE_I16: ((int16_t *)buf)[i] = (int16_t)x; break;
        case VXL_DTYPE_U32: ((uint32_t *)buf)[i] = (uint32_t)x; break;
        case VXL_DTYPE_I32: ((int32_t *)buf)[i] = (int32_t)x; break;
        case VXL_DTYPE_F32: ((float *)buf)[i] = (float)x; break;
        default: ((double *)buf)[i] = x; break;
        }
    }
}

static int host_big(void)
{
    uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 0;
}

static void check_values(vxl_test_ctx *T_, const vxl_volume *v, uint32_t dtype, const char *what)
{
    CHECKF(v->dims[0] == NX && v->dims[1] == NY && v->dims[2] == NZ, "%s: dims %ux%ux%u", what, v->dims[0],
           v->dims[1], v->dims[2]);
    CHECKF(v->src_dtype == dtype, "%s: dtype %u, want %u", what, v->src_dtype, dtype);
    for (int i = 0; i < NV; i++) {
        double tol = v->texture_bits == 32 ? 1e-6 : 1e-12;
        CHECKF(near(voxel(v, (uint64_t)i), expected(dtype, i), tol), "%s: voxel %d = %g, want %g", what, i,
               voxel(v, (uint64_t)i), expected(dtype, i));
    }
}

static int load(const char *path, const vxl_load_options *opt, vxl_volume **v) { return vxl_volume_load(path, opt, v); }

/* ------------------------------------------------------------------ NRRD */

static int write_nrrd(const char *path, const dtype_case *t, int big, int mode, const char *data_file,
                      const char *extra)
{
    unsigned char buf[NV * 8];
    fill(t->dtype, buf);
    void *data = buf;
    void *sw = NULL;
    if (t->size > 1 && big != host_big()) data = sw = tw_swapped(buf, NV, t->size);
    char hdr[1024], dpath[512];
    snprintf(hdr, sizeof hdr,
             "NRRD0004\n# written by test_loaders\ntype: %s\ndimension: 3\nsizes: %d %d %d\nencoding: %s\n"
             "endian: %s\n%s%s%s%s",
             t->nrrd, NX, NY, NZ, mode == TW_GZIP ? "gzip" : "raw", big ? "big" : "little", extra ? extra : "",
             data_file ? "data file: " : "", data_file ? data_file : "", data_file ? "\n" : "\n");
    if (data_file) snprintf(dpath, sizeof dpath, "%s/%s", g_dir, data_file);
    int rc = tw_write_header_data(path, hdr, data, NV * t->size, mode, data_file ? dpath : NULL);
    free(sw);
    return rc;
}

TEST(nrrd_every_type_both_byte_orders_raw_and_gzip)
{
    char p[256], what[128];
    for (size_t k = 0; k < sizeof k_types / sizeof k_types[0]; k++)
        for (int big = 0; big < 2; big++)
            for (int gz = 0; gz < 2; gz++) {
                REQUIRE(write_nrrd(tmp(p, sizeof p, "t.nrrd"), &k_types[k], big, gz ? TW_GZIP : TW_RAW, NULL,
                                   NULL) == 0);
                snprintf(what, sizeof what, "nrrd %s %s %s", k_types[k].nrrd, big ? "big" : "little",
                         gz ? "gzip" : "raw");
                vxl_volume *v = NULL;
                int rc = load(p, NULL, &v);
                CHECKF(rc == VXL_OK, "%s: %s", what, vxl_last_error());
                if (v) check_values(T_, v, k_types[k].dtype, what);
                vxl_volume_destroy(v);
            }
}

TEST(nrrd_detached_header_skips_and_data_at_end)
{
    char p[256];
    const dtype_case *t = &k_types[3]; /* int16 */
    for (int gz = 0; gz < 2; gz++) {
        REQUIRE(write_nrrd(tmp(p, sizeof p, "d.nhdr"), t, 0, gz ? TW_GZIP : TW_RAW, "d.raw", NULL) == 0);
        vxl_volume *v = NULL;
        CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
        if (v) check_values(T_, v, t->dtype, gz ? "nhdr gzip" : "nhdr raw");
        vxl_volume_destroy(v);
    }
    /* line skip + byte skip in a detached raw file */
    unsigned char buf[NV * 2];
    fill(t->dtype, buf);
    void *le = host_big() ? tw_swapped(buf, NV, 2) : NULL;
    char dpath[256];
    FILE *f = fopen(tmp(dpath, sizeof dpath, "skip.raw"), "wb");
    REQUIRE(f);
    fputs("junk line one\njunk line two\nXYZ", f);
    fwrite(le ? le : buf, 1, sizeof buf, f);
    fclose(f);
    char hdr[512];
    snprintf(hdr, sizeof hdr, "NRRD0004\ntype: short\ndimension: 3\nsizes: %d %d %d\nencoding: raw\n"
             "endian: little\nline skip: 2\nbyte skip: 3\ndata file: skip.raw\n", NX, NY, NZ);
    REQUIRE(tw_write(tmp(p, sizeof p, "skip.nhdr"), hdr, strlen(hdr), NULL, 0) == 0);
    vxl_volume *v = NULL;
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) check_values(T_, v, t->dtype, "line/byte skip");
    vxl_volume_destroy(v);
    /* byte skip -1: the data is the last bytes of the file */
    snprintf(hdr, sizeof hdr, "NRRD0004\ntype: short\ndimension: 3\nsizes: %d %d %d\nencoding: raw\n"
             "endian: little\nbyte skip: -1\ndata file: skip.raw\n", NX, NY, NZ);
    REQUIRE(tw_write(tmp(p, sizeof p, "end.nhdr"), hdr, strlen(hdr), NULL, 0) == 0);
    v = NULL;
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) check_values(T_, v, t->dtype, "byte skip -1");
    vxl_volume_destroy(v);
    free(le);
}

TEST(nrrd_space_directions_and_origin_give_the_ras_affine)
{
    char p[256];
    /* LPS: x and y flip to RAS. Axis 0 along LPS (0,2,0), axis 1 along
     * (-3,0,0), axis 2 along (0,0,4); origin (10,20,30) LPS. */
    REQUIRE(write_nrrd(tmp(p, sizeof p, "g.nrrd"), &k_types[0], 0, TW_RAW, NULL,
                       "space: left-posterior-superior\nspace directions: (0,2,0) (-3,0,0) (0,0,4)\n"
                       "space origin: (10,20,30)\nkinds: domain domain domain\n") == 0);
    vxl_volume *v = NULL;
    REQUIRE(load(p, NULL, &v) == VXL_OK);
    const double want[16] = {0, -2, 0, 0, 3, 0, 0, 0, 0, 0, 4, 0, -10, -20, 30, 1};
    for (int i = 0; i < 16; i++) CHECKF(near(v->affine[i], want[i], 1e-12), "affine[%d] = %g, want %g", i, v->affine[i], want[i]);
    CHECK(near(v->spacing[0], 2, 1e-12) && near(v->spacing[1], 3, 1e-12) && near(v->spacing[2], 4, 1e-12));
    vxl_volume_destroy(v);

    /* no space: spacings -> diag, nan = unknown = 1 */
    REQUIRE(write_nrrd(p, &k_types[0], 0, TW_RAW, NULL, "spacings: 0.5 nan 2\n") == 0);
    REQUIRE(load(p, NULL, &v) == VXL_OK);
    CHECK(v->affine[0] == 0.5 && v->affine[5] == 1.0 && v->affine[10] == 2.0 && v->affine[12] == 0.0);
    vxl_volume_destroy(v);
}

TEST(nrrd_4d_reads_the_first_volume_and_2d_is_one_slice)
{
    char p[256];
    unsigned char buf[NV * 2];
    fill(VXL_DTYPE_U8, buf);
    memset(buf + NV, 0xEE, NV); /* second time point: must not be read */
    char hdr[512];
    snprintf(hdr, sizeof hdr, "NRRD0005\ntype: uint8\ndimension: 4\nsizes: %d %d %d 2\nencoding: raw\n"
             "space: RAS\nspace directions: (1,0,0) (0,1,0) (0,0,1) none\nkinds: space space space time\n\n",
             NX, NY, NZ);
    REQUIRE(tw_write(tmp(p, sizeof p, "t4.nrrd"), hdr, strlen(hdr), buf, sizeof buf) == 0);
    vxl_volume *v = NULL;
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) check_values(T_, v, VXL_DTYPE_U8, "4d first volume");
    vxl_volume_destroy(v);

    snprintf(hdr, sizeof hdr, "NRRD0004\ntype: uint8\ndimension: 2\nsizes: 4 3\nencoding: raw\n\n");
    REQUIRE(tw_write(tmp(p, sizeof p, "t2.nrrd"), hdr, strlen(hdr), buf, 12) == 0);
    v = NULL;
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) CHECK(v->dims[0] == 4 && v->dims[1] == 3 && v->dims[2] == 1);
    vxl_volume_destroy(v);

    /* RGB as the fastest axis is a colour volume (test_colour.c); as another axis it is refused */
    snprintf(hdr, sizeof hdr, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 3 2 2\nkinds: RGB-color domain domain\n"
             "encoding: raw\n\n");
    REQUIRE(tw_write(tmp(p, sizeof p, "rgb.nrrd"), hdr, strlen(hdr), buf, 12) == 0);
    v = NULL;
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) CHECK(v->components == 3 && v->dims[0] == 2 && v->dims[1] == 2 && v->dims[2] == 1);
    vxl_volume_destroy(v);
    snprintf(hdr, sizeof hdr, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 3 2\nkinds: domain RGB-color domain\n"
             "encoding: raw\n\n");
    REQUIRE(tw_write(tmp(p, sizeof p, "rgb_middle.nrrd"), hdr, strlen(hdr), buf, 12) == 0);
    CHECK(load(p, NULL, &v) == VXL_ERR_FORMAT && strstr(vxl_last_error(), "not spatial"));
}

/* Loads path expecting failure code with every needle in the message. */
static void expect_error(vxl_test_ctx *T_, const char *path, const vxl_load_options *opt, int code, const char *n1,
                         const char *n2)
{
    vxl_volume *v = (vxl_volume *)1;
    int rc = load(path, opt, &v);
    const char *msg = vxl_last_error();
    CHECKF(rc == code, "%s: rc %d, want %d (%s)", path, rc, code, msg);
    CHECKF(v == NULL, "%s: out not NULL on failure", path);
    CHECKF(strstr(msg, path) != NULL || (n1 && strstr(msg, n1)), "%s: message does not name the file: %s", path, msg);
    if (n1) CHECKF(strstr(msg, n1) != NULL, "%s: '%s' not in: %s", path, n1, msg);
    if (n2) CHECKF(strstr(msg, n2) != NULL, "%s: '%s' not in: %s", path, n2, msg);
    if (rc == VXL_OK) vxl_volume_destroy(v);
}

static void write_text(const char *path, const char *text) { tw_write(path, text, strlen(text), NULL, 0); }

TEST(nrrd_hostile_headers_give_clear_errors)
{
    char p[256];
    tmp(p, sizeof p, "bad.nrrd");
    write_text(p, "NRRX0004\ntype: uchar\n\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "not a NRRD file", NULL);
    write_text(p, "NRRD0004\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "no 'type'", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2\nencoding: raw\n\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "'sizes' has 2 entries", NULL);
    write_text(p, "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "'endian'", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: bzip2\n\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "unsupported NRRD encoding", NULL);
    write_text(p, "NRRD0004\ntype: int64\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "unsupported NRRD type", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 -2 2\nencoding: raw\n\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "'sizes'", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\nabc");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "truncated", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "no blank line", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n\nnot gzip at all");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "compressed", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: /dev/zero\n\n");
    expect_error(T_, p, NULL, VXL_ERR_IO, "/dev/zero", "not a regular file");
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: nothere.raw\n\n");
    expect_error(T_, p, NULL, VXL_ERR_IO, "nothere.raw", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspace: RAS\n"
                  "space directions: (1,0,0) (0,1,0) (1,0,0)\n\n12345678");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "singular", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspace: RAS\n"
                  "space directions: (1,0,nan) (0,1,0) (0,0,1)\n\n12345678");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "space directions", NULL);
    tmp(p, sizeof p, "nodata.nhdr");
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "no 'data file'", NULL);
}

TEST(nrrd_absurd_sizes_are_refused_before_allocation_naming_the_budget)
{
    char p[256];
    tmp(p, sizeof p, "huge.nrrd");
    /* 100000^3 float: the file is a few bytes, so any allocation first
     * would be a bug; the budget must be named. */
    write_text(p, "NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\nencoding: gzip\n"
                  "endian: little\n\nxx");
    expect_error(T_, p, NULL, VXL_ERR_LIMIT, "memory budget", NULL);
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4294967295 4294967295 4294967295\nencoding: raw\n\n");
    expect_error(T_, p, NULL, VXL_ERR_LIMIT, "memory budget", NULL);
    /* within the default budget but over a caller's budget */
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 64 64 64\nencoding: raw\n\n");
    vxl_load_options opt = {.struct_size = sizeof opt, .memory_budget_bytes = 1000};
    expect_error(T_, p, &opt, VXL_ERR_LIMIT, "memory budget", NULL);
    /* a compressed stream far too short for what the header claims */
    write_text(p, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1000 1000 1000\nencoding: gzip\n\nabc");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "truncated", NULL);
}

/* ------------------------------------------------------------- MetaImage */

static int write_mha(const char *path, const dtype_case *t, int msb, int mode, const char *data_file,
                     const char *extra)
{
    unsigned char buf[NV * 8];
    fill(t->dtype, buf);
    void *data = buf, *sw = NULL;
    if (t->size > 1 && msb != host_big()) data = sw = tw_swapped(buf, NV, t->size);
    char hdr[1024], dpath[512];
    snprintf(hdr, sizeof hdr,
             "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = %s\nCompressedData = %s\n"
             "%sDimSize = %d %d %d\nElementType = %s\nElementDataFile = %s\n",
             msb ? "True" : "False", mode ? "True" : "False", extra ? extra : "", NX, NY, NZ, t->met,
             data_file ? data_file : "LOCAL");
    if (data_file) snprintf(dpath, sizeof dpath, "%s/%s", g_dir, data_file);
    int rc = tw_write_header_data(path, hdr, data, NV * t->size, mode, data_file ? dpath : NULL);
    free(sw);
    return rc;
}

TEST(metaimage_every_type_both_byte_orders_raw_and_zlib)
{
    char p[256], what[128];
    for (size_t k = 0; k < sizeof k_types / sizeof k_types[0]; k++)
        for (int msb = 0; msb < 2; msb++)
            for (int z = 0; z < 2; z++) {
                REQUIRE(write_mha(tmp(p, sizeof p, "t.mha"), &k_types[k], msb, z ? TW_ZLIB : TW_RAW, NULL, NULL) == 0);
                snprintf(what, sizeof what, "mha %s msb=%d compressed=%d", k_types[k].met, msb, z);
                vxl_volume *v = NULL;
                CHECKF(load(p, NULL, &v) == VXL_OK, "%s: %s", what, vxl_last_error());
                if (v) check_values(T_, v, k_types[k].dtype, what);
                vxl_volume_destroy(v);
            }
}

TEST(metaimage_detached_and_header_size)
{
    char p[256];
    const dtype_case *t = &k_types[6]; /* float */
    for (int z = 0; z < 2; z++) {
        REQUIRE(write_mha(tmp(p, sizeof p, "d.mhd"), t, 0, z ? TW_ZLIB : TW_RAW, "d.zraw", NULL) == 0);
        vxl_volume *v = NULL;
        CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
        if (v) check_values(T_, v, t->dtype, z ? "mhd zlib" : "mhd raw");
        vxl_volume_destroy(v);
    }
    /* HeaderSize = -1: the data is the end of a file with a preamble */
    float buf[NV];
    fill(VXL_DTYPE_F32, buf);
    void *le = host_big() ? tw_swapped(buf, NV, 4) : NULL;
    char dpath[256];
    REQUIRE(tw_write(tmp(dpath, sizeof dpath, "pre.raw"), "PREAMBLE!", 9, le ? le : (void *)buf, sizeof buf) == 0);
    char hdr[512];
    snprintf(hdr, sizeof hdr, "NDims = 3\nDimSize = %d %d %d\nElementType = MET_FLOAT\nHeaderSize = -1\n"
             "ElementDataFile = pre.raw\n", NX, NY, NZ);
    REQUIRE(tw_write(tmp(p, sizeof p, "pre.mhd"), hdr, strlen(hdr), NULL, 0) == 0);
    vxl_volume *v = NULL;
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) check_values(T_, v, VXL_DTYPE_F32, "HeaderSize -1");
    vxl_volume_destroy(v);
    snprintf(hdr, sizeof hdr, "NDims = 3\nDimSize = %d %d %d\nElementType = MET_FLOAT\nHeaderSize = 9\n"
             "ElementDataFile = pre.raw\n", NX, NY, NZ);
    REQUIRE(tw_write(tmp(p, sizeof p, "pre9.mhd"), hdr, strlen(hdr), NULL, 0) == 0);
    v = NULL;
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) check_values(T_, v, VXL_DTYPE_F32, "HeaderSize 9");
    vxl_volume_destroy(v);
    free(le);
}

TEST(metaimage_geometry_is_converted_from_lps_to_ras)
{
    char p[256];
    /* axis 0 along LPS y, axis 1 along -x, axis 2 along z; spacing 2 3 4 */
    REQUIRE(write_mha(tmp(p, sizeof p, "g.mha"), &k_types[0], 0, TW_RAW, NULL,
                      "TransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 10 20 30\nElementSpacing = 2 3 4\n"
                      "AnatomicalOrientation = RAI\n") == 0);
    vxl_volume *v = NULL;
    REQUIRE(load(p, NULL, &v) == VXL_OK);
    const double want[16] = {0, -2, 0, 0, 3, 0, 0, 0, 0, 0, 4, 0, -10, -20, 30, 1};
    for (int i = 0; i < 16; i++) CHECKF(near(v->affine[i], want[i], 1e-12), "affine[%d] = %g, want %g", i, v->affine[i], want[i]);
    CHECK(v->spacing[0] == 2 && v->spacing[1] == 3 && v->spacing[2] == 4);
    vxl_volume_destroy(v);
}

TEST(metaimage_hostile_headers_give_clear_errors)
{
    char p[256];
    tmp(p, sizeof p, "bad.mha");
    write_text(p, "NDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_FLOAT\nElementDataFile = LOCAL\nxx");
    expect_error(T_, p, NULL, VXL_ERR_LIMIT, "memory budget", NULL);
    write_text(p, "NDims = 3\nDimSize = 2 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n12345678");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "DimSize has 2 entries", NULL);
    write_text(p, "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n1234");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "truncated", NULL);
    write_text(p, "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "ElementDataFile", NULL);
    write_text(p, "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR_ARRAY\nElementDataFile = LOCAL\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "ElementType", NULL);
    /* 3 and 4 channels are colour (test_colour_readers.c), 2..8 channels
     * (test_channel_readers.c); 9 is neither */
    write_text(p, "NDims = 3\nDimSize = 2 2 2\nElementNumberOfChannels = 9\nElementType = MET_UCHAR\n"
                  "ElementDataFile = LOCAL\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "9 channels per voxel is not supported (1, 3 and 4 as RGB and RGBA "
                 "colour, or 2 to 8 channels)", NULL);
    write_text(p, "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nCompressedData = True\n"
                  "ElementDataFile = LOCAL\nnot zlib");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "compressed", NULL);
    write_text(p, "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nTransformMatrix = 1 0 0 1 0 0 0 0 1\n"
                  "ElementDataFile = LOCAL\n12345678");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "singular", NULL);
    write_text(p, "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = /dev/zero\n");
    expect_error(T_, p, NULL, VXL_ERR_IO, "not a regular file", NULL);
    write_text(p, "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = slice%03d.raw 1 2 1\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "several files", NULL);
    write_text(p, "this is not a header\n");
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "not a MetaImage", NULL);
}

/* ---------------------------------------------------------- image stacks */

/* slice k, row y (top first), column x */
static double stack_value(int k, int y, int x) { return 10 * k + 3 * y + x + 1; }

/* voxel (i, j, k) holds pixel (x = i, y = h-1-j) of slice k */
static void check_stack(vxl_test_ctx *T_, const vxl_volume *v, uint32_t w, uint32_t h, uint32_t d, double scale,
                        const char *what)
{
    CHECKF(v->dims[0] == w && v->dims[1] == h && v->dims[2] == d, "%s: dims %ux%ux%u", what, v->dims[0], v->dims[1],
           v->dims[2]);
    if (v->dims[0] != w || v->dims[1] != h || v->dims[2] != d) return;
    for (uint32_t k = 0; k < d; k++)
        for (uint32_t j = 0; j < h; j++)
            for (uint32_t i = 0; i < w; i++) {
                uint64_t idx = i + (uint64_t)w * (j + (uint64_t)h * k);
                double want = stack_value((int)k, (int)(h - 1 - j), (int)i) * scale;
                CHECKF(near(voxel(v, idx), want, 1e-5), "%s: voxel (%u,%u,%u) = %g, want %g", what, i, j, k,
                       voxel(v, idx), want);
            }
}

#define SW 4
#define SH 3
#define SD 3

static void stack_pixels(int k, int bits_kind, void *out, double scale)
{
    for (int y = 0; y < SH; y++)
        for (int x = 0; x < SW; x++) {
            double val = stack_value(k, y, x) * scale;
            int i = y * SW + x;
            if (bits_kind == 8) ((uint8_t *)out)[i] = (uint8_t)val;
            else if (bits_kind == 16) ((uint16_t *)out)[i] = (uint16_t)val;
            else ((float *)out)[i] = (float)val;
        }
}

TEST(multipage_tiff_8_16_float)
{
    char p[256];
    struct { int bits, fmt; uint32_t dtype; double scale; const char *name; } cases[] = {
        {8, 1, VXL_DTYPE_U8, 1.0, "u8.tif"}, {16, 1, VXL_DTYPE_U16, 1000.0, "u16.tif"},
        {32, 3, VXL_DTYPE_F32, 0.125, "f32.tif"}};
    for (size_t c = 0; c < 3; c++) {
        float buf[SW * SH * SD];
        unsigned char *b = (unsigned char *)buf;
        size_t page = (size_t)SW * SH * (size_t)(cases[c].bits / 8);
        for (int k = 0; k < SD; k++) stack_pixels(k, cases[c].bits, b + k * page, cases[c].scale);
        REQUIRE(tw_write_tiff(tmp(p, sizeof p, cases[c].name), SW, SH, SD, 1, cases[c].bits, cases[c].fmt, buf) == 0);
        vxl_volume *v = NULL;
        CHECKF(load(p, NULL, &v) == VXL_OK, "%s: %s", cases[c].name, vxl_last_error());
        if (!v) continue;
        CHECKF(v->src_dtype == cases[c].dtype, "%s: dtype %u", cases[c].name, v->src_dtype);
        check_stack(T_, v, SW, SH, SD, cases[c].scale, cases[c].name);
        CHECK(v->affine[0] == 1 && v->affine[5] == 1 && v->affine[10] == 1);
        vxl_volume_destroy(v);
    }
}

TEST(numbered_series_and_folders_of_png_and_tiff)
{
    char p[512], dir[128];
    /* numbered 16-bit PNG series in a folder of its own, loaded by naming one
     * file and by naming the folder */
    snprintf(dir, sizeof dir, "%s/png16", g_dir);
    REQUIRE(mkdir(dir, 0700) == 0);
    for (int k = 0; k < SD; k++) {
        uint16_t px[SW * SH];
        stack_pixels(k, 16, px, 1000.0);
        snprintf(p, sizeof p, "%s/slice_%04d.png", dir, k + 1);
        REQUIRE(tw_write_png(p, SW, SH, 1, 16, px) == 0);
    }
    vxl_volume *v = NULL;
    snprintf(p, sizeof p, "%s/slice_0002.png", dir);
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) {
        CHECK(v->src_dtype == VXL_DTYPE_U16);
        check_stack(T_, v, SW, SH, SD, 1000.0, "png16 numbered");
    }
    vxl_volume_destroy(v);
    v = NULL;
    CHECKF(load(dir, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) check_stack(T_, v, SW, SH, SD, 1000.0, "png16 folder");
    vxl_volume_destroy(v);

    /* numbered float TIFFs, natural order across a width change (9 -> 10) */
    snprintf(dir, sizeof dir, "%s/tif", g_dir);
    REQUIRE(mkdir(dir, 0700) == 0);
    for (int k = 0; k < 11; k++) {
        float px[SW * SH];
        stack_pixels(k, 32, px, 0.5);
        snprintf(p, sizeof p, "%s/img%d.tif", dir, k);
        REQUIRE(tw_write_tiff(p, SW, SH, 1, 1, 32, 3, px) == 0);
    }
    v = NULL;
    CHECKF(load(dir, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) {
        CHECK(v->src_dtype == VXL_DTYPE_F32);
        check_stack(T_, v, SW, SH, 11, 0.5, "tif folder natural order");
    }
    vxl_volume_destroy(v);

    /* an RGB PNG becomes a colour volume whose scalar is the luminance;
     * grey+alpha keeps the grey */
    uint8_t rgb[SW * SH * 3], ga[SW * SH * 2];
    for (int i = 0; i < SW * SH; i++) {
        rgb[3 * i] = 200; rgb[3 * i + 1] = 100; rgb[3 * i + 2] = 50;
        ga[2 * i] = (uint8_t)(i * 10); ga[2 * i + 1] = 0;
    }
    REQUIRE(tw_write_png(tmp(p, sizeof p, "rgb.png"), SW, SH, 3, 8, rgb) == 0);
    v = NULL;
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) CHECKF(near(voxel(v, 0), 118, 1e-9), "rgb luminance %g (0.2126*200+0.7152*100+0.0722*50 = 117.65)", voxel(v, 0));
    if (v) CHECKF(v->components == 3 && v->colour && v->colour[0] == 200 && v->colour[1] == 100 && v->colour[2] == 50 &&
                  strstr(v->notes, "TIFF/PNG RGB: colour from the data, opacity and gradients from luminance"),
                  "rgb png: %u components, notes '%s'", v->components, v->notes);
    vxl_volume_destroy(v);
    REQUIRE(tw_write_png(tmp(p, sizeof p, "ga.png"), SW, SH, 2, 8, ga) == 0);
    v = NULL;
    CHECKF(load(p, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    if (v) CHECKF(near(voxel(v, 0), (SH - 1) * SW * 10, 1e-9), "grey+alpha kept grey: %g", voxel(v, 0));
    vxl_volume_destroy(v);
}

/* A two-page RGBA 16-bit TIFF through the helper: a colour volume with
 * its rows flipped (voxel j up) like grey stacks, the opacity source the
 * caller asked for (alpha: its values exactly), the 16-bit colour windowed
 * into 8 bits over the R, G and B range with a note, and its 3 bytes a
 * voxel charged to the budget; 5 channels read as RGB with a note. */
TEST(rgba_tiff_stack_is_a_colour_volume)
{
    char p[256];
    uint16_t px[2 * SH * SW * 4];
    for (int k = 0; k < 2; k++)
        for (int y = 0; y < SH; y++)
            for (int x = 0; x < SW; x++) {
                uint16_t *q = px + 4 * (x + SW * (y + SH * k));
                q[0] = (uint16_t)(1000 * x);        /* R 0..3000 */
                q[1] = (uint16_t)(500 * y);         /* G */
                q[2] = (uint16_t)(3000 * k);        /* B */
                q[3] = (uint16_t)(7 * x + 11 * y + 100 * k + 1); /* alpha */
            }
    REQUIRE(tw_write_tiff(tmp(p, sizeof p, "rgba16.tif"), SW, SH, 2, 4, 16, 1, px) == 0);
    vxl_load_options opt = {.struct_size = sizeof opt, .opacity_source = VXL_OPACITY_SOURCE_ALPHA};
    vxl_volume *v = NULL;
    CHECKF(load(p, &opt, &v) == VXL_OK, "%s", vxl_last_error());
    REQUIRE(v);
    CHECK(v->components == 4 && v->opacity_source == VXL_OPACITY_SOURCE_ALPHA && v->colour && v->dims[2] == 2);
    CHECKF(strstr(v->notes, "TIFF/PNG RGBA: colour from the data, opacity and gradients from the alpha channel") &&
               strstr(v->notes, "windowed over the data's range [0, 3000]"),
           "notes '%s'", v->notes);
    double worst_alpha = 0, worst_colour = 0;
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < SH; j++)
            for (int i = 0; i < SW; i++) {
                const int y = SH - 1 - j; /* the file's row */
                const size_t at = (size_t)i + SW * ((size_t)j + SH * k);
                worst_alpha = fmax(worst_alpha, fabs(voxel(v, at) - (7 * i + 11 * y + 100 * k + 1)));
                const double want[3] = {1000.0 * i, 500.0 * y, 3000.0 * k};
                for (int c = 0; c < 3; c++)
                    worst_colour = fmax(worst_colour, fabs(v->colour[3 * at + c] - floor(want[c] * 255 / 3000 + 0.5)));
            }
    CHECKF(worst_alpha == 0 && worst_colour == 0, "alpha off by %g, colour by %g", worst_alpha, worst_colour);
    vxl_volume_destroy(v);
    /* alpha of RGB data is refused, by the helper's reader as in process */
    uint8_t rgb[SW * SH * 3] = {0};
    REQUIRE(tw_write_tiff(tmp(p, sizeof p, "rgb8.tif"), SW, SH, 1, 3, 8, 1, rgb) == 0);
    v = NULL;
    CHECK(load(p, &opt, &v) == VXL_ERR_INVALID_ARGUMENT && !v);
    CHECKF(strstr(vxl_last_error(), "opacity source alpha needs RGBA data; this has 3 channels"), "%s",
           vxl_last_error());
    /* 5 channels (microscopy): OpenImageIO takes the 4th for alpha when no
     * ExtraSamples say otherwise, so RGBA, and the 5th left out, said */
    uint8_t five[SW * SH * 5];
    for (int i = 0; i < SW * SH * 5; i++) five[i] = (uint8_t)(i * 3);
    REQUIRE(tw_write_tiff(tmp(p, sizeof p, "five.tif"), SW, SH, 1, 5, 8, 1, five) == 0);
    CHECKF(load(p, NULL, &v) == VXL_OK && v->components == 4 && v->colour && v->colour[0] == five[5 * SW * (SH - 1)] &&
               strstr(v->notes, "channel 5 of 5 left out"),
           "%s", v ? v->notes : vxl_last_error());
    vxl_volume_destroy(v);
    v = NULL;
    /* 4x3x1 RGB8: 36 raw bytes, 48 once built (a byte of scalar and 3 of colour a voxel) */
    vxl_load_options small = {.struct_size = sizeof small, .memory_budget_bytes = 40};
    CHECK(load(p, &small, &v) == VXL_ERR_LIMIT && !v);
    CHECKF(strstr(vxl_last_error(), "colour volumes are read whole"), "%s", vxl_last_error());
}

TEST(voxel_size_option_and_old_struct_size)
{
    char p[256];
    uint8_t px[SW * SH * 2];
    for (int k = 0; k < 2; k++) stack_pixels(k, 8, px + k * SW * SH, 1.0);
    REQUIRE(tw_write_tiff(tmp(p, sizeof p, "vs.tif"), SW, SH, 2, 1, 8, 1, px) == 0);
    vxl_load_options opt = {.struct_size = sizeof opt, .voxel_size = {0.5, 0.25, 2.0}};
    vxl_volume *v = NULL;
    REQUIRE(load(p, &opt, &v) == VXL_OK);
    CHECK(v->spacing[0] == 0.5 && v->spacing[1] == 0.25 && v->spacing[2] == 2.0);
    CHECK(v->affine[0] == 0.5 && v->affine[5] == 0.25 && v->affine[10] == 2.0);
    vxl_volume_destroy(v);
    /* a caller built against the first ABI-1 struct (16 bytes) never has
     * its stack memory past struct_size read */
    opt.struct_size = 16;
    REQUIRE(load(p, &opt, &v) == VXL_OK);
    CHECK(v->spacing[0] == 1.0 && v->spacing[2] == 1.0);
    vxl_volume_destroy(v);
}

TEST(stack_errors_missing_slices_mixed_sizes_and_budget)
{
    char p[512], dir[128];
    uint8_t px[8 * 8];
    memset(px, 7, sizeof px);
    snprintf(dir, sizeof dir, "%s/gap", g_dir);
    REQUIRE(mkdir(dir, 0700) == 0);
    int nums[] = {1, 2, 4};
    for (int i = 0; i < 3; i++) {
        snprintf(p, sizeof p, "%s/s_%03d.png", dir, nums[i]);
        REQUIRE(tw_write_png(p, 4, 4, 1, 8, px) == 0);
    }
    snprintf(p, sizeof p, "%s/s_001.png", dir);
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "missing slices between 2", "s_004.png");

    snprintf(dir, sizeof dir, "%s/mixed", g_dir);
    REQUIRE(mkdir(dir, 0700) == 0);
    snprintf(p, sizeof p, "%s/a1.png", dir);
    REQUIRE(tw_write_png(p, 4, 4, 1, 8, px) == 0);
    snprintf(p, sizeof p, "%s/a2.png", dir);
    REQUIRE(tw_write_png(p, 8, 4, 1, 8, px) == 0);
    expect_error(T_, dir, NULL, VXL_ERR_FORMAT, "mixed slices", "a2.png");

    snprintf(dir, sizeof dir, "%s/empty", g_dir);
    REQUIRE(mkdir(dir, 0700) == 0);
    expect_error(T_, dir, NULL, VXL_ERR_FORMAT, "no .tif", NULL);

    /* 40000 x 40000 float pages claimed by a tiny TIFF: refused by the
     * budget before any pixel buffer */
    REQUIRE(tw_write_tiff(tmp(p, sizeof p, "big.tif"), 4, 4, 1, 1, 32, 3, px) == 0);
    FILE *f = fopen(p, "r+b");
    REQUIRE(f);
    /* ImageWidth / ImageLength values of the first IFD */
    unsigned char hdr[8];
    REQUIRE(fread(hdr, 1, 8, f) == 8);
    uint32_t ifd = (uint32_t)hdr[4] | (uint32_t)hdr[5] << 8 | (uint32_t)hdr[6] << 16 | (uint32_t)hdr[7] << 24;
    unsigned char big[4];
    tw_le32(big, 40000);
    fseek(f, (long)ifd + 2 + 8, SEEK_SET);
    fwrite(big, 1, 4, f);
    fseek(f, (long)ifd + 2 + 12 + 8, SEEK_SET);
    fwrite(big, 1, 4, f);
    fclose(f);
    vxl_load_options opt = {.struct_size = sizeof opt, .memory_budget_bytes = 64u << 20};
    expect_error(T_, p, &opt, VXL_ERR_LIMIT, "memory budget", NULL);

    /* a PNG whose IHDR is damaged (bad CRC). (A truncated PNG also fails
     * cleanly, but OpenImageIO 2.4's PNG reader then leaks 31 bytes inside
     * libOpenImageIO, which the ASan run would report.) */
    uint8_t g[16] = {0};
    REQUIRE(tw_write_png(tmp(p, sizeof p, "junk.png"), 4, 4, 1, 8, g) == 0);
    f = fopen(p, "r+b");
    REQUIRE(f);
    fseek(f, 16, SEEK_SET); /* IHDR width */
    fputc(0x7f, f);
    fclose(f);
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "junk.png", NULL);
}

/* -------------------------------------------------------------- dispatch */

TEST(dispatch_by_extension_folder_and_magic)
{
    char p[256], q[256];
    vxl_volume *v = NULL;
    /* NRRD content under an unknown extension is recognised by its magic */
    REQUIRE(write_nrrd(tmp(p, sizeof p, "t.nrrd"), &k_types[0], 0, TW_RAW, NULL, NULL) == 0);
    REQUIRE(rename(p, tmp(q, sizeof q, "volume.data")) == 0);
    CHECKF(load(q, NULL, &v) == VXL_OK, "%s", vxl_last_error());
    vxl_volume_destroy(v);
    /* each extension goes to its reader: garbage is reported in that
     * reader's words */
    static const struct { const char *name, *says; } by_ext[] = {
        {"junk.nrrd", "not a NRRD file"}, {"junk.NHDR", "not a NRRD file"},
        {"junk.mha", "not a MetaImage file"}, {"junk.mhd", "not a MetaImage file"},
        {"junk.nii", "not a NIfTI file"}, {"junk.nii.gz", "not a NIfTI file"}, {"junk.hdr", "not a NIfTI file"},
        {"junk.xyz", "not a NIfTI file"}, {"junk.tif", "junk.tif"}, {"junk.PNG", "junk.PNG"},
        {"junk.vdb", "cannot read OpenVDB file"},
    };
    for (size_t i = 0; i < sizeof by_ext / sizeof by_ext[0]; i++) {
        tmp(p, sizeof p, by_ext[i].name);
        write_text(p, "hello, this is no volume at all\n");
        expect_error(T_, p, NULL, VXL_ERR_FORMAT, by_ext[i].says, NULL);
        unlink(p);
    }
    /* OpenVDB's magic (0x56444220 little-endian) under another name */
    static const char vdb_head[24] = " BDV";
    REQUIRE(tw_write(tmp(p, sizeof p, "smoke.cache"), vdb_head, sizeof vdb_head, NULL, 0) == 0);
    expect_error(T_, p, NULL, VXL_ERR_FORMAT, "cannot read OpenVDB file", NULL);
    /* a folder is an image stack */
    char dir[128];
    snprintf(dir, sizeof dir, "%s/nothing_here", g_dir);
    REQUIRE(mkdir(dir, 0700) == 0);
    expect_error(T_, dir, NULL, VXL_ERR_FORMAT, "no .tif", NULL);
    /* the NIfTI default still reports its own error for an unknown file */
    expect_error(T_, "/no/such/file.xyz", NULL, VXL_ERR_IO, "/no/such/file.xyz", NULL);
}

/* ------------------------------------------------------- crash replay */

static int crashers_replayed;

static void replay_dir(vxl_test_ctx *T_, const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *ent;
    char p[1024];
    while ((ent = readdir(d)) != NULL) {
        if (ent->d_name[0] == '.') continue;
        snprintf(p, sizeof p, "%s/%s", dir, ent->d_name);
        struct stat st;
        if (stat(p, &st) != 0) continue;
        if (S_ISDIR(st.st_mode)) {
            replay_dir(T_, p);
            continue;
        }
        /* each crasher under a name its loader dispatches on: the format
         * directory's name is the extension */
        const char *fmt = strrchr(dir, '/');
        fmt = fmt ? fmt + 1 : dir;
        static const char *const ext[][2] = {
            {"nifti", "nii"}, {"nrrd", "nrrd"}, {"metaimage", "mha"}, {"tiff", "tif"}, {"png", "png"},
            {"dicom", "dcm"}};
        const char *x = fmt;
        for (size_t i = 0; i < sizeof ext / sizeof ext[0]; i++)
            if (!strcmp(fmt, ext[i][0])) x = ext[i][1];
        char q[256];
        snprintf(q, sizeof q, "%s/crasher.%s", g_dir, x);
        FILE *in = fopen(p, "rb");
        if (!in) continue;
        unsigned char buf[1 << 16];
        size_t n = fread(buf, 1, sizeof buf, in);
        fclose(in);
        tw_write(q, buf, n, NULL, 0);
        vxl_load_options opt = {.struct_size = sizeof opt, .memory_budget_bytes = 64u << 20, .max_dim = 4096};
        vxl_volume *v = NULL;
        int rc = load(q, &opt, &v);
        CHECKF(rc == VXL_OK ? v != NULL : (v == NULL && vxl_last_error()[0] != '\0'), "%s: rc %d", p, rc);
        vxl_volume_destroy(v);
        unlink(q);
        crashers_replayed++;
    }
    closedir(d);
}

/* The corpus: VOXLIGHT_CRASHERS, else tests/crashers of the tree this test
 * was built in (found from the executable, BUILD/tests/test_loaders, so any
 * working directory works). Replaying nothing is a failure, not a pass. */
TEST(crash_corpus_replays_without_crashing)
{
    char dir[1024];
    const char *env = getenv("VOXLIGHT_CRASHERS");
    if (env && env[0]) {
        snprintf(dir, sizeof dir, "%s", env);
    } else {
        char exe[900];
        ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
        REQUIRE(n > 0);
        exe[n] = '\0';
        for (int up = 0; up < 3; up++) { /* test_loaders, tests, build */
            char *slash = strrchr(exe, '/');
            REQUIRE(slash != NULL);
            *slash = '\0';
        }
        snprintf(dir, sizeof dir, "%s/tests/crashers", exe);
    }
    replay_dir(T_, dir);
    fprintf(stderr, "  replayed %d crashers from %s\n", crashers_replayed, dir);
    CHECKF(crashers_replayed > 0, "no crasher replayed from %s (missing or empty corpus)", dir);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_loaders_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(nrrd_every_type_both_byte_orders_raw_and_gzip);
    RUN(nrrd_detached_header_skips_and_data_at_end);
    RUN(nrrd_space_directions_and_origin_give_the_ras_affine);
    RUN(nrrd_4d_reads_the_first_volume_and_2d_is_one_slice);
    RUN(nrrd_hostile_headers_give_clear_errors);
    RUN(nrrd_absurd_sizes_are_refused_before_allocation_naming_the_budget);
    RUN(metaimage_every_type_both_byte_orders_raw_and_zlib);
    RUN(metaimage_detached_and_header_size);
    RUN(metaimage_geometry_is_converted_from_lps_to_ras);
    RUN(metaimage_hostile_headers_give_clear_errors);
    RUN(multipage_tiff_8_16_float);
    RUN(numbered_series_and_folders_of_png_and_tiff);
    RUN(rgba_tiff_stack_is_a_colour_volume);
    RUN(voxel_size_option_and_old_struct_size);
    RUN(stack_errors_missing_slices_mixed_sizes_and_budget);
    RUN(dispatch_by_extension_folder_and_magic);
    RUN(crash_corpus_replays_without_crashing);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
