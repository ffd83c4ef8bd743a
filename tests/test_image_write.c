/* test_image_write.c - vxl_write_image, read back by decoders written here
 * from the format specifications (not from the writer): a PNG reader that
 * checks every chunk CRC, inflates with zlib and undoes all five filters,
 * and an OpenEXR reader that checks the header attributes and the line
 * offset table and undoes ZIP compression. Pixels are compared with what the
 * public contract promises: bottom row first in memory, top row first in the
 * file; PNG straight alpha in 8 bits; EXR premultiplied halves (correctly
 * rounded, checked against neighbouring halves) plus a float Z. */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "harness.h"
#include "loader_test_util.h"
#include "voxlight.h"

static char g_dir[64];

static const char *tmp(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
    return buf;
}

static int file_exists(const char *path)
{
    struct stat st;
    return lstat(path, &st) == 0;
}

static uint32_t be32(const uint8_t *p) { return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]; }
static uint32_t le32(const uint8_t *p) { return (uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0]; }
static uint64_t le64(const uint8_t *p) { return (uint64_t)le32(p + 4) << 32 | le32(p); }

static float bits_float(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* A small deterministic generator (values in [lo, hi)). */
static float rnd(uint32_t *s, float lo, float hi)
{
    *s = *s * 1664525u + 1013904223u;
    return lo + (hi - lo) * (float)(*s >> 8) / 16777216.0f;
}

/* ------------------------------------------------------------------ PNG reader */

typedef struct png_image {
    uint32_t w, h;
    int idat_chunks;
    unsigned filters; /* bit t set when some row uses filter type t */
    uint8_t *px; /* RGBA, top row first */
} png_image;

static int paeth(int a, int b, int c)
{
    int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    if (pa <= pb && pa <= pc) return a;
    return pb <= pc ? b : c;
}

/* Returns 0 and fills *img, or -1 after failing a check. */
static int png_read(vxl_test_ctx *T_, const char *path, png_image *img)
{
    memset(img, 0, sizeof *img);
    size_t len;
    uint8_t *b = read_all(path, &len);
    CHECK(b != NULL);
    if (!b) return -1;
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    int ok = len >= 8 && memcmp(b, sig, 8) == 0;
    CHECK(ok);
    uint8_t *idat = NULL;
    size_t idat_len = 0, pos = 8;
    int nchunk = 0, seen_iend = 0, idat_done = 0;
    while (ok && pos < len) {
        if (len - pos < 12) { CHECK(!"truncated chunk"); ok = 0; break; }
        uint32_t n = be32(b + pos);
        if (n > len - pos - 12) { CHECK(!"chunk past the end"); ok = 0; break; }
        const uint8_t *type = b + pos + 4, *data = b + pos + 8;
        uint32_t crc = (uint32_t)crc32(crc32(0L, Z_NULL, 0), type, n + 4);
        CHECKF(crc == be32(data + n), "chunk %.4s: crc %08x, stored %08x", (const char *)type, crc, be32(data + n));
        if (nchunk == 0) {
            CHECK(memcmp(type, "IHDR", 4) == 0 && n == 13);
            if (memcmp(type, "IHDR", 4) != 0 || n != 13) { ok = 0; break; }
            img->w = be32(data);
            img->h = be32(data + 4);
            CHECK(data[8] == 8);  /* 8 bits per sample */
            CHECK(data[9] == 6);  /* RGBA */
            CHECK(data[10] == 0 && data[11] == 0 && data[12] == 0);
        } else if (memcmp(type, "IDAT", 4) == 0) {
            CHECK(!idat_done); /* IDAT chunks must be consecutive */
            uint8_t *grown = realloc(idat, idat_len + n + 1);
            CHECK(grown != NULL);
            if (!grown) { ok = 0; break; }
            idat = grown;
            memcpy(idat + idat_len, data, n);
            idat_len += n;
            img->idat_chunks++;
        } else if (memcmp(type, "IEND", 4) == 0) {
            CHECK(n == 0);
            seen_iend = 1;
        } else {
            CHECKF((type[0] & 0x20) != 0, "unknown critical chunk %.4s", (const char *)type);
        }
        if (img->idat_chunks && memcmp(type, "IDAT", 4) != 0) idat_done = 1;
        nchunk++;
        pos += 12 + (size_t)n;
        if (seen_iend) break;
    }
    CHECK(seen_iend && pos == len);
    ok = ok && seen_iend && img->idat_chunks > 0 && img->w > 0 && img->h > 0;
    size_t stride = (size_t)img->w * 4, raw_len = (stride + 1) * img->h;
    uint8_t *raw = ok ? malloc(raw_len + 1) : NULL;
    if (ok) {
        uLongf got = (uLongf)raw_len + 1; /* one spare byte catches trailing data */
        int zrc = uncompress(raw, &got, idat, (uLong)idat_len);
        CHECKF(zrc == Z_OK && got == raw_len, "inflate rc %d, %lu of %zu bytes", zrc, (unsigned long)got, raw_len);
        ok = zrc == Z_OK && got == raw_len;
    }
    if (ok) {
        img->px = malloc(stride * img->h);
        for (uint32_t y = 0; y < img->h && ok; y++) {
            const uint8_t *in = raw + y * (stride + 1) + 1;
            uint8_t *cur = img->px + y * stride;
            const uint8_t *prev = y ? cur - stride : NULL;
            int f = raw[y * (stride + 1)];
            CHECKF(f <= 4, "row %u: filter %d", y, f);
            if (f > 4) ok = 0;
            else img->filters |= 1u << f;
            for (size_t i = 0; i < stride && ok; i++) {
                int a = i >= 4 ? cur[i - 4] : 0, up = prev ? prev[i] : 0, c = prev && i >= 4 ? prev[i - 4] : 0;
                int p = f == 1 ? a : f == 2 ? up : f == 3 ? (a + up) / 2 : f == 4 ? paeth(a, up, c) : 0;
                cur[i] = (uint8_t)(in[i] + p);
            }
        }
        if (!ok) {
            free(img->px);
            img->px = NULL;
        }
    }
    free(raw);
    free(idat);
    free(b);
    return ok ? 0 : -1;
}

/* What the contract promises for one premultiplied pixel channel k: non-finite
 * to 0, colour divided by alpha (at most 1) where alpha > 0, then 8 bits as
 * OpenImageIO rounds: clamp(v * 255 + 0.5) truncated, in float. */
static uint8_t png_expected(const float *px, int k)
{
    float v = isfinite(px[k]) ? px[k] : 0.0f;
    if (k < 3 && px[3] > 0) v = fminf(1.0f, v / px[3]);
    float s = v * 255.0f + 0.5f;
    return s <= 0.0f ? 0 : s >= 255.0f ? 255 : (uint8_t)s;
}

/* Checks every pixel of a w x h file against the bottom-first buffer. */
static void png_compare(vxl_test_ctx *T_, const png_image *img, const float *rgba, uint32_t w, uint32_t h)
{
    CHECK(img->w == w && img->h == h);
    if (img->w != w || img->h != h || !img->px) return;
    int bad = 0;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++)
            for (int k = 0; k < 4; k++) {
                const float *s = rgba + ((size_t)(h - 1 - y) * w + x) * 4;
                uint8_t got = img->px[((size_t)y * w + x) * 4 + k], want = png_expected(s, k);
                if (got != want && bad++ < 5)
                    CHECKF(got == want, "file row %u x %u channel %d: %u, want %u (input %g alpha %g)", y, x, k,
                           got, want, (double)s[k], (double)s[3]);
            }
    CHECKF(bad == 0, "%d samples differ", bad);
}

