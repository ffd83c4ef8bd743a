/* test_brick_source.c - CPU side: brick sources serve exactly
 * what the whole volume holds. The memory source against the whole volume
 * at every level (the LOD fallback's downsampling, storage/lod.c) and in any
 * box; every source's index against the skipping grid's CPU copy
 * (vxl_bricks_minmax_cpu); the raw source over NIfTI, NRRD and MetaImage
 * files of every type and both byte orders against the whole load; sparse
 * files whose holes are not read; truncated files, over-claiming headers
 * and cancelled passes as errors; a sparse NIfTI of more than 24 GB opened
 * streamed with bounded memory. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fuzz/writers.h"
#include "harness.h"
#include "os.h"
#include "loader_test_util.h"
#include "nifti_writer.h"
#include "stream_compare.h"
#include "voxlight_dev.h"

static char g_dir[256];

static const char *tmp(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
    return buf;
}

static vxl_load_options load_options(uint32_t streaming)
{
    vxl_load_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.streaming = streaming;
    return o;
}

static uint32_t dtype_bytes(uint32_t dtype)
{
    return dtype == VXL_DTYPE_F64 ? 8 : dtype >= VXL_DTYPE_U32 ? 4 : dtype >= VXL_DTYPE_U16 ? 2 : 1;
}

/* Deterministic voxels of dtype with structure and noise (floats: values far
 * outside [0, 1] so normalisation matters, and, with specials, NaN and
 * +-Inf sprinkled in), native byte order. */
static void *make_raw(uint32_t dtype, uint32_t nx, uint32_t ny, uint32_t nz, int specials)
{
    const size_t n = (size_t)nx * ny * nz;
    const uint32_t es = dtype_bytes(dtype);
    uint8_t *raw = malloc(n * es);
    if (!raw) return NULL;
    uint32_t s = 12345;
    for (size_t i = 0; i < n; i++) {
        s = s * 1664525u + 1013904223u;
        const double x = (double)(i % nx) / nx, y = (double)(i / nx % ny) / ny, z = (double)(i / nx / ny) / nz;
        const double f = sin(6 * x) * cos(5 * y) + z + (s >> 24) / 512.0; /* about -1 .. 2.5 */
        switch (dtype) {
        case VXL_DTYPE_U8: raw[i] = (uint8_t)(f * 70 + 80); break;
        case VXL_DTYPE_I8: ((int8_t *)raw)[i] = (int8_t)(f * 40); break;
        case VXL_DTYPE_U16: ((uint16_t *)raw)[i] = (uint16_t)(f * 9000 + 10000); break;
        case VXL_DTYPE_I16: ((int16_t *)raw)[i] = (int16_t)(f * 9000); break;
        case VXL_DTYPE_U32: ((uint32_t *)raw)[i] = (uint32_t)(f * 1e6 + 2e6); break;
        case VXL_DTYPE_I32: ((int32_t *)raw)[i] = (int32_t)(f * 1e6); break;
        case VXL_DTYPE_F32: ((float *)raw)[i] = (float)(f * 1000); break;
        default: ((double *)raw)[i] = f * 1e5; break;
        }
        if (specials && (dtype == VXL_DTYPE_F32 || dtype == VXL_DTYPE_F64) && (i % 97 == 5 || i % 101 == 7)) {
            const double x = i % 97 == 5 ? NAN : (i & 1) ? INFINITY : -INFINITY;
            if (dtype == VXL_DTYPE_F32) ((float *)raw)[i] = (float)x;
            else ((double *)raw)[i] = x;
        }
    }
    return raw;
}

static vxl_volume *make_volume(uint32_t dtype, uint32_t nx, uint32_t ny, uint32_t nz)
{
    void *raw = make_raw(dtype, nx, ny, nz, 0);
    if (!raw) return NULL;
    const vxl_volume_desc d = {.struct_size = sizeof d, .dtype = dtype, .dims = {nx, ny, nz}, .data = raw};
    vxl_volume *v = NULL;
    vxl_volume_create(&d, NULL, &v);
    free(raw);
    return v;
}

