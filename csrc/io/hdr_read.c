/* hdr_read.c - the Radiance RGBE decoder (hdr_read.h). The format: text
 * header lines ("#?RADIANCE" or "#?RGBE" first, FORMAT=32-bit_rle_rgbe,
 * other variables ignored) up to an empty line, a resolution line
 * "-Y H +X W" (top row first, the common one) or "+Y H +X W" (bottom row
 * first), then H scanlines of W pixels, each either flat (4 bytes R, G, B,
 * E per pixel) or, for 8 <= W < 32768, run-length encoded: the bytes 2 2
 * then W as 16 bits, then the four channels one after the other, each as
 * runs (a count c > 128: the next byte c - 128 times) and literals (c <= 128:
 * the next c bytes). The old run-length scheme (pixels 1 1 1 n repeating
 * the previous pixel) is refused, as are other orientations and the XYZE
 * colour format: what the tools write today is the above. A pixel is
 * (channel + 0.5) * 2^(E - 136), 0 when E is 0, as Radiance's colr_color. */
#include "hdr_read.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "voxlight.h"

#define MAX_HEADER 65536u /* bytes of header text; real ones are a few lines */
#define MAX_SIDE 65535u

typedef struct cursor {
    const uint8_t *p;
    size_t left;
} cursor;

static int bad(vxl_err *e, const char *what) { return vxl_fail(e, VXL_ERR_FORMAT, "Radiance .hdr: %s", what); }

/* One header line without its newline, at most cap - 1 bytes; 0 at the end of data. */
static int next_line(cursor *c, char *out, size_t cap)
{
    size_t n = 0;
    while (c->left) {
        uint8_t b = *c->p++;
        c->left--;
        if (b == '\n') {
            out[n] = '\0';
            return 1;
        }
        if (n + 1 < cap) out[n++] = (char)b;
    }
    return 0;
}

static int read_header(cursor *c, uint32_t *w, uint32_t *h, int *top_first, vxl_err *e)
{
    char line[256];
    size_t start = c->left;
    if (!next_line(c, line, sizeof line) || (strncmp(line, "#?RADIANCE", 10) && strncmp(line, "#?RGBE", 6)))
        return bad(e, "no #?RADIANCE signature on the first line");
    for (;;) {
        if (start - c->left > MAX_HEADER) return bad(e, "the header is longer than 64 KiB");
        if (!next_line(c, line, sizeof line)) return bad(e, "the header never ends (no empty line)");
        if (!line[0]) break;
        if (!strncmp(line, "FORMAT=", 7) && strcmp(line + 7, "32-bit_rle_rgbe"))
            return vxl_fail(e, VXL_ERR_FORMAT, "Radiance .hdr: FORMAT=%.40s is not supported (only 32-bit_rle_rgbe)",
                            line + 7);
    }
    if (!next_line(c, line, sizeof line)) return bad(e, "no resolution line");
    char ya[3] = "", xa[3] = "";
    unsigned long hv = 0, wv = 0;
    char tail;
    /* %2s reads "-Y" or "+Y"; the trailing %c catches anything after the width */
    if (sscanf(line, "%2s %lu %2s %lu%c", ya, &hv, xa, &wv, &tail) != 4)
        return vxl_fail(e, VXL_ERR_FORMAT, "Radiance .hdr: resolution line \"%.60s\" is not \"-Y H +X W\"", line);
    if (strcmp(xa, "+X") || (strcmp(ya, "-Y") && strcmp(ya, "+Y")))
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "Radiance .hdr: orientation \"%s %s\" is not supported (only -Y H +X W and +Y H +X W)", ya, xa);
    if (hv < 1 || wv < 1 || hv > MAX_SIDE || wv > MAX_SIDE)
        return vxl_fail(e, VXL_ERR_FORMAT, "Radiance .hdr: size %lux%lu must be 1..%u per side", wv, hv, MAX_SIDE);
    *w = (uint32_t)wv;
    *h = (uint32_t)hv;
    *top_first = ya[0] == '-';
    return VXL_OK;
}

