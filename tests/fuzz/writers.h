/* writers.h - test-side writers for NRRD, MetaImage, PNG and TIFF files,
 * independent of the library's readers. Used by tests/test_loaders.c and by
 * tests/fuzz/make_seeds.c (the seed corpus). Header only; needs zlib.
 * Every function returns 0 on success. */
#ifndef VXL_TEST_WRITERS_H
#define VXL_TEST_WRITERS_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#define TW_RAW 0
#define TW_GZIP 1
#define TW_ZLIB 2

static int tw_write(const char *path, const void *a, size_t na, const void *b, size_t nb)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    int ok = (na == 0 || fwrite(a, 1, na, f) == na) && (nb == 0 || fwrite(b, 1, nb, f) == nb);
    return (fclose(f) == 0 && ok) ? 0 : -1;
}

/* Compresses with a gzip (TW_GZIP) or zlib (TW_ZLIB) wrapper; malloc'd. */
static unsigned char *tw_deflate(const void *data, size_t n, int mode, size_t *out_n)
{
    z_stream z;
    memset(&z, 0, sizeof z);
    if (deflateInit2(&z, 6, Z_DEFLATED, mode == TW_GZIP ? 31 : 15, 8, Z_DEFAULT_STRATEGY) != Z_OK) return NULL;
    size_t cap = deflateBound(&z, (uLong)n) + 64;
    unsigned char *out = malloc(cap);
    if (!out) {
        deflateEnd(&z);
        return NULL;
    }
    z.next_in = (Bytef *)(uintptr_t)data;
    z.avail_in = (uInt)n;
    z.next_out = out;
    z.avail_out = (uInt)cap;
    int r = deflate(&z, Z_FINISH);
    *out_n = cap - z.avail_out;
    deflateEnd(&z);
    if (r != Z_STREAM_END) {
        free(out);
        return NULL;
    }
    return out;
}

/* A copy of count elements of elem bytes with each element's bytes reversed
 * (to write the non-native byte order). */
static void *tw_swapped(const void *data, size_t count, size_t elem)
{
    unsigned char *c = malloc(count * elem + 1);
    if (!c) return NULL;
    const unsigned char *s = data;
    for (size_t i = 0; i < count; i++)
        for (size_t k = 0; k < elem; k++) c[i * elem + k] = s[i * elem + elem - 1 - k];
    return c;
}

/* Writes header text and the (optionally compressed) payload: attached
 * (header then data in path) when data_path is NULL, else the header to
 * path and the data to data_path. */
static int tw_write_header_data(const char *path, const char *header, const void *data, size_t n, int mode,
                                const char *data_path)
{
    const void *payload = data;
    size_t pn = n;
    unsigned char *z = NULL;
    if (mode != TW_RAW) {
        z = tw_deflate(data, n, mode, &pn);
        if (!z) return -1;
        payload = z;
    }
    int rc = data_path ? (tw_write(path, header, strlen(header), NULL, 0) || tw_write(data_path, payload, pn, NULL, 0))
                       : tw_write(path, header, strlen(header), payload, pn);
    free(z);
    return rc;
}

/* ------------------------------------------------------------------ PNG */

static void tw_be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

static int tw_png_chunk(FILE *f, const char *type, const unsigned char *data, size_t n)
{
    unsigned char hdr[8];
    tw_be32(hdr, (uint32_t)n);
    memcpy(hdr + 4, type, 4);
    uLong crc = crc32(0, hdr + 4, 4);
    if (n) crc = crc32(crc, data, (uInt)n);
    unsigned char c[4];
    tw_be32(c, (uint32_t)crc);
    return fwrite(hdr, 1, 8, f) == 8 && (n == 0 || fwrite(data, 1, n, f) == n) && fwrite(c, 1, 4, f) == 4 ? 0 : -1;
}

/* pixels: h rows top first, channels (1 grey, 2 grey+alpha, 3 RGB, 4 RGBA)
 * of bits 8 (uint8_t) or 16 (uint16_t, native order). */
static int tw_write_png(const char *path, uint32_t w, uint32_t h, int channels, int bits, const void *pixels)
{
    static const int color_type[5] = {0, 0, 4, 2, 6};
    size_t bps = (size_t)bits / 8, row = (size_t)w * channels * bps;
    unsigned char *raw = malloc((row + 1) * h + 1);
    if (!raw) return -1;
    for (uint32_t y = 0; y < h; y++) {
        unsigned char *d = raw + y * (row + 1);
        d[0] = 0; /* filter: none */
        for (size_t i = 0; i < (size_t)w * channels; i++) {
            if (bits == 8) d[1 + i] = ((const uint8_t *)pixels)[y * (size_t)w * channels + i];
            else {
                uint16_t v = ((const uint16_t *)pixels)[y * (size_t)w * channels + i];
                d[1 + 2 * i] = (unsigned char)(v >> 8);
                d[2 + 2 * i] = (unsigned char)v;
            }
        }
    }
    size_t zn = 0;
    unsigned char *z = tw_deflate(raw, (row + 1) * h, TW_ZLIB, &zn);
    free(raw);
    if (!z) return -1;
    FILE *f = fopen(path, "wb");
    if (!f) {
        free(z);
        return -1;
    }
    unsigned char ihdr[13];
    tw_be32(ihdr, w);
    tw_be32(ihdr + 4, h);
    ihdr[8] = (unsigned char)bits;
    ihdr[9] = (unsigned char)color_type[channels];
    ihdr[10] = ihdr[11] = ihdr[12] = 0;
    int rc = fwrite("\x89PNG\r\n\x1a\n", 1, 8, f) == 8 ? 0 : -1;
    rc |= tw_png_chunk(f, "IHDR", ihdr, 13);
    rc |= tw_png_chunk(f, "IDAT", z, zn);
    rc |= tw_png_chunk(f, "IEND", NULL, 0);
    free(z);
    return (fclose(f) == 0 && rc == 0) ? 0 : -1;
}

