/* test_tiff_stream.c - uncompressed multi-page TIFF files stream,
 * read by offset (csrc/io/tiff_layout.c decides, csrc/io/raw_source.c
 * reads). TIFFs written here (classic and BigTIFF, both byte orders, every
 * pixel type the whole read maps, several strips per page) load streamed
 * equal to the whole read through OpenImageIO (streaming OFF) texel for
 * texel at every level, with the index and the geometry, and the row flip
 * checked against the written pixels; files that cannot stream (compressed,
 * colour, half-float, strips apart) are read whole and say why over the
 * budget; a truncated file is an error naming it; a 5 GB sparse BigTIFF
 * opens under AUTO with a 512 MB budget and bounded memory.
 * `test_tiff_stream --write-seeds DIR` writes small TIFFs as fuzz seeds
 * (tests/fuzz/run.sh, fuzz_tiff_layout). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "harness.h"
#include "os.h"
#include "loader_test_util.h"
#include "stream_compare.h"
#include "voxlight_dev.h"

static char g_dir[256];

static const char *tmp(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
    return buf;
}

/* ------------------------------------------------------------ the writer */

typedef struct tiff_spec {
    int be, big;                 /* byte order "MM", BigTIFF */
    uint32_t w, h, pages, spp;
    uint32_t bits, format;       /* BitsPerSample, SampleFormat (1 uint, 2 int, 3 float) */
    uint32_t rps;                /* rows per strip */
    uint32_t compression;        /* 1: none (the pixels are written raw whatever it says) */
    uint32_t gap;                /* bytes between strips (0: contiguous) */
} tiff_spec;

static void put(const tiff_spec *sp, uint8_t *p, uint64_t v, int n)
{
    for (int i = 0; i < n; i++) p[sp->be ? n - 1 - i : i] = (uint8_t)(v >> (8 * i));
}

static uint32_t strips_of(const tiff_spec *sp) { return (sp->h + sp->rps - 1) / sp->rps; }
static uint64_t row_bytes(const tiff_spec *sp) { return (uint64_t)sp->w * sp->spp * (sp->bits / 8); }
static uint64_t page_span(const tiff_spec *sp)
{
    return row_bytes(sp) * sp->h + (uint64_t)(strips_of(sp) - 1) * sp->gap;
}

/* Bytes of one page's directory block (the directory, then its arrays). */
static uint64_t ifd_block(const tiff_spec *sp)
{
    const uint64_t b = (sp->big ? 16 : 6) + 10 * (sp->big ? 20 : 12) + 2 * (uint64_t)strips_of(sp) * 8 + 16;
    return (b + 7) & ~7ull;
}

/* Where the pixels start: after the header and every page's directory. */
static uint64_t data_start(const tiff_spec *sp) { return 16 + (uint64_t)sp->pages * ifd_block(sp); }