TEST(memory_source_serves_the_whole_volume_at_every_level)
{
    static const uint32_t types[] = {VXL_DTYPE_U8, VXL_DTYPE_I16, VXL_DTYPE_U16, VXL_DTYPE_F32};
    static const uint32_t sizes[][3] = {{37, 23, 19}, {64, 40, 33}, {9, 1, 5}};
    for (size_t t = 0; t < sizeof types / sizeof types[0]; t++)
        for (size_t z = 0; z < sizeof sizes / sizeof sizes[0]; z++) {
            vxl_volume *w = make_volume(types[t], sizes[z][0], sizes[z][1], sizes[z][2]), *s = NULL;
            REQUIRE(w);
            REQUIRE(vxl_volume_stream_copy(w, 5, &s) == VXL_OK);
            CHECK(s->texels == NULL && s->source != NULL && s->source->n_levels == 5);
            vxl_volume_info wi, si;
            memset(&wi, 0, sizeof wi);
            memset(&si, 0, sizeof si);
            wi.struct_size = si.struct_size = sizeof wi;
            CHECK(vxl_volume_get_info(w, &wi) == VXL_OK && vxl_volume_get_info(s, &si) == VXL_OK);
            CHECK(si.streamed == 1 && wi.streamed == 0 && si.level_count == 5 && wi.level_count == 1);
            CHECK(si.storage_bytes == wi.storage_bytes && si.value_min == wi.value_min && si.value_max == wi.value_max);
            same_levels(T_, w, s, 5);
            same_index(T_, w, s);
            vxl_volume_destroy(s);
            vxl_volume_destroy(w);
        }
}

/* ------------------------------------------------------------ files */

typedef struct dtype_case {
    uint32_t dtype;
    int nifti;
    const char *nrrd, *met;
} dtype_case;

static const dtype_case k_types[] = {
    {VXL_DTYPE_U8, 2, "uchar", "MET_UCHAR"},     {VXL_DTYPE_I8, 256, "signed char", "MET_CHAR"},
    {VXL_DTYPE_U16, 512, "ushort", "MET_USHORT"}, {VXL_DTYPE_I16, 4, "short", "MET_SHORT"},
    {VXL_DTYPE_U32, 768, "uint", "MET_UINT"},     {VXL_DTYPE_I32, 8, "int", "MET_INT"},
    {VXL_DTYPE_F32, 16, "float", "MET_FLOAT"},    {VXL_DTYPE_F64, 64, "double", "MET_DOUBLE"},
};

static int host_big(void)
{
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 0;
}

#define FX 70
#define FY 33
#define FZ 17

/* Writes voxels (native order) of t as format 0 NIfTI-1, 1 NIfTI-2 .hdr/.img,
 * 2 NRRD, 3 MetaImage, in the byte order `big`. */
static int write_case(const char *path, int format, const dtype_case *t, int big, const void *raw)
{
    const size_t n = (size_t)FX * FY * FZ, es = dtype_bytes(t->dtype);
    if (format < 2) {
        tnw_header h;
        tnw_init(&h, format + 1, t->nifti, FX, FY, FZ);
        h.swap = big != host_big();
        if (t->dtype >= VXL_DTYPE_U32) { /* scaled: raw * 2 - 3 */
            h.scl_slope = 2.0;
            h.scl_inter = -3.0;
        }
        return tnw_write(path, &h, raw, n * es);
    }
    void *sw = es > 1 && big != host_big() ? tw_swapped(raw, n, es) : NULL;
    char head[512];
    if (format == 2)
        snprintf(head, sizeof head, "NRRD0004\ntype: %s\ndimension: 3\nsizes: %d %d %d\nencoding: raw\nendian: %s\n\n",
                 t->nrrd, FX, FY, FZ, big ? "big" : "little");
    else
        snprintf(head, sizeof head,
                 "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = %s\n"
                 "DimSize = %d %d %d\nElementType = %s\nElementDataFile = LOCAL\n",
                 big ? "True" : "False", FX, FY, FZ, t->met);
    int rc = tw_write_header_data(path, head, sw ? sw : raw, n * es, TW_RAW, NULL);
    free(sw);
    return rc;
}