/* ----------------------------------------------------------------- TIFF */

static void tw_le16(unsigned char *p, uint16_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
}

static void tw_le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}

/* Little-endian, uncompressed, one strip per page. pixels: pages images of
 * h rows (top first) x w x channels samples of bits bits, native order;
 * sample_format 1 unsigned, 2 signed, 3 IEEE float. */
static int tw_write_tiff(const char *path, uint32_t w, uint32_t h, uint32_t pages, int channels, int bits,
                         int sample_format, const void *pixels)
{
    size_t page_bytes = (size_t)w * h * channels * (bits / 8);
    size_t nent = 11, ifd_size = 2 + nent * 12 + 4 + 2 * 2 * (size_t)channels; /* + arrays */
    size_t total = 8 + pages * (page_bytes + ifd_size + 4);
    unsigned char *b = calloc(1, total);
    if (!b) return -1;
    memcpy(b, "II*\0", 4);
    size_t pos = 8;
    size_t prev_next = 4; /* where the offset of the next IFD goes */
    for (uint32_t p = 0; p < pages; p++) {
        size_t data_at = pos;
        memcpy(b + pos, (const unsigned char *)pixels + p * page_bytes, page_bytes);
        pos += page_bytes;
        pos += pos & 1; /* IFDs start on a word boundary */
        size_t ifd = pos;
        tw_le32(b + prev_next, (uint32_t)ifd);
        size_t arrays = ifd + 2 + nent * 12 + 4;
        tw_le16(b + ifd, (uint16_t)nent);
        unsigned char *e = b + ifd + 2;
        int k = 0;
#define TW_ENTRY(tag, type, count, value)                 \
    do {                                                  \
        tw_le16(e + 12 * k, tag);                         \
        tw_le16(e + 12 * k + 2, type);                    \
        tw_le32(e + 12 * k + 4, count);                   \
        if ((type) == 3 && (count) == 1) tw_le16(e + 12 * k + 8, (uint16_t)(value)); \
        else tw_le32(e + 12 * k + 8, (uint32_t)(value));  \
        k++;                                              \
    } while (0)
        size_t bits_at = arrays, fmt_at = arrays + 2 * (size_t)channels;
        for (int c = 0; c < channels; c++) {
            tw_le16(b + bits_at + 2 * c, (uint16_t)bits);
            tw_le16(b + fmt_at + 2 * c, (uint16_t)sample_format);
        }
        TW_ENTRY(256, 4, 1, w);
        TW_ENTRY(257, 4, 1, h);
        if (channels <= 2) {
            /* two SHORTs fit in the value field */
            tw_le16(e + 12 * k, 258); tw_le16(e + 12 * k + 2, 3); tw_le32(e + 12 * k + 4, (uint32_t)channels);
            tw_le16(e + 12 * k + 8, (uint16_t)bits); if (channels == 2) tw_le16(e + 12 * k + 10, (uint16_t)bits);
            k++;
        } else {
            TW_ENTRY(258, 3, (uint32_t)channels, bits_at);
        }
        TW_ENTRY(259, 3, 1, 1);
        TW_ENTRY(262, 3, 1, channels >= 3 ? 2 : 1);
        TW_ENTRY(273, 4, 1, data_at);
        TW_ENTRY(277, 3, 1, channels);
        TW_ENTRY(278, 4, 1, h);
        TW_ENTRY(279, 4, 1, page_bytes);
        TW_ENTRY(284, 3, 1, 1);
        if (channels <= 2) {
            tw_le16(e + 12 * k, 339); tw_le16(e + 12 * k + 2, 3); tw_le32(e + 12 * k + 4, (uint32_t)channels);
            tw_le16(e + 12 * k + 8, (uint16_t)sample_format);
            if (channels == 2) tw_le16(e + 12 * k + 10, (uint16_t)sample_format);
            k++;
        } else {
            TW_ENTRY(339, 3, (uint32_t)channels, fmt_at);
        }
#undef TW_ENTRY
        prev_next = ifd + 2 + nent * 12;
        tw_le32(b + prev_next, 0);
        pos = arrays + 4 * (size_t)channels;
    }
    int rc = tw_write(path, b, pos, NULL, 0);
    free(b);
    return rc;
}

#endif
