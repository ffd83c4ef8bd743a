/* image_write.c - vxl_write_image: the renderer's premultiplied float RGBA
 * (row 0 = bottom) to an 8-bit straight-alpha PNG or to a half-float
 * premultiplied OpenEXR with an optional 32-bit float Z channel. Both formats
 * are written here with zlib alone, so the library links no image library.
 *
 * PNG: one IHDR, IDAT chunks from a streamed deflate, IEND; each row gets the
 * filter with the smallest sum of absolute differences (the usual heuristic).
 * EXR: OpenEXR 2, single part, scanline, ZIP compression (16-line blocks,
 * byte interleave + delta predictor + zlib), increasing Y. Files hold the top
 * row first. On a failed write the partial file is removed. */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "crc32.h"
#include "files.h"
#include "zlib_api.h"

#include "error.h"
#include "voxlight.h"

#define MAX_SIDE 65536u
#define PNG_IDAT_MAX 65536u /* bytes of deflate output per IDAT chunk */
#define EXR_ZIP_LINES 16u   /* scanlines per chunk in EXR's ZIP compression */

/* ------------------------------------------------------------------ output */

/* A file being written: remembers the first write error so the callers can
 * write a whole section and check once. */
typedef struct out_file {
    const vxl_zlib *z;
    FILE *f;
    const char *path;
    int err; /* errno of the first failed write, 0 while all is well */
} out_file;

static void out_put(out_file *o, const void *p, size_t n)
{
    if (o->err || n == 0) return;
    if (fwrite(p, 1, n, o->f) != n) o->err = errno ? errno : EIO;
}

static void put_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

static void put_le16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

static void put_le32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i));
}

static void put_le64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++) p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

/* ------------------------------------------------------------------ pixels */

/* Non-finite colour (a broken shader or transfer function) becomes 0 rather
 * than poisoning the file. */
static float finite_or_zero(float v) { return isfinite(v) ? v : 0.0f; }

/* Float [0,1] to 8 bits the way OpenImageIO converts: scale, add 0.5, clamp,
 * truncate, all in float - so PNGs match what the library wrote before. */
static uint8_t unorm8(float v)
{
    float s = v * 255.0f + 0.5f;
    if (!(s > 0.0f)) return 0;
    if (s > 255.0f) return 255;
    return (uint8_t)s;
}

/* IEEE binary16 from binary32, rounding to nearest even: values at or above
 * 65520 become infinity, tiny ones become subnormals or signed zero. */
static uint16_t half_from_float(float f)
{
    uint32_t x = float_bits(f);
    uint16_t sign = (uint16_t)((x >> 16) & 0x8000u);
    uint32_t ax = x & 0x7fffffffu;
    if (ax >= 0x7f800000u) /* inf stays inf; NaN stays a (quiet) NaN */
        return (uint16_t)(sign | 0x7c00u | (ax > 0x7f800000u ? 0x200u | ((ax >> 13) & 0x3ffu) : 0u));
    if (ax >= 0x477ff000u) return (uint16_t)(sign | 0x7c00u); /* >= 65520: past the largest half */
    if (ax < 0x38800000u) {                                    /* below 2^-14: subnormal half */
        if (ax <= 0x33000000u) return sign;                    /* <= 2^-25 rounds (to even) to 0 */
        uint32_t m = (ax & 0x7fffffu) | 0x800000u;
        uint32_t shift = 126u - (ax >> 23); /* 14..24: units of 2^-24 */
        uint32_t r = m >> shift, rem = m & ((1u << shift) - 1u), halfway = 1u << (shift - 1u);
        if (rem > halfway || (rem == halfway && (r & 1u))) r++; /* may carry into the smallest normal */
        return (uint16_t)(sign | r);
    }
    uint32_t h = (ax >> 13) - (112u << 10); /* rebias the exponent from 127 to 15 */
    uint32_t rem = ax & 0x1fffu;
    if (rem > 0x1000u || (rem == 0x1000u && (h & 1u))) h++; /* a carry moves into the exponent correctly */
    return (uint16_t)(sign | h);
}

/* One file row (top first) of 8-bit straight-alpha RGBA. */
static void png_pixels(const float *rgba, uint32_t w, uint32_t h, uint32_t y, uint8_t *out)
{
    const float *row = rgba + (size_t)(h - 1 - y) * w * 4;
    for (uint32_t x = 0; x < w; x++) {
        const float *s = row + (size_t)x * 4;
        float a = s[3];
        float c[4];
        for (int k = 0; k < 4; k++) c[k] = finite_or_zero(s[k]);
        if (a > 0) /* PNG holds straight alpha */
            for (int k = 0; k < 3; k++) c[k] = fminf(1.0f, c[k] / a);
        for (int k = 0; k < 4; k++) out[(size_t)x * 4 + k] = unorm8(c[k]);
    }
}