static int load_mode(const char *path, uint32_t mode, vxl_volume **v)
{
    vxl_load_options o = load_options(mode);
    return vxl_volume_load(path, &o, v);
}

TEST(raw_source_equals_the_whole_load_for_every_type_and_byte_order)
{
    static const char *names[] = {"t.nii", "t.hdr", "t.nrrd", "t.mha"};
    char p[512], what[128];
    for (size_t k = 0; k < sizeof k_types / sizeof k_types[0]; k++) {
        void *raw = make_raw(k_types[k].dtype, FX, FY, FZ, 1);
        REQUIRE(raw);
        for (int format = 0; format < 4; format++)
            for (int big = 0; big < 2; big++) {
                /* the big-endian half reads every coarse level by averaging level-0 reads */
                if (big) vxl_os_set_env("VOXLIGHT_SOURCE_KEEP_BYTES", "0");
                snprintf(what, sizeof what, "%s %s %s", names[format], k_types[k].nrrd, big ? "big" : "little");
                REQUIRE(write_case(tmp(p, sizeof p, names[format]), format, &k_types[k], big, raw) == 0);
                vxl_volume *w = NULL, *s = NULL;
                CHECKF(load_mode(p, VXL_STREAMING_OFF, &w) == VXL_OK, "%s: %s", what, vxl_last_error());
                CHECKF(load_mode(p, VXL_STREAMING_ON, &s) == VXL_OK, "%s: %s", what, vxl_last_error());
                if (w && s) {
                    CHECK(s->texels == NULL && s->source != NULL && w->source == NULL);
                    same_volume(T_, w, s, what);
                }
                vxl_volume_destroy(w);
                vxl_volume_destroy(s);
                vxl_os_set_env("VOXLIGHT_SOURCE_KEEP_BYTES", NULL);
            }
        free(raw);
    }
}

TEST(auto_streams_only_over_half_the_budget)
{
    char p[512];
    void *raw = make_raw(VXL_DTYPE_I16, FX, FY, FZ, 0);
    REQUIRE(raw);
    REQUIRE(write_case(tmp(p, sizeof p, "auto.nii"), 0, &k_types[3], host_big(), raw) == 0);
    free(raw);
    const uint64_t texture = (uint64_t)FX * FY * FZ * 2;
    vxl_load_options o = load_options(VXL_STREAMING_AUTO);
    vxl_volume *v = NULL;
    o.memory_budget_bytes = 2 * texture + 2; /* half the budget holds it: whole */
    REQUIRE(vxl_volume_load(p, &o, &v) == VXL_OK);
    CHECK(v->texels != NULL && v->source == NULL);
    vxl_volume_destroy(v);
    o.memory_budget_bytes = 2 * texture - 2; /* over half: streamed */
    REQUIRE(vxl_volume_load(p, &o, &v) == VXL_OK);
    CHECK(v->texels == NULL && v->source != NULL);
    vxl_volume_info i;
    info_of(v, &i);
    CHECK(i.streamed == 1 && i.storage_bytes == texture && i.resident_bytes > 0 && i.resident_bytes < texture);
    vxl_volume_destroy(v);
    o.memory_budget_bytes = texture / 2; /* streaming off: over the budget is an error, as always */
    o.streaming = VXL_STREAMING_OFF;
    CHECK(vxl_volume_load(p, &o, &v) == VXL_ERR_LIMIT && strstr(vxl_last_error(), "budget"));
    /* an options struct from before streaming (no streaming field) is AUTO */
    o.struct_size = (uint32_t)offsetof(vxl_load_options, streaming);
    o.streaming = VXL_STREAMING_OFF;
    o.memory_budget_bytes = 2 * texture - 2;
    REQUIRE(vxl_volume_load(p, &o, &v) == VXL_OK);
    CHECK(v->source != NULL);
    vxl_volume_destroy(v);
}