/* ------------------------------------------------------------------ EXR reader */

typedef struct exr_image {
    uint32_t w, h;
    int nch;
    char names[5];
    int types[5];
    int compression;
    uint16_t *half[4]; /* A, B, G, R as stored, top row first */
    float *z;          /* NULL without a Z channel */
} exr_image;

static void exr_free(exr_image *e)
{
    for (int c = 0; c < 4; c++) free(e->half[c]);
    free(e->z);
}

/* The attribute named name, or NULL; *size gets its size. */
static const uint8_t *exr_find_attr(const uint8_t *b, size_t hend, const char *name, const char *type,
                                    uint32_t *size)
{
    size_t pos = 8;
    while (pos < hend && b[pos]) {
        const char *an = (const char *)b + pos;
        const char *at = an + strlen(an) + 1;
        const uint8_t *sz = (const uint8_t *)at + strlen(at) + 1;
        uint32_t n = le32(sz);
        if (strcmp(an, name) == 0 && strcmp(at, type) == 0) {
            *size = n;
            return sz + 4;
        }
        pos = (size_t)(sz + 4 + n - b);
    }
    return NULL;
}

static float half_to_float(uint16_t h)
{
    int e = (h >> 10) & 31, m = h & 1023;
    float v = e == 0 ? ldexpf((float)m, -24) : e == 31 ? (m ? NAN : INFINITY) : ldexpf((float)(m + 1024), e - 25);
    return (h & 0x8000) ? -v : v;
}