/* The directories (header included): data_start(sp) bytes. */
static uint8_t *directories(const tiff_spec *sp)
{
    const uint64_t n = data_start(sp), blk = ifd_block(sp), d0 = data_start(sp);
    uint8_t *b = calloc(1, n);
    if (!b) return NULL;
    memcpy(b, sp->be ? "MM" : "II", 2);
    put(sp, b + 2, sp->big ? 43 : 42, 2);
    if (sp->big) {
        put(sp, b + 4, 8, 2);
        put(sp, b + 8, 16, 8);
    } else {
        put(sp, b + 4, 16, 4);
    }
    const int esz = sp->big ? 20 : 12, cnt = sp->big ? 8 : 2, field = sp->big ? 8 : 4, osz = sp->big ? 8 : 4;
    const uint32_t strips = strips_of(sp);
    for (uint32_t p = 0; p < sp->pages; p++) {
        const uint64_t ifd = 16 + p * blk, arrays = ifd + cnt + 10 * esz + field;
        uint8_t *e = b + ifd + cnt;
        int k = 0;
        uint64_t extra = arrays;
        /* one entry: values inline when they fit, else in the block after the directory */
#define ENTRY(tag, type, tsz, count, ...)                                                      \
    do {                                                                                       \
        const uint64_t vals_[] = {__VA_ARGS__};                                                \
        put(sp, e + esz * k, tag, 2);                                                          \
        put(sp, e + esz * k + 2, type, 2);                                                     \
        put(sp, e + esz * k + 4, count, sp->big ? 8 : 4);                                      \
        uint8_t *v_ = e + esz * k + (sp->big ? 12 : 8);                                        \
        if ((uint64_t)(count) * (tsz) > (uint64_t)field) {                                     \
            put(sp, v_, extra, field);                                                         \
            v_ = b + extra;                                                                    \
            extra += (uint64_t)(count) * (tsz);                                                \
        }                                                                                      \
        for (uint64_t i_ = 0; i_ < (uint64_t)(count); i_++)                                    \
            put(sp, v_ + i_ * (tsz), vals_[i_ < sizeof vals_ / 8 ? i_ : 0], tsz);              \
        k++;                                                                                   \
    } while (0)
        put(sp, b + ifd, 10, cnt);
        ENTRY(256, 4, 4, 1, sp->w);
        ENTRY(257, 4, 4, 1, sp->h);
        ENTRY(258, 3, 2, sp->spp, sp->bits);
        ENTRY(259, 3, 2, 1, sp->compression);
        ENTRY(262, 3, 2, 1, sp->spp >= 3 ? 2 : 1);
        /* strip offsets and byte counts: arrays of LONG (LONG8 in BigTIFF) */
        const uint64_t page0 = d0 + p * page_span(sp);
        /* one LONG (BigTIFF: LONG8) per strip, VALUE an expression of the strip s */
#define STRIP_ENTRY(tag, VALUE)                                                                \
    do {                                                                                       \
        put(sp, e + esz * k, tag, 2);                                                          \
        put(sp, e + esz * k + 2, sp->big ? 16 : 4, 2);                                         \
        put(sp, e + esz * k + 4, strips, sp->big ? 8 : 4);                                     \
        uint8_t *v_ = e + esz * k + (sp->big ? 12 : 8);                                        \
        if ((uint64_t)strips * osz > (uint64_t)field) {                                        \
            put(sp, v_, extra, field);                                                         \
            v_ = b + extra;                                                                    \
            extra += (uint64_t)strips * osz;                                                   \
        }                                                                                      \
        for (uint32_t s = 0; s < strips; s++) put(sp, v_ + (uint64_t)s * osz, (VALUE), osz);   \
        k++;                                                                                   \
    } while (0)
        STRIP_ENTRY(273, page0 + s * (sp->rps * row_bytes(sp) + sp->gap));
        ENTRY(277, 3, 2, 1, sp->spp);
        ENTRY(278, 4, 4, 1, sp->rps);
        STRIP_ENTRY(279, (s + 1 < strips ? sp->rps : sp->h - s * sp->rps) * row_bytes(sp));
#undef STRIP_ENTRY
        ENTRY(339, 3, 2, sp->spp, sp->format);
#undef ENTRY
        put(sp, b + ifd + cnt + 10 * esz, p + 1 < sp->pages ? ifd + blk : 0, field);
    }
    return b;
}

/* Writes the file: directories, then each page's strips (pixels: pages x h
 * rows, top first, x w x spp samples in host order). pixels NULL: the data
 * is left as a hole (a sparse file). */
static int write_tiff(const char *path, const tiff_spec *sp, const void *pixels)
{
    uint8_t *dirs = directories(sp);
    if (!dirs) return -1;
    int fd = open(path, O_CREAT | O_TRUNC | O_WRONLY, 0644);
    int ok = fd >= 0 && pwrite(fd, dirs, data_start(sp), 0) == (ssize_t)data_start(sp);
    free(dirs);
    const uint64_t row = row_bytes(sp), es = sp->bits / 8, total = data_start(sp) + sp->pages * page_span(sp);
    ok = ok && ftruncate(fd, (off_t)total) == 0;
    uint8_t *buf = malloc(row);
    ok = ok && buf;
    for (uint32_t p = 0; ok && pixels && p < sp->pages; p++)
        for (uint32_t y = 0; ok && y < sp->h; y++) {
            memcpy(buf, (const uint8_t *)pixels + ((uint64_t)p * sp->h + y) * row, row);
            if (sp->be) /* host little-endian: swap each sample */
                for (uint64_t i = 0; i < row; i += es)
                    for (uint64_t a = 0; a < es / 2; a++) {
                        uint8_t t = buf[i + a];
                        buf[i + a] = buf[i + es - 1 - a];
                        buf[i + es - 1 - a] = t;
                    }
            const uint32_t s = y / sp->rps;
            const uint64_t at = data_start(sp) + p * page_span(sp) + (uint64_t)s * sp->gap + y * row;
            ok = pwrite(fd, buf, row, (off_t)at) == (ssize_t)row;
        }
    free(buf);
    if (fd >= 0 && close(fd) != 0) ok = 0;
    return ok ? 0 : -1;
}