/* ------------------------------------------------------------------ PNG */

static void png_chunk(out_file *o, const char type[4], const uint8_t *data, uint32_t n)
{
    uint8_t head[8], tail[4];
    put_be32(head, n);
    memcpy(head + 4, type, 4);
    uint32_t crc = vxl_crc32(0, type, 4);
    if (n) crc = vxl_crc32(crc, data, n);
    put_be32(tail, crc);
    out_put(o, head, sizeof head);
    out_put(o, data, n);
    out_put(o, tail, sizeof tail);
}

static int paeth(int a, int b, int c)
{
    int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    if (pa <= pb && pa <= pc) return a;
    return pb <= pc ? b : c;
}

/* Writes filter type t of row cur (previous row prev) into out[0..n]: out[0]
 * is the type byte. Returns the sum of |filtered byte as signed|. */
static unsigned long png_filter(int t, const uint8_t *cur, const uint8_t *prev, size_t n, uint8_t *out)
{
    unsigned long cost = 0;
    out[0] = (uint8_t)t;
    for (size_t i = 0; i < n; i++) {
        int a = i >= 4 ? cur[i - 4] : 0, b = prev[i], c = i >= 4 ? prev[i - 4] : 0, p = 0;
        switch (t) {
        case 1: p = a; break;
        case 2: p = b; break;
        case 3: p = (a + b) / 2; break;
        case 4: p = paeth(a, b, c); break;
        default: break;
        }
        uint8_t v = (uint8_t)(cur[i] - p);
        out[1 + i] = v;
        cost += v < 128 ? v : 256u - v;
    }
    return cost;
}

/* Feeds in (flush = Z_NO_FLUSH or Z_FINISH) through deflate, writing an IDAT
 * chunk each time the output buffer fills and, at Z_FINISH, the rest. */
static int png_deflate(out_file *o, z_stream *zs, const uint8_t *in, size_t n, int flush, uint8_t *buf)
{
    zs->next_in = (Bytef *)(uintptr_t)in;
    zs->avail_in = (uInt)n;
    for (;;) {
        int rc = o->z->deflate(zs, flush);
        if (rc != Z_OK && rc != Z_STREAM_END && rc != Z_BUF_ERROR) return -1;
        uint32_t have = PNG_IDAT_MAX - zs->avail_out;
        if (zs->avail_out == 0 || (rc == Z_STREAM_END && have)) {
            png_chunk(o, "IDAT", buf, have);
            zs->next_out = buf;
            zs->avail_out = PNG_IDAT_MAX;
        }
        if (rc == Z_STREAM_END) return 0;
        if (flush != Z_FINISH && zs->avail_in == 0 && zs->avail_out != 0) return 0;
    }
}

static int write_png(out_file *o, const float *rgba, uint32_t w, uint32_t h)
{
    size_t n = (size_t)w * 4;
    uint8_t *rows = malloc(2 * n), *cand = malloc(5 * (n + 1)), *buf = malloc(PNG_IDAT_MAX);
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    int zok = o->z->deflateInit_(&zs, Z_DEFAULT_COMPRESSION, ZLIB_VERSION, (int)sizeof zs) == Z_OK;
    int rc = VXL_OK;
    if (!rows || !cand || !buf || !zok) {
        rc = vxl_fail(NULL, VXL_ERR_NO_MEMORY, "write_image: out of memory writing %s", o->path);
        goto done;
    }
    zs.next_out = buf;
    zs.avail_out = PNG_IDAT_MAX;

    static const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    uint8_t ihdr[13];
    put_be32(ihdr, w);
    put_be32(ihdr + 4, h);
    ihdr[8] = 8;  /* bits per sample */
    ihdr[9] = 6;  /* colour type: RGBA */
    ihdr[10] = 0; /* deflate */
    ihdr[11] = 0; /* adaptive filtering, the only method */
    ihdr[12] = 0; /* not interlaced */
    out_put(o, signature, sizeof signature);
    png_chunk(o, "IHDR", ihdr, sizeof ihdr);

    uint8_t *prev = rows, *cur = rows + n;
    memset(prev, 0, n);
    for (uint32_t y = 0; y < h && !o->err; y++) {
        png_pixels(rgba, w, h, y, cur);
        int best = 0;
        unsigned long best_cost = 0;
        for (int t = 0; t < 5; t++) {
            unsigned long cost = png_filter(t, cur, prev, n, cand + (size_t)t * (n + 1));
            if (t == 0 || cost < best_cost) {
                best = t;
                best_cost = cost;
            }
        }
        if (png_deflate(o, &zs, cand + (size_t)best * (n + 1), n + 1, Z_NO_FLUSH, buf)) {
            rc = vxl_fail(NULL, VXL_ERR_IO, "write_image: compressing %s failed", o->path);
            goto done;
        }
        uint8_t *t = prev;
        prev = cur;
        cur = t;
    }
    if (png_deflate(o, &zs, NULL, 0, Z_FINISH, buf)) {
        rc = vxl_fail(NULL, VXL_ERR_IO, "write_image: compressing %s failed", o->path);
        goto done;
    }
    png_chunk(o, "IEND", NULL, 0);
done:
    if (zok) o->z->deflateEnd(&zs);
    free(rows);
    free(cand);
    free(buf);
    return rc;
}