/* Undoes EXR's ZIP pre-pass: predictor, then the even/odd byte split. */
static void exr_unpredict(uint8_t *t, size_t n, uint8_t *out)
{
    for (size_t i = 1; i < n; i++) t[i] = (uint8_t)(t[i - 1] + t[i] - 128);
    size_t half = (n + 1) / 2;
    for (size_t i = 0; i < n; i++) out[i] = (i & 1) ? t[half + i / 2] : t[i / 2];
}

static int exr_read(vxl_test_ctx *T_, const char *path, exr_image *img)
{
    memset(img, 0, sizeof *img);
    size_t len;
    uint8_t *b = read_all(path, &len);
    CHECK(b != NULL);
    if (!b) return -1;
    int ok = len > 8 && le32(b) == 20000630u && le32(b + 4) == 2; /* magic; version 2, no flags */
    CHECK(ok);
    /* Walk the attributes to the terminating 0, checking each is in bounds
     * and that names come in ascending order (as OpenEXR writes them). */
    size_t pos = 8;
    char last[64] = "";
    while (ok) {
        if (pos >= len) { ok = 0; break; }
        if (b[pos] == 0) break;
        const uint8_t *nul1 = memchr(b + pos, 0, len - pos);
        const uint8_t *nul2 = nul1 ? memchr(nul1 + 1, 0, len - (size_t)(nul1 + 1 - b)) : NULL;
        if (!nul2 || (size_t)(nul2 - b) + 5 > len) { ok = 0; break; }
        uint32_t n = le32(nul2 + 1);
        if (n > len - (size_t)(nul2 + 5 - b)) { ok = 0; break; }
        CHECKF(strcmp((const char *)b + pos, last) > 0, "attribute %s after %s", (const char *)b + pos, last);
        snprintf(last, sizeof last, "%s", (const char *)b + pos);
        pos = (size_t)(nul2 + 5 - b) + n;
    }
    CHECK(ok);
    size_t hend = pos;
    uint32_t n;
    const uint8_t *v;
    if (ok) {
        /* channels: name, pixel type, pLinear, 3 reserved, x and y sampling; sorted by name */
        v = exr_find_attr(b, hend, "channels", "chlist", &n);
        CHECK(v != NULL);
        size_t p = 0;
        while (v && p < n && v[p] && img->nch < 5) {
            CHECK(v[p + 1] == 0); /* one-letter names */
            img->names[img->nch] = (char)v[p];
            img->types[img->nch] = (int)le32(v + p + 2);
            CHECK(le32(v + p + 10) == 1 && le32(v + p + 14) == 1);
            img->nch++;
            p += 18;
        }
        CHECK(v && p + 1 == n && v[p] == 0);
        v = exr_find_attr(b, hend, "compression", "compression", &n);
        CHECK(v && n == 1);
        img->compression = v ? v[0] : -1;
        CHECKF(img->compression == 0 || img->compression == 3, "compression %d", img->compression);
        v = exr_find_attr(b, hend, "dataWindow", "box2i", &n);
        CHECK(v && n == 16 && le32(v) == 0 && le32(v + 4) == 0);
        if (v) img->w = le32(v + 8) + 1, img->h = le32(v + 12) + 1;
        const uint8_t *d = exr_find_attr(b, hend, "displayWindow", "box2i", &n);
        CHECK(d && v && memcmp(d, v, 16) == 0);
        v = exr_find_attr(b, hend, "lineOrder", "lineOrder", &n);
        CHECK(v && n == 1 && v[0] == 0); /* increasing y */
        v = exr_find_attr(b, hend, "pixelAspectRatio", "float", &n);
        CHECK(v && bits_float(le32(v)) == 1.0f);
        v = exr_find_attr(b, hend, "screenWindowCenter", "v2f", &n);
        CHECK(v && bits_float(le32(v)) == 0.0f && bits_float(le32(v + 4)) == 0.0f);
        v = exr_find_attr(b, hend, "screenWindowWidth", "float", &n);
        CHECK(v && bits_float(le32(v)) == 1.0f);
        ok = img->w && img->h && img->w <= 65536 && img->h <= 65536 && (img->nch == 4 || img->nch == 5) &&
             (img->compression == 0 || img->compression == 3);
        CHECK(ok);
    }
    if (ok) {
        static const char want[] = "ABGRZ";
        for (int c = 0; c < img->nch; c++) {
            CHECKF(img->names[c] == want[c], "channel %d is %c", c, img->names[c]);
            CHECKF(img->types[c] == (c < 4 ? 1 : 2), "channel %c type %d", img->names[c], img->types[c]);
            if (img->names[c] != want[c] || img->types[c] != (c < 4 ? 1 : 2)) ok = 0;
        }
    }
    uint32_t lines = img->compression == 3 ? 16 : 1;
    size_t line_bytes = (size_t)img->w * (img->nch == 5 ? 12 : 8), npx = (size_t)img->w * img->h;
    uint8_t *raw = NULL, *tmpb = NULL;
    if (ok) {
        for (int c = 0; c < 4; c++) img->half[c] = malloc(npx * 2);
        if (img->nch == 5) img->z = malloc(npx * 4);
        raw = malloc(line_bytes * lines);
        tmpb = malloc(line_bytes * lines);
    }
    uint32_t nblocks = (img->h + lines - 1) / lines;
    size_t table = hend + 1;
    if (ok && table + (size_t)nblocks * 8 > len) {
        CHECK(!"offset table past the end");
        ok = 0;
    }
    size_t expect_off = table + (size_t)nblocks * 8; /* chunks follow the table in order */
    for (uint32_t k = 0; ok && k < nblocks; k++) {
        uint64_t off = le64(b + table + (size_t)k * 8);
        CHECKF(off == expect_off, "chunk %u at %llu, want %zu", k, (unsigned long long)off, expect_off);
        if (off + 8 > len) { ok = 0; break; }
        uint32_t y = le32(b + off), size = le32(b + off + 4);
        uint32_t nl = img->h - k * lines < lines ? img->h - k * lines : lines;
        size_t want = nl * line_bytes;
        CHECKF(y == k * lines, "chunk %u: y %u", k, y);
        if (off + 8 + size > len || size > want) { CHECK(!"chunk size"); ok = 0; break; }
        const uint8_t *data = b + off + 8;
        if (size < want) { /* compressed; a chunk as big as the raw data is stored raw */
            uLongf got = (uLongf)want;
            int zrc = uncompress(tmpb, &got, data, size);
            CHECKF(zrc == Z_OK && got == want, "chunk %u: inflate rc %d", k, zrc);
            if (zrc != Z_OK || got != want) { ok = 0; break; }
            exr_unpredict(tmpb, want, raw);
            data = raw;
        }
        for (uint32_t l = 0; l < nl; l++) {
            const uint8_t *p = data + l * line_bytes;
            size_t row = (size_t)(y + l) * img->w;
            for (int c = 0; c < 4; c++)
                for (uint32_t x = 0; x < img->w; x++, p += 2) img->half[c][row + x] = (uint16_t)(p[0] | p[1] << 8);
            if (img->z)
                for (uint32_t x = 0; x < img->w; x++, p += 4) img->z[row + x] = bits_float(le32(p));
        }
        expect_off = off + 8 + size;
    }
    if (ok) CHECKF(expect_off == len, "%zu bytes after the last chunk", len - expect_off);
    free(raw);
    free(tmpb);
    free(b);
    if (!ok) exr_free(img);
    return ok ? 0 : -1;
}

