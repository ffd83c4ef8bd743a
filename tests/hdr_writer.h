/* hdr_writer.h - Radiance RGBE files written from floats for the tests and
 * the fuzz seeds: flat or run-length-encoded scanlines (runs of repeats of
 * 3 or more, literals otherwise), top row first ("-Y H +X W") or bottom
 * first. The reader is csrc/io/hdr_read.c. */
#ifndef VXL_TEST_HDR_WRITER_H
#define VXL_TEST_HDR_WRITER_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static inline void hdr_rgbe(const float *rgb, uint8_t out[4])
{
    float m = rgb[0] > rgb[1] ? rgb[0] : rgb[1];
    m = m > rgb[2] ? m : rgb[2];
    if (!(m > 1e-32f)) {
        memset(out, 0, 4);
        return;
    }
    int ex;
    float f = frexpf(m, &ex) * 256.0f / m;
    for (int k = 0; k < 3; k++) out[k] = (uint8_t)(rgb[k] * f);
    out[3] = (uint8_t)(ex + 128);
}

/* One channel's bytes (n of them, stride 4) as runs and literals. */
static inline size_t hdr_rle_channel(const uint8_t *px, uint32_t n, uint8_t *out)
{
    size_t o = 0;
    uint32_t x = 0;
    while (x < n) {
        uint32_t run = 1;
        while (x + run < n && run < 127 && px[4 * (x + run)] == px[4 * x]) run++;
        if (run >= 3) {
            out[o++] = (uint8_t)(128 + run);
            out[o++] = px[4 * x];
            x += run;
            continue;
        }
        uint32_t lit = 0; /* up to the next run of 3 */
        while (x + lit < n && lit < 128 &&
               !(x + lit + 2 < n && px[4 * (x + lit)] == px[4 * (x + lit + 1)] && px[4 * (x + lit)] == px[4 * (x + lit + 2)]))
            lit++;
        if (!lit) lit = 1;
        out[o++] = (uint8_t)lit;
        for (uint32_t i = 0; i < lit; i++) out[o++] = px[4 * (x + i)];
        x += lit;
    }
    return o;
}

/* The file's bytes (malloc'd, *size of them): rgb has w*h*3 floats, row 0 at the bottom. */
static inline uint8_t *hdr_encode(const float *rgb, uint32_t w, uint32_t h, int rle, int top_first, size_t *size)
{
    char head[128];
    int hn = snprintf(head, sizeof head, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n%s %u +X %u\n",
                      top_first ? "-Y" : "+Y", h, w);
    size_t cap = (size_t)hn + (size_t)h * (4 + (size_t)w * 8) + 16;
    uint8_t *out = malloc(cap), *line = malloc((size_t)w * 4 + 4);
    if (!out || !line) {
        free(out);
        free(line);
        return NULL;
    }
    memcpy(out, head, (size_t)hn);
    size_t o = (size_t)hn;
    for (uint32_t y = 0; y < h; y++) {
        const float *row = rgb + (size_t)(top_first ? h - 1 - y : y) * w * 3;
        for (uint32_t x = 0; x < w; x++) hdr_rgbe(row + 3 * x, line + 4 * x);
        if (rle && w >= 8 && w < 32768) {
            out[o++] = 2;
            out[o++] = 2;
            out[o++] = (uint8_t)(w >> 8);
            out[o++] = (uint8_t)(w & 255);
            for (int c = 0; c < 4; c++) o += hdr_rle_channel(line + c, w, out + o);
        } else {
            memcpy(out + o, line, (size_t)w * 4);
            o += (size_t)w * 4;
        }
    }
    free(line);
    *size = o;
    return out;
}

static inline int hdr_write_file(const char *path, const float *rgb, uint32_t w, uint32_t h, int rle)
{
    size_t n = 0;
    uint8_t *b = hdr_encode(rgb, w, h, rle, 1, &n);
    FILE *f = b ? fopen(path, "wb") : NULL;
    int ok = f && fwrite(b, 1, n, f) == n;
    if (f) ok = fclose(f) == 0 && ok;
    free(b);
    return ok ? 0 : -1;
}

#endif