/* Deterministic pixels of the type (floats: far outside [0, 1], with NaN and +-Inf). */
static void *make_pixels(uint32_t bits, uint32_t format, size_t n)
{
    uint8_t *raw = malloc(n * (bits / 8));
    if (!raw) return NULL;
    uint32_t s = 777;
    for (size_t i = 0; i < n; i++) {
        s = s * 1664525u + 1013904223u;
        const double f = sin(i * 0.013) * 1.5 + (s >> 24) / 256.0; /* about -1.5 .. 2.5 */
        if (format == 3 && bits == 32) ((float *)raw)[i] = i % 89 == 3 ? NAN : i % 97 == 5 ? -INFINITY : (float)(f * 500);
        else if (format == 3) ((double *)raw)[i] = i % 83 == 1 ? INFINITY : f * 1e5;
        else if (bits == 8 && format == 1) raw[i] = (uint8_t)(f * 60 + 100);
        else if (bits == 8) ((int8_t *)raw)[i] = (int8_t)(f * 40);
        else if (bits == 16 && format == 1) ((uint16_t *)raw)[i] = (uint16_t)(f * 9000 + 20000);
        else if (bits == 16) ((int16_t *)raw)[i] = (int16_t)(f * 9000);
        else if (format == 1) ((uint32_t *)raw)[i] = (uint32_t)(f * 1e6 + 2e6);
        else ((int32_t *)raw)[i] = (int32_t)(f * 1e6);
    }
    return raw;
}

/* ---------------------------------------------------------------- checks */

static vxl_load_options options(uint32_t streaming, uint64_t budget)
{
    vxl_load_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.streaming = streaming;
    o.memory_budget_bytes = budget;
    o.voxel_size[0] = 0.5;
    o.voxel_size[1] = 0.25;
    o.voxel_size[2] = 2.0;
    return o;
}

static int load(const char *path, uint32_t streaming, uint64_t budget, vxl_volume **v)
{
    vxl_load_options o = options(streaming, budget);
    *v = NULL;
    return vxl_volume_load(path, &o, v);
}


static const struct {
    int be, big;
    uint32_t bits, format, rps;
    const char *name;
} k_cases[] = {
    {0, 0, 8, 1, 3, "classic LE u8"},    {1, 0, 16, 1, 2, "classic BE u16"}, {0, 1, 16, 2, 5, "BigTIFF LE i16"},
    {1, 1, 32, 3, 4, "BigTIFF BE f32"},  {0, 0, 8, 2, 7, "classic LE i8"},   {1, 0, 32, 1, 23, "classic BE u32"},
    {0, 1, 32, 2, 1, "BigTIFF LE i32"},  {1, 0, 64, 3, 6, "classic BE f64"},
};