TEST(gzip_nifti_streams_through_the_brick_cache)
{
    /* the loader's routing: a .nii.gz streams through the bricked cache
     * (io/brick_cache.c), with the whole load's value mapping and level 0 */
    char p[512];
    void *raw = make_raw(VXL_DTYPE_I16, FX, FY, FZ, 0);
    REQUIRE(raw);
    tnw_header h;
    tnw_init(&h, 1, 4, FX, FY, FZ);
    REQUIRE(tnw_write(tmp(p, sizeof p, "c.nii.gz"), &h, raw, (size_t)FX * FY * FZ * 2) == 0);
    free(raw);
    vxl_volume *w = NULL, *s = NULL;
    REQUIRE(load_mode(p, VXL_STREAMING_OFF, &w) == VXL_OK);
    vxl_load_options o = load_options(VXL_STREAMING_ON);
    o.cache_dir = g_dir;
    CHECKF(vxl_volume_load(p, &o, &s) == VXL_OK, "%s", vxl_last_error());
    if (s) {
        vxl_volume_info wi, si;
        info_of(w, &wi);
        info_of(s, &si);
        CHECK(si.streamed == 1 && si.value_min == wi.value_min && si.value_max == wi.value_max);
        CHECK(s->tex_lo == w->tex_lo && s->tex_hi == w->tex_hi && si.storage_bytes == wi.storage_bytes);
        CHECKF(!same_levels(T_, w, s, 1), "level 0 through the cache differs");
    }
    vxl_volume_destroy(w);
    vxl_volume_destroy(s);
}

/* Loads p with streaming mode and budget; returns the code, *msg the error. */
static int load_budget(const char *p, uint32_t mode, uint64_t budget, vxl_volume **v)
{
    vxl_load_options o = load_options(mode);
    o.memory_budget_bytes = budget;
    return vxl_volume_load(p, &o, v);
}

TEST(formats_without_random_access_load_whole_or_say_streaming_is_unavailable)
{
    char p[512];
    uint8_t px[8 * 8 * 4];
    for (size_t i = 0; i < sizeof px; i++) px[i] = (uint8_t)(i * 7);
    /* a colour TIFF (read whole by its helper: only single-sample pages stream,
     * test_tiff_stream.c) and a PNG (attached gzip NRRD and zlib MetaImage
     * data stream through the brick cache: test_brick_cache.c) */
    REQUIRE(tw_write_tiff(tmp(p, sizeof p, "w.tif"), 8, 8, 1, 3, 8, 1, px) == 0);
    char png[512];
    REQUIRE(tw_write_png(tmp(png, sizeof png, "w.png"), 8, 4, 1, 8, px) == 0);
    const char *files[] = {p, png}, *names[] = {"TIFF", "PNG"};
    for (int f = 0; f < 2; f++) {
        vxl_volume *v = NULL;
        /* streaming asked for, and the volume fits: read whole */
        CHECKF(load_budget(files[f], VXL_STREAMING_ON, 1 << 20, &v) == VXL_OK, "%s: %s", files[f], vxl_last_error());
        CHECK(v && v->texels && !v->source && v->dims[0] == 8);
        vxl_volume_destroy(v);
        v = NULL;
        /* over the budget: the limit, saying streaming is not available for it */
        CHECK(load_budget(files[f], VXL_STREAMING_ON, 20, &v) == VXL_ERR_LIMIT && !v);
        CHECKF(strstr(vxl_last_error(), "streaming is not available") && strstr(vxl_last_error(), names[f]), "%s",
               vxl_last_error());
        CHECK(load_budget(files[f], VXL_STREAMING_AUTO, 20, &v) == VXL_ERR_LIMIT &&
              strstr(vxl_last_error(), "streaming is not available"));
        /* OFF: the whole read's limit; the colour TIFF is a colour volume,
         * read whole whatever the option, and its limit says so */
        CHECKF(load_budget(files[f], VXL_STREAMING_OFF, 20, &v) == VXL_ERR_LIMIT && strstr(vxl_last_error(), "budget") &&
                   (f == 0 ? strstr(vxl_last_error(), "colour volumes are read whole") != NULL
                           : !strstr(vxl_last_error(), "streaming")),
               "%s", vxl_last_error());
    }
}