/* ------------------------------------------------------------------ EXR */

/* EXR lists channels sorted by name; src is the channel's index in our
 * RGBA pixel, 4 meaning depth. */
typedef struct exr_channel {
    const char *name;
    int src;
    int type; /* 1 = HALF, 2 = FLOAT */
} exr_channel;

static const exr_channel k_exr_channels[5] = {{"A", 3, 1}, {"B", 2, 1}, {"G", 1, 1}, {"R", 0, 1}, {"Z", 4, 2}};

/* Appends one header attribute (name, type, size, value) to hdr at *len. */
static void exr_attr(uint8_t *hdr, size_t *len, const char *name, const char *type, const void *v, uint32_t n)
{
    size_t a = strlen(name) + 1, b = strlen(type) + 1;
    memcpy(hdr + *len, name, a);
    memcpy(hdr + *len + a, type, b);
    put_le32(hdr + *len + a + b, n);
    memcpy(hdr + *len + a + b + 4, v, n);
    *len += a + b + 4 + n;
}

/* The header: magic, version 2 (single-part scanline), attributes in name
 * order, the terminating 0. Returns its length; hdr holds at least 512 bytes. */
static size_t exr_header(uint8_t *hdr, uint32_t w, uint32_t h, int nch)
{
    size_t len = 0;
    uint8_t chlist[5 * 18 + 1], box[16], v[8];
    size_t cl = 0;
    for (int c = 0; c < nch; c++) {
        chlist[cl++] = (uint8_t)k_exr_channels[c].name[0];
        chlist[cl++] = 0;
        put_le32(chlist + cl, (uint32_t)k_exr_channels[c].type);
        chlist[cl + 4] = 0; /* pLinear */
        chlist[cl + 5] = chlist[cl + 6] = chlist[cl + 7] = 0;
        put_le32(chlist + cl + 8, 1); /* x sampling */
        put_le32(chlist + cl + 12, 1); /* y sampling */
        cl += 16;
    }
    chlist[cl++] = 0;

    put_le32(hdr, 20000630u); /* magic 76 2f 31 01 */
    put_le32(hdr + 4, 2);      /* version 2, no flags: scanline, short names */
    len = 8;
    exr_attr(hdr, &len, "channels", "chlist", chlist, (uint32_t)cl);
    uint8_t zip = 3; /* ZIP_COMPRESSION: 16 scanlines per chunk */
    exr_attr(hdr, &len, "compression", "compression", &zip, 1);
    put_le32(box, 0);
    put_le32(box + 4, 0);
    put_le32(box + 8, w - 1);
    put_le32(box + 12, h - 1);
    exr_attr(hdr, &len, "dataWindow", "box2i", box, 16);
    exr_attr(hdr, &len, "displayWindow", "box2i", box, 16);
    uint8_t increasing_y = 0;
    exr_attr(hdr, &len, "lineOrder", "lineOrder", &increasing_y, 1);
    put_le32(v, float_bits(1.0f));
    exr_attr(hdr, &len, "pixelAspectRatio", "float", v, 4);
    memset(v, 0, 8);
    exr_attr(hdr, &len, "screenWindowCenter", "v2f", v, 8);
    put_le32(v, float_bits(1.0f));
    exr_attr(hdr, &len, "screenWindowWidth", "float", v, 4);
    hdr[len++] = 0;
    return len;
}

/* The uncompressed chunk for file rows y0..y1-1: per row, each channel's
 * samples in channel order, little endian. Returns its size. */
static size_t exr_block(const float *rgba, const float *depth, uint32_t w, uint32_t h, int nch, uint32_t y0,
                        uint32_t y1, uint8_t *out)
{
    uint8_t *p = out;
    for (uint32_t y = y0; y < y1; y++) {
        size_t row = (size_t)(h - 1 - y) * w;
        for (int c = 0; c < nch; c++) {
            int src = k_exr_channels[c].src;
            for (uint32_t x = 0; x < w; x++) {
                if (src == 4) {
                    put_le32(p, float_bits(depth[row + x]));
                    p += 4;
                } else {
                    put_le16(p, half_from_float(finite_or_zero(rgba[(row + x) * 4 + (size_t)src])));
                    p += 2;
                }
            }
        }
    }
    return (size_t)(p - out);
}