TEST(streamed_tiff_equals_the_whole_read)
{
    char p[512];
    for (size_t c = 0; c < sizeof k_cases / sizeof k_cases[0]; c++) {
        const tiff_spec sp = {k_cases[c].be, k_cases[c].big, 37, 23, 6, 1, k_cases[c].bits, k_cases[c].format,
                              k_cases[c].rps, 1, 0};
        const size_t n = (size_t)sp.w * sp.h * sp.pages;
        void *px = make_pixels(sp.bits, sp.format, n);
        REQUIRE(px);
        REQUIRE(write_tiff(tmp(p, sizeof p, c % 2 ? "case.tiff" : "case.tif"), &sp, px) == 0);
        vxl_volume *w = NULL, *s = NULL;
        /* every other case reads each coarse level by averaging level-0 reads (the large-file path) */
        if (c % 2) vxl_os_set_env("VOXLIGHT_SOURCE_KEEP_BYTES", "0");
        CHECKF(load(p, VXL_STREAMING_OFF, 0, &w) == VXL_OK, "%s: %s", k_cases[c].name, vxl_last_error());
        CHECKF(load(p, VXL_STREAMING_ON, 0, &s) == VXL_OK, "%s: %s", k_cases[c].name, vxl_last_error());
        if (w && s) {
            CHECK(s->texels == NULL && s->source != NULL && w->source == NULL);
            same_volume(T_, w, s, k_cases[c].name);
            CHECK(s->source->n_levels >= 2); /* the coarse levels of the pass */
        }
        /* the flip, against the written pixels: voxel (i, j, k) is pixel (i, h-1-j) of page k */
        if (s && sp.bits == 8 && sp.format == 1) {
            uint8_t *t = malloc(n);
            const uint32_t zero[3] = {0, 0, 0};
            REQUIRE(t);
            CHECK(vxl_volume_read_level(s, 0, zero, s->dims, t) == VXL_OK);
            int same = 1;
            for (uint32_t k = 0; k < sp.pages; k++)
                for (uint32_t j = 0; j < sp.h; j++)
                    for (uint32_t i = 0; i < sp.w; i++)
                        same &= t[((size_t)k * sp.h + j) * sp.w + i] ==
                                ((const uint8_t *)px)[((size_t)k * sp.h + (sp.h - 1 - j)) * sp.w + i];
            CHECKF(same, "voxel (i, j, k) is not pixel (i, h-1-j) of page k");
            free(t);
        }
        vxl_volume_destroy(w);
        vxl_volume_destroy(s);
        vxl_os_set_env("VOXLIGHT_SOURCE_KEEP_BYTES", NULL);
        free(px);
    }
}

TEST(auto_streams_a_tiff_only_over_half_the_budget)
{
    char p[512];
    const tiff_spec sp = {0, 0, 40, 30, 20, 1, 16, 1, 4, 1, 0};
    void *px = make_pixels(16, 1, (size_t)40 * 30 * 20);
    REQUIRE(px && write_tiff(tmp(p, sizeof p, "auto.tif"), &sp, px) == 0);
    free(px);
    const uint64_t bytes = 40 * 30 * 20 * 2;
    vxl_volume *v = NULL;
    CHECKF(load(p, VXL_STREAMING_AUTO, bytes * 4, &v) == VXL_OK && v->texels && !v->source, "%s", vxl_last_error());
    vxl_volume_destroy(v);
    CHECKF(load(p, VXL_STREAMING_AUTO, bytes + bytes / 2, &v) == VXL_OK && !v->texels && v->source, "%s",
           vxl_last_error());
    vxl_volume_destroy(v);
    /* OFF over the budget: the whole read's limit, as before */
    CHECK(load(p, VXL_STREAMING_OFF, bytes / 2, &v) == VXL_ERR_LIMIT && !v);
}