/* A NIfTI-1 header for nx*ny*nz u8 (or i16) voxels at offset 352. */
static void sparse_header(unsigned char head[352], int datatype, int64_t nx, int64_t ny, int64_t nz)
{
    tnw_header h;
    tnw_init(&h, 1, datatype, nx, ny, nz);
    memset(head, 0, 352);
    tnw_build_v1(&h, 0, 352, head);
}

/* Writes a ball of value `value` (es bytes, native order) into the sparse
 * file, row by row, so only its rows become data. */
static int write_ball(int fd, size_t es, const uint32_t d[3], const int c[3], int r, const void *value)
{
    unsigned char row[4096 * 8];
    for (int z = c[2] - r; z <= c[2] + r; z++)
        for (int y = c[1] - r; y <= c[1] + r; y++) {
            const int dy = y - c[1], dz = z - c[2], h2 = r * r - dy * dy - dz * dz;
            if (h2 < 0) continue;
            const int h = (int)sqrt((double)h2);
            for (int x = 0; x < 2 * h + 1; x++) memcpy(row + x * es, value, es);
            const uint64_t off = 352 + es * ((uint64_t)(c[0] - h) + d[0] * ((uint64_t)y + (uint64_t)d[1] * z));
            if (pwrite(fd, row, (size_t)(2 * h + 1) * es, (off_t)off) != (ssize_t)((2 * h + 1) * es)) return -1;
        }
    return 0;
}

static uint64_t bytes_read_of(const vxl_volume *v)
{
    vxl_volume_info i;
    info_of(v, &i);
    return i.bytes_read;
}

TEST(sparse_file_streams_without_reading_its_holes)
{
    char p[512];
    const uint32_t d[3] = {400, 300, 120};
    unsigned char head[352];
    sparse_header(head, 4, d[0], d[1], d[2]); /* int16: a hole (raw 0) is texel 32768, not 0 */
    int fd = open(tmp(p, sizeof p, "sparse.nii"), O_CREAT | O_TRUNC | O_RDWR, 0644);
    REQUIRE(fd >= 0);
    const uint64_t size = 352 + (uint64_t)d[0] * d[1] * d[2] * 2;
    CHECK(pwrite(fd, head, 352, 0) == 352 && ftruncate(fd, (off_t)size) == 0);
    const int16_t a = 1200, b = -700;
    const int c1[3] = {100, 80, 30}, c2[3] = {300, 200, 90};
    CHECK(write_ball(fd, 2, d, c1, 14, &a) == 0 && write_ball(fd, 2, d, c2, 9, &b) == 0);
    struct stat st;
    CHECK(fstat(fd, &st) == 0);
    close(fd);
    const uint64_t allocated = (uint64_t)st.st_blocks * 512;
    CHECKF(allocated < size / 8, "the file is not sparse here (%llu of %llu bytes allocated)",
           (unsigned long long)allocated, (unsigned long long)size);
    vxl_volume *w = NULL, *s = NULL;
    REQUIRE(load_mode(p, VXL_STREAMING_ON, &s) == VXL_OK);
    const uint64_t opened = bytes_read_of(s);
    /* the pass read the data extents only: never more than the blocks the file has */
    CHECKF(opened > 0 && opened <= allocated, "the pass read %llu bytes; the file has %llu allocated",
           (unsigned long long)opened, (unsigned long long)allocated);
    REQUIRE(load_mode(p, VXL_STREAMING_OFF, &w) == VXL_OK);
    CHECK(s->value_min == -700 && s->value_max == 1200);
    same_volume(T_, w, s, "sparse int16");
    vxl_volume_destroy(w);
    vxl_volume_destroy(s);
}

static int g_calls, g_cancel_at;
static double g_last;
static int count_progress(void *user, double fraction, const char *stage)
{
    (void)user;
    if (!stage || fraction < g_last || fraction < 0 || fraction > 1) g_last = 2; /* marks a bad call */
    else g_last = fraction;
    return ++g_calls >= g_cancel_at;
}