/* Whether h is v correctly rounded to half: no other half is nearer, and on a
 * tie the one with an even significand wins. v is finite. */
static int is_rounded_half(float v, uint16_t h)
{
    double d = fabs((double)half_to_float(h) - v);
    if (isinf(half_to_float(h))) return fabs(v) >= 65520.0 && (v > 0) == !(h & 0x8000);
    if (fabs(v) >= 65520.0) return 0; /* should have overflowed */
    if ((h & 0x8000) && v > 0) return 0;
    if (!(h & 0x8000) && v < 0) return 0;
    for (int step = -1; step <= 1; step += 2) {
        int mag = (h & 0x7fff) + step;
        if (mag < 0 || mag > 0x7bff) continue;
        double dn = fabs((double)half_to_float((uint16_t)((h & 0x8000) | mag)) - v);
        if (dn < d || (dn == d && (h & 1))) return 0;
    }
    return 1;
}

static void exr_compare(vxl_test_ctx *T_, const exr_image *img, const float *rgba, const float *depth, uint32_t w,
                        uint32_t h)
{
    CHECK(img->w == w && img->h == h && (img->z != NULL) == (depth != NULL));
    if (img->w != w || img->h != h || !img->half[0]) return;
    static const int src[4] = {3, 2, 1, 0}; /* A B G R */
    int bad = 0;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++) {
            size_t in = (size_t)(h - 1 - y) * w + x, out = (size_t)y * w + x;
            for (int c = 0; c < 4; c++) {
                float v = rgba[in * 4 + (size_t)src[c]];
                if (!isfinite(v)) v = 0;
                uint16_t got = img->half[c][out];
                if (!is_rounded_half(v, got) && bad++ < 5)
                    CHECKF(0, "file row %u x %u channel %c: half %04x for %.9g", y, x, img->names[c], got,
                           (double)v);
            }
            if (depth && img->z && memcmp(&img->z[out], &depth[in], 4) != 0 && bad++ < 5)
                CHECKF(0, "file row %u x %u: Z %.9g, want %.9g", y, x, (double)img->z[out], (double)depth[in]);
        }
    CHECKF(bad == 0, "%d samples differ", bad);
}