static void to_float(const uint8_t rgbe[4], float *out)
{
    if (!rgbe[3]) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    const float f = ldexpf(1.0f, (int)rgbe[3] - 136);
    for (int k = 0; k < 3; k++) out[k] = ((float)rgbe[k] + 0.5f) * f;
}

/* One run-length scanline's four channels into line (w * 4 bytes, RGBE interleaved). */
static int read_rle(cursor *c, uint32_t w, uint8_t *line, vxl_err *e)
{
    for (int ch = 0; ch < 4; ch++) {
        uint32_t x = 0;
        while (x < w) {
            if (!c->left) return bad(e, "truncated inside a run-length scanline");
            uint32_t n = *c->p++;
            c->left--;
            if (n > 128) {
                n -= 128;
                if (n > w - x) return bad(e, "a run passes the end of its scanline");
                if (!c->left) return bad(e, "truncated inside a run");
                for (uint32_t i = 0; i < n; i++) line[(x + i) * 4 + ch] = *c->p;
                c->p++;
                c->left--;
            } else {
                if (n == 0) return bad(e, "a run-length scanline has a zero count");
                if (n > w - x) return bad(e, "literal bytes pass the end of their scanline");
                if (c->left < n) return bad(e, "truncated inside literal bytes");
                for (uint32_t i = 0; i < n; i++) line[(x + i) * 4 + ch] = c->p[i];
                c->p += n;
                c->left -= n;
            }
            x += n;
        }
    }
    return VXL_OK;
}

int vxl_hdr_decode(const uint8_t *data, size_t size, uint64_t max_pixels, float *rgb, uint32_t *width,
                   uint32_t *height, vxl_err *e)
{
    cursor c = {data, size};
    uint32_t w = 0, h = 0;
    int top_first = 1;
    int rc = read_header(&c, &w, &h, &top_first, e);
    if (rc) return rc;
    if ((uint64_t)w * h > max_pixels)
        return vxl_fail(e, VXL_ERR_LIMIT, "Radiance .hdr: %ux%u pixels exceed the limit of %llu", w, h,
                        (unsigned long long)max_pixels);
    /* the smallest a scanline can be coded in: a run of 127 bytes takes 2 */
    if ((uint64_t)h * (w < 8 ? 4u * w : 4u + 8u * ((w + 126) / 127)) > c.left)
        return bad(e, "the file is too short for its size");
    *width = w;
    *height = h;
    if (!rgb) return VXL_OK;
    uint8_t *line = malloc((size_t)w * 4);
    if (!line) return vxl_fail(e, VXL_ERR_NO_MEMORY, "Radiance .hdr: no memory for a scanline of %u pixels", w);
    for (uint32_t y = 0; y < h && !rc; y++) {
        const int rle = w >= 8 && w < 32768 && c.left >= 4 && c.p[0] == 2 && c.p[1] == 2 && !(c.p[2] & 0x80);
        if (rle) {
            if (((uint32_t)c.p[2] << 8 | c.p[3]) != w) {
                rc = bad(e, "a scanline's length differs from the width");
                break;
            }
            c.p += 4;
            c.left -= 4;
            if ((rc = read_rle(&c, w, line, e))) break;
        } else {
            if (c.left < (size_t)w * 4) {
                rc = bad(e, "truncated inside a flat scanline");
                break;
            }
            for (uint32_t x = 0; x < w && !rc; x++)
                if (c.p[4 * x] == 1 && c.p[4 * x + 1] == 1 && c.p[4 * x + 2] == 1)
                    rc = bad(e, "old-style run-length encoding (pixels 1 1 1 n) is not supported");
            if (rc) break;
            memcpy(line, c.p, (size_t)w * 4);
            c.p += (size_t)w * 4;
            c.left -= (size_t)w * 4;
        }
        /* row 0 is the bottom: a top-first file's first scanline is the last row */
        float *row = rgb + (size_t)(top_first ? h - 1 - y : y) * w * 3;
        for (uint32_t x = 0; x < w; x++) to_float(line + 4 * x, row + 3 * x);
    }
    free(line);
    return rc;
}