TEST(truncated_over_claiming_and_cancelled_opens_fail_cleanly)
{
    char p[512];
    void *raw = make_raw(VXL_DTYPE_F32, FX, FY, FZ, 0);
    REQUIRE(raw);
    const size_t full = (size_t)FX * FY * FZ * 4;
    tnw_header h;
    tnw_init(&h, 1, 16, FX, FY, FZ);
    REQUIRE(tnw_write(tmp(p, sizeof p, "short.nii"), &h, raw, full - 100) == 0);
    vxl_volume *v = NULL;
    CHECK(load_mode(p, VXL_STREAMING_ON, &v) == VXL_ERR_FORMAT && v == NULL);
    CHECKF(strstr(vxl_last_error(), "short.nii") && strstr(vxl_last_error(), "truncated"), "%s", vxl_last_error());
    /* a header claiming 54 TB over a small file: an error naming it, nothing allocated for it */
    tnw_init(&h, 2, 2, 60000, 30000, 30000);
    REQUIRE(tnw_write(tmp(p, sizeof p, "claims.nii"), &h, raw, 4096) == 0);
    CHECK(load_mode(p, VXL_STREAMING_ON, &v) == VXL_ERR_FORMAT && v == NULL);
    CHECKF(strstr(vxl_last_error(), "claims.nii") && strstr(vxl_last_error(), "truncated"), "%s", vxl_last_error());
    /* the same under AUTO reports the budget, as the whole read always has */
    CHECK(load_mode(p, VXL_STREAMING_AUTO, &v) == VXL_ERR_LIMIT && strstr(vxl_last_error(), "budget"));
    /* past the per-axis limit */
    tnw_init(&h, 2, 2, 70000, 2, 2);
    REQUIRE(tnw_write(tmp(p, sizeof p, "wide.nii"), &h, raw, 4096) == 0);
    CHECK(load_mode(p, VXL_STREAMING_ON, &v) == VXL_ERR_LIMIT && strstr(vxl_last_error(), "per-axis"));

    /* progress: called in order within [0, 1], ending at 1; a nonzero return cancels */
    tnw_init(&h, 1, 16, FX, FY, FZ);
    REQUIRE(tnw_write(tmp(p, sizeof p, "ok.nii"), &h, raw, full) == 0);
    vxl_load_options o = load_options(VXL_STREAMING_ON);
    o.progress = count_progress;
    g_calls = 0;
    g_last = 0;
    g_cancel_at = 1 << 30;
    CHECK(vxl_volume_load(p, &o, &v) == VXL_OK);
    CHECKF(g_calls >= 2 && g_last == 1.0, "%d calls, last %g", g_calls, g_last);
    vxl_volume_destroy(v);
    v = NULL;
    for (int at = 1; at <= 2; at++) { /* during the range pass, then the texel pass of a float file */
        g_calls = 0;
        g_last = 0;
        g_cancel_at = at;
        CHECK(vxl_volume_load(p, &o, &v) == VXL_ERR_CANCELLED && v == NULL);
        CHECK(g_calls == at && strstr(vxl_last_error(), "cancel"));
    }
    free(raw);
}