/* ------------------------------------------------------------------ tests */

/* A few premultiplied pixels with known answers, then the rest noise, in a
 * 7x5 image whose rows differ so a missing flip shows. */
static void fill_special(float *p, uint32_t w, uint32_t h)
{
    uint32_t s = 7;
    for (size_t i = 0; i < (size_t)w * h * 4; i++) p[i] = rnd(&s, -0.2f, 1.3f);
    static const float sp[] = {
        0.5f, 0.25f, 0.0f, 0.5f,            /* -> 255 128 0 128 */
        NAN, INFINITY, -INFINITY, 1.0f,     /* -> 0 0 0 255 */
        0.25f, 0.3f, 0.2f, 0.0f,            /* alpha 0 keeps the colour: 64 77 51 0 */
        2.0f, 1.0f, 0.5f, 1.0f,             /* clamped: 255 255 128 255 */
        0.001f, 0.0f, 0.0f, 0.002f,         /* 0.5 -> 128 */
        0.3f, 0.3f, 0.3f, NAN,              /* NaN alpha: colour kept, alpha 0 */
        -0.5f, 0.1f, 0.1f, -1.0f,           /* negative alpha: not divided */
    };
    memcpy(p, sp, sizeof sp);
}

TEST(png_pixels_match)
{
    enum { W = 7, H = 5 };
    float px[W * H * 4];
    fill_special(px, W, H);
    char path[128];
    REQUIRE(vxl_write_image(tmp(path, sizeof path, "a.png"), px, NULL, W, H) == VXL_OK);
    png_image img;
    REQUIRE(png_read(T_, path, &img) == 0);
    png_compare(T_, &img, px, W, H);
    /* The known answers: buffer row 0 is the file's last row. */
    static const uint8_t want[7][4] = {{255, 128, 0, 128}, {0, 0, 0, 255},     {64, 77, 51, 0},  {255, 255, 128, 255},
                                       {128, 0, 0, 1},     {77, 77, 77, 0},    {0, 26, 26, 0}};
    const uint8_t *last = img.px + (size_t)(H - 1) * W * 4;
    for (int i = 0; i < 7; i++)
        CHECKF(memcmp(last + i * 4, want[i], 4) == 0, "pixel %d: %u %u %u %u", i, last[i * 4], last[i * 4 + 1],
               last[i * 4 + 2], last[i * 4 + 3]);
    free(img.px);
}

TEST(png_large_and_smooth)
{
    /* Noise does not compress, so the stream spans several IDAT chunks. */
    enum { W = 300, H = 200 };
    float *px = malloc(sizeof(float) * W * H * 4);
    REQUIRE(px);
    uint32_t s = 99;
    for (size_t i = 0; i < (size_t)W * H * 4; i++) px[i] = rnd(&s, 0.0f, 1.0f);
    char path[128];
    CHECK(vxl_write_image(tmp(path, sizeof path, "noise.png"), px, NULL, W, H) == VXL_OK);
    png_image img;
    if (png_read(T_, path, &img) == 0) {
        CHECKF(img.idat_chunks > 1, "%d IDAT chunks", img.idat_chunks);
        png_compare(T_, &img, px, W, H);
        free(img.px);
    }
    /* A smooth opaque gradient: the row filters make it compress well. */
    for (uint32_t y = 0; y < H; y++)
        for (uint32_t x = 0; x < W; x++) {
            float *p = px + ((size_t)y * W + x) * 4;
            p[0] = (float)x / W, p[1] = (float)y / H, p[2] = (float)(x + y) / (W + H), p[3] = 1.0f;
        }
    CHECK(vxl_write_image(tmp(path, sizeof path, "smooth.png"), px, NULL, W, H) == VXL_OK);
    if (png_read(T_, path, &img) == 0) {
        png_compare(T_, &img, px, W, H);
        free(img.px);
    }
    size_t len;
    uint8_t *b = read_all(path, &len);
    CHECKF(b && len < (size_t)W * H * 4 / 20, "smooth image: %zu bytes", len);
    free(b);
    free(px);
}