/* EXR's ZIP pre-pass: even bytes then odd bytes, then each byte stored as
 * the difference from the one before (+128), which zlib compresses well. */
static void exr_zip_predict(const uint8_t *in, size_t n, uint8_t *out)
{
    size_t half = (n + 1) / 2;
    for (size_t i = 0; i < n; i++) out[(i & 1) ? half + i / 2 : i / 2] = in[i];
    uint8_t prev = n ? out[0] : 0;
    for (size_t i = 1; i < n; i++) {
        uint8_t cur = out[i];
        out[i] = (uint8_t)(cur - prev + 128);
        prev = cur;
    }
}

static int write_exr(out_file *o, const float *rgba, const float *depth, uint32_t w, uint32_t h)
{
    int nch = depth ? 5 : 4;
    size_t line = (size_t)w * (depth ? 4 * 2 + 4 : 4 * 2);
    size_t raw_max = line * EXR_ZIP_LINES;
    uLong zmax = o->z->compressBound((uLong)raw_max);
    uint32_t nblocks = (h + EXR_ZIP_LINES - 1) / EXR_ZIP_LINES;
    uint8_t *raw = malloc(raw_max), *pred = malloc(raw_max), *z = malloc(zmax);
    uint8_t *offsets = calloc(nblocks, 8);
    int rc = VXL_OK;
    if (!raw || !pred || !z || !offsets) {
        rc = vxl_fail(NULL, VXL_ERR_NO_MEMORY, "write_image: out of memory writing %s", o->path);
        goto done;
    }
    uint8_t hdr[512];
    size_t hlen = exr_header(hdr, w, h, nch);
    out_put(o, hdr, hlen);
    out_put(o, offsets, (size_t)nblocks * 8); /* placeholder, rewritten below */
    uint64_t pos = hlen + (uint64_t)nblocks * 8;
    for (uint32_t b = 0; b < nblocks && !o->err; b++) {
        uint32_t y0 = b * EXR_ZIP_LINES, y1 = y0 + EXR_ZIP_LINES < h ? y0 + EXR_ZIP_LINES : h;
        size_t n = exr_block(rgba, depth, w, h, nch, y0, y1, raw);
        exr_zip_predict(raw, n, pred);
        uLongf zn = zmax;
        if (o->z->compress2(z, &zn, pred, (uLong)n, Z_DEFAULT_COMPRESSION) != Z_OK) {
            rc = vxl_fail(NULL, VXL_ERR_IO, "write_image: compressing %s failed", o->path);
            goto done;
        }
        /* A chunk no smaller than the raw data is stored raw, as readers expect. */
        const uint8_t *data = zn < n ? z : raw;
        size_t dn = zn < n ? zn : n;
        uint8_t head[8];
        put_le32(head, y0);
        put_le32(head + 4, (uint32_t)dn);
        put_le64(offsets + (size_t)b * 8, pos);
        out_put(o, head, sizeof head);
        out_put(o, data, dn);
        pos += sizeof head + dn;
    }
    if (!o->err && fseek(o->f, (long)hlen, SEEK_SET) != 0) o->err = errno ? errno : EIO;
    out_put(o, offsets, (size_t)nblocks * 8);
done:
    free(raw);
    free(pred);
    free(z);
    free(offsets);
    return rc;
}

/* ------------------------------------------------------------------ entry */

static int ends_with_ci(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    if (n < m) return 0;
    for (size_t i = 0; i < m; i++) {
        char c = s[n - m + i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != suffix[i]) return 0;
    }
    return 1;
}

VXL_API int vxl_write_image(const char *path, const float *rgba, const float *depth, uint32_t w, uint32_t h)
{
    if (!path || !rgba || w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "write_image: bad path, buffer or size");
    int exr = ends_with_ci(path, ".exr");
    if (!exr && !ends_with_ci(path, ".png"))
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "write_image: %s: use a .png or .exr name", path);
    const vxl_zlib *z = vxl_zlib_api(NULL);
    if (!z) return VXL_ERR_IO;
    out_file o = {z, vxl_fopen(path, "wb"), path, 0};
    if (!o.f) return vxl_fail(NULL, VXL_ERR_IO, "write_image: cannot open %s for writing: %s", path, strerror(errno));
    int rc = exr ? write_exr(&o, rgba, depth, w, h) : write_png(&o, rgba, w, h);
    if (fclose(o.f) != 0 && !o.err) o.err = errno ? errno : EIO;
    if (rc == VXL_OK && o.err)
        rc = vxl_fail(NULL, VXL_ERR_IO, "write_image: writing %s failed: %s", path, strerror(o.err));
    if (rc != VXL_OK) remove(path); /* a partial image is worse than none */
    return rc;
}