TEST(tiffs_that_cannot_stream_are_read_whole_and_say_why)
{
    char p[512];
    static const struct {
        tiff_spec sp;
        const char *why;
        int readable; /* the whole read takes it (a compressed page of raw bytes does not) */
    } cases[] = {
        {{0, 0, 16, 12, 3, 1, 8, 1, 4, 1, 8}, "strips are not contiguous", 1},
        {{1, 1, 16, 12, 3, 3, 8, 1, 4, 1, 0}, "colour TIFF", 1},
        {{0, 0, 16, 12, 3, 1, 16, 3, 12, 1, 0}, "half-float TIFF", 1},
        {{0, 0, 16, 12, 3, 1, 8, 1, 12, 5, 0}, "compressed TIFF", 0},
        {{0, 0, 16, 12, 1, 1, 8, 1, 12, 1, 0}, "single-page TIFF", 1},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const tiff_spec *sp = &cases[c].sp;
        const size_t n = (size_t)sp->w * sp->h * sp->pages * sp->spp;
        void *px = make_pixels(sp->bits, sp->bits == 16 ? 1 : sp->format, n); /* half: any 16-bit pattern */
        REQUIRE(px && write_tiff(tmp(p, sizeof p, "whole.tif"), sp, px) == 0);
        free(px);
        vxl_volume *v = NULL;
        if (cases[c].readable) { /* streaming asked for, and it fits: read whole */
            CHECKF(load(p, VXL_STREAMING_ON, 1 << 20, &v) == VXL_OK && v->texels && !v->source, "%s: %s",
                   cases[c].why, vxl_last_error());
            vxl_volume_destroy(v);
            v = NULL;
        }
        /* over the budget: the whole read's limit, saying why it could not stream */
        CHECK(load(p, VXL_STREAMING_ON, 64, &v) == VXL_ERR_LIMIT && !v);
        CHECKF(strstr(vxl_last_error(), "streaming is not available for") && strstr(vxl_last_error(), cases[c].why),
               "%s", vxl_last_error());
        CHECK(load(p, VXL_STREAMING_AUTO, 64, &v) == VXL_ERR_LIMIT && strstr(vxl_last_error(), cases[c].why));
        /* OFF: the whole read's limit; a colour TIFF is a colour volume, which
         * is read whole whatever the option, and its limit says so */
        CHECKF(load(p, VXL_STREAMING_OFF, 64, &v) == VXL_ERR_LIMIT &&
                   (sp->spp == 3 ? strstr(vxl_last_error(), "colour volumes are read whole") != NULL
                                 : !strstr(vxl_last_error(), "streaming")),
               "%s: %s", cases[c].why, vxl_last_error());
    }
    /* the contiguous twin of the first case streams */
    const tiff_spec ok = {0, 0, 16, 12, 3, 1, 8, 1, 4, 1, 0};
    void *px = make_pixels(8, 1, 16 * 12 * 3);
    REQUIRE(px && write_tiff(tmp(p, sizeof p, "whole.tif"), &ok, px) == 0);
    free(px);
    vxl_volume *v = NULL;
    CHECKF(load(p, VXL_STREAMING_ON, 1 << 20, &v) == VXL_OK && v->source, "%s", vxl_last_error());
    vxl_volume_destroy(v);
}

TEST(a_truncated_tiff_is_an_error_naming_it)
{
    char p[512];
    const tiff_spec sp = {1, 1, 20, 10, 4, 1, 16, 2, 3, 1, 0};
    void *px = make_pixels(16, 2, 20 * 10 * 4);
    REQUIRE(px && write_tiff(tmp(p, sizeof p, "short.tif"), &sp, px) == 0);
    free(px);
    struct stat st;
    REQUIRE(stat(p, &st) == 0 && truncate(p, st.st_size - 7) == 0); /* cuts the last page's last strip */
    vxl_volume *v = NULL;
    CHECK(load(p, VXL_STREAMING_ON, 0, &v) == VXL_ERR_FORMAT && !v);
    CHECKF(strstr(vxl_last_error(), p) && strstr(vxl_last_error(), "truncated"), "%s", vxl_last_error());
    /* the pages' directories cut off */
    REQUIRE(truncate(p, 200) == 0);
    CHECK(load(p, VXL_STREAMING_ON, 0, &v) == VXL_ERR_FORMAT && !v);
    CHECKF(strstr(vxl_last_error(), p) && strstr(vxl_last_error(), "truncated"), "%s", vxl_last_error());
}