TEST(png_every_filter)
{
    /* Rows built (in file order, 8-bit opaque) so that each of the five
     * filters is the clear best for one of them: the round trip then covers
     * every filter the writer can emit. Row 7's second pixel is a Paeth tie
     * between the pixels above and above-left (which the spec settles: above);
     * without the kick every 8 pixels Paeth would just copy the row above. */
    enum { W = 64, H = 8 };
    static uint8_t rows[H][W * 4];
    uint32_t s = 3;
    for (int y = 0; y < H; y++)
        for (int i = 0; i < W * 4; i++) {
            int a = i >= 4 ? rows[y][i - 4] : 0, b = y ? rows[y - 1][i] : 0, c = y && i >= 4 ? rows[y - 1][i - 4] : 0;
            int v;
            switch (y) {
            case 0: v = 200; break;                       /* constant: sub */
            case 1: v = b; break;                         /* a copy: up */
            case 3: v = (i / 4) % 2 ? 254 : 2; break;     /* small signed bytes: none */
            case 5: v = (a + b) / 2; break;               /* average */
            case 6: v = i < 4 ? 100 : i < 8 ? 0 : (int)rnd(&s, 0.0f, 256.0f); break; /* noise, and a tie for row 7 */
            case 7: v = paeth(a, b, c) + (i % 32 < 3 ? 50 : 0); break; /* paeth, kicked so it is not a copy */
            default: v = (int)(rnd(&s, 0.0f, 256.0f)); break; /* noise between them */
            }
            rows[y][i] = (uint8_t)((i % 4 == 3) ? 255 : v);
        }
    float px[W * H * 4];
    for (int y = 0; y < H; y++)
        for (int i = 0; i < W * 4; i++) px[(size_t)(H - 1 - y) * W * 4 + i] = (float)rows[y][i] / 255.0f;
    char path[128];
    REQUIRE(vxl_write_image(tmp(path, sizeof path, "filters.png"), px, NULL, W, H) == VXL_OK);
    png_image img;
    REQUIRE(png_read(T_, path, &img) == 0);
    png_compare(T_, &img, px, W, H);
    CHECK(memcmp(img.px, rows, sizeof rows) == 0);
    CHECKF(img.filters == 0x1f, "filter types used: mask %#x", img.filters);
    free(img.px);
}

TEST(exr_pixels_match)
{
    enum { W = 7, H = 5 };
    float px[W * H * 4];
    fill_special(px, W, H);
    char path[128];
    REQUIRE(vxl_write_image(tmp(path, sizeof path, "a.exr"), px, NULL, W, H) == VXL_OK);
    exr_image img;
    REQUIRE(exr_read(T_, path, &img) == 0);
    CHECK(img.nch == 4 && img.z == NULL);
    exr_compare(T_, &img, px, NULL, W, H);
    /* Premultiplied as given: the first pixel's R G B A are 0.5 0.25 0 0.5. */
    size_t first = (size_t)(H - 1) * W;
    CHECK(img.half[3][first] == 0x3800 && img.half[2][first] == 0x3400 && img.half[1][first] == 0 &&
          img.half[0][first] == 0x3800);
    CHECK(img.half[3][first + 1] == 0 && img.half[2][first + 1] == 0 && img.half[1][first + 1] == 0); /* non-finite */
    exr_free(&img);
}

TEST(exr_depth_and_blocks)
{
    /* 37 rows: two full 16-line ZIP chunks and a partial one. */
    enum { W = 23, H = 37 };
    float *px = malloc(sizeof(float) * W * H * 4), *z = malloc(sizeof(float) * W * H);
    REQUIRE(px && z);
    for (uint32_t y = 0; y < H; y++)
        for (uint32_t x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            float a = (float)(x + 1) / W;
            px[i * 4 + 0] = a * (float)y / H, px[i * 4 + 1] = a * 0.5f, px[i * 4 + 2] = a * (float)x / W;
            px[i * 4 + 3] = a;
            z[i] = x == 3 ? INFINITY : 1.0f + (float)y * 0.125f + (float)x * 1e-3f;
        }
    char path[128];
    REQUIRE(vxl_write_image(tmp(path, sizeof path, "depth.exr"), px, z, W, H) == VXL_OK);
    exr_image img;
    if (exr_read(T_, path, &img) == 0) {
        CHECK(img.nch == 5 && img.compression == 3);
        exr_compare(T_, &img, px, z, W, H);
        exr_free(&img);
    }
    /* Noise: chunks may be stored raw when zlib cannot shrink them. */
    uint32_t s = 5;
    for (size_t i = 0; i < (size_t)W * H * 4; i++) px[i] = rnd(&s, -70000.0f, 70000.0f);
    for (size_t i = 0; i < (size_t)W * H; i++) z[i] = rnd(&s, -1e30f, 1e30f);
    REQUIRE(vxl_write_image(tmp(path, sizeof path, "noise.exr"), px, z, W, H) == VXL_OK);
    if (exr_read(T_, path, &img) == 0) {
        exr_compare(T_, &img, px, z, W, H);
        exr_free(&img);
    }
    free(px);
    free(z);
}