TEST(a_sparse_file_larger_than_memory_opens_with_bounded_memory)
{
    char p[512];
    const uint32_t d[3] = {4096, 4096, 1600}; /* 26.8 GB of uint8: more than this machine's 24 GB */
    unsigned char head[352];
    sparse_header(head, 2, d[0], d[1], d[2]);
    int fd = open(tmp(p, sizeof p, "huge_sparse.nii"), O_CREAT | O_TRUNC | O_RDWR, 0644);
    REQUIRE(fd >= 0);
    const uint64_t size = 352 + (uint64_t)d[0] * d[1] * d[2];
    const uint8_t a = 200, b = 90;
    const int c1[3] = {1000, 3000, 400}, c2[3] = {3500, 700, 1300};
    int ok = pwrite(fd, head, 352, 0) == 352 && ftruncate(fd, (off_t)size) == 0;
    ok = ok && write_ball(fd, 1, d, c1, 12, &a) == 0 && write_ball(fd, 1, d, c2, 8, &b) == 0;
    struct stat st;
    ok = ok && fstat(fd, &st) == 0;
    close(fd);
    if (!ok) unlink(p);
    REQUIRE(ok);
    const long before = peak_rss_kb(1);
    vxl_volume *v = NULL;
    int rc = load_mode(p, VXL_STREAMING_AUTO, &v); /* 26.8 GB is far over half the default 2 GiB budget */
    const long after = peak_rss_kb(0);
    CHECKF(rc == VXL_OK, "%s", vxl_last_error());
    if (rc == VXL_OK) {
        vxl_volume_info i;
        info_of(v, &i);
        CHECK(i.streamed == 1 && i.storage_bytes == size - 352 && i.level_count == 8);
        fprintf(stderr, "  opened %.1f GB: peak RSS +%ld MB, source holds %llu MB, read %llu kB\n", size / 1e9,
                (after - before) / 1024, (unsigned long long)(i.resident_bytes >> 20),
                (unsigned long long)(i.bytes_read >> 10));
        CHECKF(after - before < 256 * 1024, "opening raised the peak RSS by %ld MB", (after - before) / 1024);
        CHECKF(i.resident_bytes < (128ull << 20), "the source holds %llu MB", (unsigned long long)(i.resident_bytes >> 20));
        CHECKF(i.bytes_read <= (uint64_t)st.st_blocks * 512, "read %llu bytes of %llu allocated",
               (unsigned long long)i.bytes_read, (unsigned long long)st.st_blocks * 512);
        CHECK(i.value_min == 0 && i.value_max == 200);
        /* the ball's centre voxel and a hole, at level 0; the ball shows in the index */
        const uint32_t lo[3] = {(uint32_t)c1[0], (uint32_t)c1[1], (uint32_t)c1[2]}, one[3] = {1, 1, 1};
        const uint32_t hole[3] = {10, 10, 10};
        uint8_t t = 0;
        CHECK(vxl_volume_read_level(v, 0, lo, one, &t) == VXL_OK && t == 200);
        CHECK(vxl_volume_read_level(v, 0, hole, one, &t) == VXL_OK && t == 0);
        uint32_t brick = 0, id[3];
        CHECK(vxl_volume_brick_index(v, &brick, id, NULL, 0) == VXL_OK);
        float mm[2] = {0, 0};
        const size_t bi = c1[0] / brick + (size_t)id[0] * (c1[1] / brick + (size_t)id[1] * (c1[2] / brick));
        CHECK(vxl_volume_brick_index(v, &brick, id, NULL, 0) == VXL_OK && brick >= 8);
        float *grid = malloc((size_t)id[0] * id[1] * id[2] * 2 * sizeof *grid);
        if (grid && vxl_volume_brick_index(v, &brick, id, grid, (size_t)id[0] * id[1] * id[2] * 2) == VXL_OK) {
            memcpy(mm, grid + 2 * bi, sizeof mm);
            CHECK(mm[0] == 0.0f && mm[1] == (float)(200 / 255.0));
            CHECK(grid[0] == 0.0f && grid[1] == 0.0f); /* a brick in the holes */
        }
        free(grid);
    }
    vxl_volume_destroy(v);
    unlink(p);
}

/* Runs every test, or those whose name contains argv[1]. */
#define RUN_IF(name)                                        \
    do {                                                    \
        if (!only || strstr(#name, only)) RUN(name);        \
    } while (0)

int main(int argc, char **argv)
{
    const char *only = argc > 1 ? argv[1] : NULL;
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_brick_source_XXXXXX");
    if (!mkdtemp(g_dir)) return 1;
    /* first, so the peak it measures is not an earlier test's */
    RUN_IF(a_sparse_file_larger_than_memory_opens_with_bounded_memory);
    RUN_IF(memory_source_serves_the_whole_volume_at_every_level);
    RUN_IF(raw_source_equals_the_whole_load_for_every_type_and_byte_order);
    RUN_IF(auto_streams_only_over_half_the_budget);
    RUN_IF(gzip_nifti_streams_through_the_brick_cache);
    RUN_IF(formats_without_random_access_load_whole_or_say_streaming_is_unavailable);
    RUN_IF(sparse_file_streams_without_reading_its_holes);
    RUN_IF(truncated_over_claiming_and_cancelled_opens_fail_cleanly);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