TEST(a_sparse_bigtiff_larger_than_the_budget_streams_with_bounded_memory)
{
    char p[512];
    const tiff_spec sp = {0, 1, 2048, 2048, 1200, 1, 8, 1, 2048, 1, 0}; /* 5 GB of uint8, one strip a page */
    REQUIRE(write_tiff(tmp(p, sizeof p, "huge.tif"), &sp, NULL) == 0);
    /* a ball of 200 around (500, 1500, 600) in voxels: stored rows top first */
    const int c[3] = {500, 1500, 600}, r = 10;
    int fd = open(p, O_WRONLY);
    REQUIRE(fd >= 0);
    uint8_t row[2 * 10 + 1];
    memset(row, 200, sizeof row);
    int ok = 1;
    for (int z = -r; z <= r && ok; z++)
        for (int y = -r; y <= r && ok; y++) {
            const int half = (int)floor(sqrt((double)(r * r - y * y - z * z > 0 ? r * r - y * y - z * z : 0)));
            if (y * y + z * z > r * r) continue;
            const uint64_t at = data_start(&sp) + (uint64_t)(c[2] + z) * page_span(&sp) +
                                (uint64_t)(sp.h - 1 - (c[1] + y)) * sp.w + (c[0] - half);
            ok = pwrite(fd, row, (size_t)(2 * half + 1), (off_t)at) == 2 * half + 1;
        }
    struct stat st;
    ok = ok && fstat(fd, &st) == 0;
    close(fd);
    REQUIRE(ok);
    CHECKF((uint64_t)st.st_blocks * 512 < (uint64_t)st.st_size / 8, "the file is not sparse here");
    const long before = peak_rss_kb(1);
    vxl_volume *v = NULL;
    int rc = load(p, VXL_STREAMING_AUTO, 512ull << 20, &v);
    const long after = peak_rss_kb(0);
    CHECKF(rc == VXL_OK, "%s", vxl_last_error());
    if (rc == VXL_OK) {
        vxl_volume_info i;
        info_of(v, &i);
        fprintf(stderr, "  opened %.1f GB: peak RSS +%ld MB, source holds %llu MB, read %llu kB\n",
                (double)st.st_size / 1e9, (after - before) / 1024, (unsigned long long)(i.resident_bytes >> 20),
                (unsigned long long)(i.bytes_read >> 10));
        CHECK(i.streamed == 1 && i.dims[0] == 2048 && i.dims[2] == 1200);
        CHECKF(after - before < 256 * 1024, "opening raised the peak RSS by %ld MB", (after - before) / 1024);
        CHECKF(i.bytes_read <= (uint64_t)st.st_blocks * 512, "read %llu bytes of %llu allocated",
               (unsigned long long)i.bytes_read, (unsigned long long)st.st_blocks * 512);
        CHECK(i.value_min == 0 && i.value_max == 200);
        const uint32_t one[3] = {1, 1, 1}, at[3] = {(uint32_t)c[0], (uint32_t)c[1], (uint32_t)c[2]};
        const uint32_t mirror[3] = {(uint32_t)c[0], (uint32_t)(sp.h - 1 - c[1]), (uint32_t)c[2]};
        uint8_t t = 0;
        CHECK(vxl_volume_read_level(v, 0, at, one, &t) == VXL_OK && t == 200);
        CHECK(vxl_volume_read_level(v, 0, mirror, one, &t) == VXL_OK && t == 0);
    }
    vxl_volume_destroy(v);
    unlink(p);
}

/* Small TIFFs for the fuzz target's seeds (tests/fuzz/run.sh). */
static int write_seeds(const char *dir)
{
    static const tiff_spec seeds[] = {
        {0, 0, 5, 4, 3, 1, 8, 1, 2, 1, 0},  {1, 0, 4, 3, 2, 1, 16, 2, 1, 1, 0}, {0, 1, 3, 5, 2, 1, 32, 3, 2, 1, 0},
        {1, 1, 4, 4, 2, 1, 64, 3, 4, 1, 0}, {0, 0, 4, 6, 2, 1, 8, 1, 2, 1, 3},  {0, 0, 4, 3, 2, 3, 8, 1, 3, 1, 0},
        {0, 0, 4, 3, 2, 1, 8, 1, 3, 5, 0},
    };
    mkdir(dir, 0755);
    for (size_t k = 0; k < sizeof seeds / sizeof seeds[0]; k++) {
        const tiff_spec *sp = &seeds[k];
        void *px = make_pixels(sp->bits, sp->format, (size_t)sp->w * sp->h * sp->pages * sp->spp);
        char p[1024];
        snprintf(p, sizeof p, "%s/seed_%zu.tif", dir, k);
        const int rc = px ? write_tiff(p, sp, px) : -1;
        free(px);
        if (rc) return 1;
    }
    return 0;
}

#define RUN_IF(name)                                 \
    do {                                             \
        if (!only || strstr(#name, only)) RUN(name); \
    } while (0)

int main(int argc, char **argv)
{
    if (argc > 2 && !strcmp(argv[1], "--write-seeds")) return write_seeds(argv[2]);
    const char *only = argc > 1 ? argv[1] : NULL;
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_tiff_stream_XXXXXX");
    if (!mkdtemp(g_dir)) return 1;
    /* first, so the peak it measures is not an earlier test's */
    RUN_IF(a_sparse_bigtiff_larger_than_the_budget_streams_with_bounded_memory);
    RUN_IF(streamed_tiff_equals_the_whole_read);
    RUN_IF(auto_streams_a_tiff_only_over_half_the_budget);
    RUN_IF(tiffs_that_cannot_stream_are_read_whole_and_say_why);
    RUN_IF(a_truncated_tiff_is_an_error_naming_it);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