TEST(exr_half_rounding)
{
    /* Rounding to nearest even, overflow and subnormals, with the halves
     * they must give (IEEE 754 binary16). */
    static const struct {
        float v;
        uint16_t h;
    } cases[] = {
        {1.0f, 0x3c00},
        {-2.0f, 0xc000},
        {0.1f, 0x2e66},
        {1.0f + 0x1p-11f, 0x3c00},       /* tie: stays even */
        {1.0f + 3 * 0x1p-11f, 0x3c02},   /* tie: rounds up to even */
        {1.0f + 0x1p-11f + 0x1p-20f, 0x3c01},
        {65504.0f, 0x7bff},
        {65519.0f, 0x7bff},
        {65520.0f, 0x7c00},              /* tie with 65536: overflows to infinity */
        {70000.0f, 0x7c00},
        {-1e10f, 0xfc00},
        {0x1p-14f, 0x0400},              /* smallest normal */
        {0x1p-14f - 0x1p-25f, 0x0400},   /* tie: rounds up to the even normal */
        {0x1p-24f, 0x0001},              /* smallest subnormal */
        {0x1p-25f, 0x0000},              /* tie: rounds to even zero */
        {0x1.8p-25f, 0x0001},
        {1e-6f, 0x0011},
        {3 * 0x1p-25f, 0x0002},          /* 1.5 units: tie to even */
        {5 * 0x1p-25f, 0x0002},          /* 2.5 units: tie to even */
        {1e-30f, 0x0000},
        {-0.0f, 0x8000},
        {-0x1p-24f, 0x8001},
        {2049.0f, 0x6800},               /* tie in a large binade */
        {2051.0f, 0x6802},
    };
    enum { N = sizeof cases / sizeof cases[0] };
    float px[N * 4];
    for (int i = 0; i < N; i++) px[i * 4] = cases[i].v, px[i * 4 + 1] = px[i * 4 + 2] = 0, px[i * 4 + 3] = 1;
    char path[128];
    REQUIRE(vxl_write_image(tmp(path, sizeof path, "half.exr"), px, NULL, N, 1) == VXL_OK);
    exr_image img;
    REQUIRE(exr_read(T_, path, &img) == 0);
    for (int i = 0; i < N; i++)
        CHECKF(img.half[3][i] == cases[i].h, "%a: %04x, want %04x", (double)cases[i].v, img.half[3][i], cases[i].h);
    exr_compare(T_, &img, px, NULL, N, 1);
    exr_free(&img);
}

TEST(extension_case_and_sizes)
{
    float px[4 * 4] = {0.25f, 0.5f, 0.75f, 1.0f, 0, 0, 0, 0, 1, 1, 1, 1, 0.1f, 0.2f, 0.3f, 0.5f};
    char path[128];
    png_image img;
    exr_image e;
    CHECK(vxl_write_image(tmp(path, sizeof path, "UPPER.PNG"), px, NULL, 2, 2) == VXL_OK);
    if (png_read(T_, path, &img) == 0) {
        png_compare(T_, &img, px, 2, 2);
        free(img.px);
    }
    CHECK(vxl_write_image(tmp(path, sizeof path, "UPPER.Exr"), px, NULL, 4, 1) == VXL_OK);
    if (exr_read(T_, path, &e) == 0) {
        exr_compare(T_, &e, px, NULL, 4, 1);
        exr_free(&e);
    }
    CHECK(vxl_write_image(tmp(path, sizeof path, "one.png"), px, NULL, 1, 1) == VXL_OK);
    if (png_read(T_, path, &img) == 0) {
        png_compare(T_, &img, px, 1, 1);
        free(img.px);
    }
    /* The widest image allowed. */
    float *wide = calloc((size_t)65536 * 4, sizeof(float));
    REQUIRE(wide);
    for (size_t i = 0; i < 65536; i++) wide[i * 4] = wide[i * 4 + 3] = (float)(i % 256) / 255.0f;
    CHECK(vxl_write_image(tmp(path, sizeof path, "wide.exr"), wide, NULL, 65536, 1) == VXL_OK);
    if (exr_read(T_, path, &e) == 0) {
        exr_compare(T_, &e, wide, NULL, 65536, 1);
        exr_free(&e);
    }
    CHECK(vxl_write_image(tmp(path, sizeof path, "wide.png"), wide, NULL, 65536, 1) == VXL_OK);
    if (png_read(T_, path, &img) == 0) {
        png_compare(T_, &img, wide, 65536, 1);
        free(img.px);
    }
    free(wide);
}

TEST(bad_arguments_touch_nothing)
{
    float px[4] = {1, 1, 1, 1};
    char path[128];
    tmp(path, sizeof path, "keep.png");
    REQUIRE(vxl_write_image(path, px, NULL, 1, 1) == VXL_OK);
    size_t len0, len1;
    uint8_t *before = read_all(path, &len0);
    REQUIRE(before);
    CHECK(vxl_write_image(NULL, px, NULL, 1, 1) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_write_image(path, NULL, NULL, 1, 1) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_write_image(path, px, NULL, 0, 1) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_write_image(path, px, NULL, 1, 0) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_write_image(path, px, NULL, 65537, 1) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_write_image(path, px, NULL, 1, 65537) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_last_error(), "size") != NULL);
    uint8_t *after = read_all(path, &len1);
    CHECK(after && len1 == len0 && memcmp(before, after, len0) == 0);
    free(before);
    free(after);
    static const char *names[] = {"x.jpg", "png", "x.png.txt", "x.ex", ".pn"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        CHECK(vxl_write_image(tmp(path, sizeof path, names[i]), px, NULL, 1, 1) == VXL_ERR_INVALID_ARGUMENT);
        CHECKF(strstr(vxl_last_error(), ".png") && strstr(vxl_last_error(), names[i]), "%s", vxl_last_error());
        CHECK(!file_exists(path));
    }
}

TEST(io_errors_leave_no_file)
{
    float px[4 * 64 * 64];
    for (size_t i = 0; i < sizeof px / sizeof px[0]; i++) px[i] = (float)(i % 97) / 97.0f;
    char path[128];
    /* A folder that does not exist: cannot open, named in the message. */
    CHECK(vxl_write_image(tmp(path, sizeof path, "missing/x.png"), px, NULL, 64, 64) == VXL_ERR_IO);
    CHECKF(strstr(vxl_last_error(), "missing/x.png") != NULL, "%s", vxl_last_error());
    /* A full disk (/dev/full through a link with the right name): the write
     * fails and the partial file - here the link - is removed. */
    if (access("/dev/full", W_OK) == 0) {
        const char *exts[] = {"full.png", "full.exr"};
        for (int i = 0; i < 2; i++) {
            tmp(path, sizeof path, exts[i]);
            REQUIRE(symlink("/dev/full", path) == 0);
            int rc = vxl_write_image(path, px, i ? px : NULL, 64, 64);
            CHECKF(rc == VXL_ERR_IO, "%s: rc %d", exts[i], rc);
            CHECKF(strstr(vxl_last_error(), "failed") && strstr(vxl_last_error(), exts[i]), "%s", vxl_last_error());
            CHECK(!file_exists(path));
        }
    } else {
        fprintf(stderr, "  (no writable /dev/full: the full-disk case is not run)\n");
    }
}

static void remove_dir(const char *dir)
{
    static const char *names[] = {"a.png", "noise.png", "smooth.png", "filters.png", "a.exr", "depth.exr", "noise.exr", "half.exr",
                                  "UPPER.PNG", "UPPER.Exr", "one.png", "wide.exr", "wide.png", "keep.png",
                                  "full.png", "full.exr"};
    char path[128];
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) unlink(tmp(path, sizeof path, names[i]));
    if (rmdir(dir) != 0) fprintf(stderr, "rmdir %s: %s\n", dir, strerror(errno));
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_image_write_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(png_pixels_match);
    RUN(png_large_and_smooth);
    RUN(png_every_filter);
    RUN(exr_pixels_match);
    RUN(exr_depth_and_blocks);
    RUN(exr_half_rounding);
    RUN(extension_case_and_sizes);
    RUN(bad_arguments_touch_nothing);
    RUN(io_errors_leave_no_file);
    remove_dir(g_dir);
    return TEST_SUMMARY();
}
