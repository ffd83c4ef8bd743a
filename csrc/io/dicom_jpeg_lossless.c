/* dicom_jpeg_lossless.c - dicom_jpeg_lossless.h, after ITU T.81: markers
 * (B.1), Huffman tables as code lengths (C, F.2.2.3's MAXCODE/VALPTR
 * decoding), the lossless differences (H.1.2: SSSS and its extra bits,
 * 16 meaning 32768) and predictors (H.1.2.1, with the first line and a
 * restart's first line predicted from the left, the first column from
 * above), modulo 2^16. */
#include "dicom_jpeg_lossless.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A failure of this frame: a format error, every message naming the codec. */
#define BAD(...) vxl_fail(e, VXL_ERR_FORMAT, "lossless JPEG: " __VA_ARGS__)

typedef struct huff {
    int defined;
    int32_t maxcode[18]; /* largest code of each length, -1 when none */
    int32_t valptr[17];  /* index in vals of each length's first code */
    int32_t mincode[17];
    uint8_t vals[256];
} huff;

typedef struct reader {
    const uint8_t *p, *end; /* the entropy-coded data */
    uint32_t bits;          /* bit buffer, most significant first */
    int nbits;
    int marker;             /* a marker met inside the data (0: none; -1: the data ran out) */
    int pad;                /* zero bytes fed past the data or a marker: the buffer's last 8 * pad bits */
} reader;

static unsigned be16(const uint8_t *p) { return (unsigned)p[0] << 8 | p[1]; }

/* One DHT table's counts and values into h; the bytes it took, or 0. */
static size_t read_table(const uint8_t *p, size_t n, huff *h)
{
    if (n < 16) return 0;
    size_t total = 0;
    for (int l = 0; l < 16; l++) total += p[l];
    if (total > 256 || 16 + total > n) return 0;
    memcpy(h->vals, p + 16, total);
    int32_t code = 0, k = 0;
    for (int l = 1; l <= 16; l++) {
        const int count = p[l - 1];
        if (count) {
            h->valptr[l] = k;
            h->mincode[l] = code;
            code += count;
            k += count;
            h->maxcode[l] = code - 1;
            if (code - 1 >= (1 << l)) return 0; /* more codes than bits allow */
        } else {
            h->maxcode[l] = -1;
        }
        code <<= 1;
    }
    h->maxcode[17] = 0x7fffffff;
    h->defined = 1;
    return 16 + total;
}

/* Tops the bit buffer up to at least 25 bits: FF00 is a data FF; FF
 * followed by anything else is a marker, which ends the data. Past the end
 * or a marker zeros are fed (counted in pad), so a decoder that reads into
 * them has met cut-short data (consumed_padding). */
static void fill(reader *r)
{
    while (r->nbits <= 24) {
        uint32_t byte = 0;
        if (!r->marker && r->p < r->end && !(r->p[0] == 0xFF && r->p + 1 >= r->end)) {
            byte = *r->p;
            if (byte != 0xFF) {
                r->p++;
            } else if (r->p[1] == 0x00) {
                r->p += 2;
            } else {
                r->marker = r->p[1];
                byte = 0;
            }
        } else if (!r->marker) {
            r->marker = -1;
        }
        if (r->marker) r->pad++;
        r->bits |= byte << (24 - r->nbits);
        r->nbits += 8;
    }
}

static int consumed_padding(const reader *r) { return r->nbits < 8 * r->pad; }

static uint32_t get_bits(reader *r, int n)
{
    if (!n) return 0;
    fill(r);
    const uint32_t v = r->bits >> (32 - n);
    r->bits <<= n;
    r->nbits -= n;
    return v;
}

/* The next Huffman-coded symbol, or -1 for a code no table holds. */
static int decode_symbol(reader *r, const huff *h)
{
    fill(r);
    int32_t code = 0;
    for (int l = 1; l <= 16; l++) {
        code = (code << 1) | (int32_t)(r->bits >> 31);
        r->bits <<= 1;
        r->nbits--;
        if (h->maxcode[l] >= 0 && code <= h->maxcode[l] && code >= h->mincode[l])
            return h->vals[h->valptr[l] + code - h->mincode[l]];
    }
    return -1;
}

/* A restart marker: the bits left in the buffer are the interval's padding;
 * the data resumes after RSTn (which the buffer may or may not have met:
 * either way r->p is at its FF). */
static int restart(reader *r, int expected)
{
    if (r->marker ? r->marker != 0xD0 + expected
                  : !(r->p + 1 < r->end && r->p[0] == 0xFF && r->p[1] == 0xD0 + expected))
        return -1;
    r->p += 2;
    r->marker = 0;
    r->bits = 0;
    r->nbits = 0;
    r->pad = 0;
    return 0;
}

typedef struct frame_info {
    unsigned precision, lines, samples, comp_id;
    unsigned restart_interval;
    huff tables[4];
} frame_info;

static int predict(int sv, int ra, int rb, int rc)
{
    switch (sv) {
    case 1: return ra;
    case 2: return rb;
    case 3: return rc;
    case 4: return ra + rb - rc;
    case 5: return ra + ((rb - rc) >> 1);
    case 6: return rb + ((ra - rc) >> 1);
    default: return (ra + rb) >> 1;
    }
}

/* The scan's samples into out (rows x cols, 16-bit working values). */
static int decode_scan(reader *r, const frame_info *f, const huff *h, int sv, int pt, uint16_t *out, vxl_err *e)
{
    const uint32_t cols = f->samples, rows = f->lines;
    const unsigned mask = 0xFFFFu;
    const int first = 1 << (f->precision - pt - 1);
    uint32_t since_restart = 0;
    int next_rst = 0, line_start = 1; /* the next line is predicted as the first (after SOS or a restart) */
    for (uint32_t y = 0; y < rows; y++) {
        for (uint32_t x = 0; x < cols; x++) {
            if (f->restart_interval && since_restart == f->restart_interval) {
                if (restart(r, next_rst))
                    return BAD("restart marker %d missing at line %u", next_rst, y);
                next_rst = (next_rst + 1) & 7;
                since_restart = 0;
                line_start = 1;
                if (x) return BAD("a restart interval that is not whole lines");
            }
            const int s = decode_symbol(r, h);
            if (s < 0 || s > 16) return BAD("corrupt Huffman data at line %u", y);
            int diff;
            if (s == 16) {
                diff = 32768;
            } else {
                const int v = (int)get_bits(r, s);
                diff = s && v < (1 << (s - 1)) ? v - (1 << s) + 1 : v;
            }
            if (consumed_padding(r))
                return BAD("the data ends at line %u of %u", y, rows);
            int pred;
            uint16_t *row = out + (size_t)y * cols;
            const uint16_t *up = y ? row - cols : row; /* read only after the first line */
            if (line_start) pred = x == 0 ? first : row[x - 1];
            else if (x == 0) pred = up[0];
            else pred = predict(sv, row[x - 1], up[x], up[x - 1]);
            row[x] = (uint16_t)(((unsigned)pred + (unsigned)diff) & mask);
            since_restart++;
        }
        line_start = 0;
    }
    return 0;
}

int vxl_jpeg_lossless_decode(const uint8_t *data, size_t n, uint32_t rows, uint32_t cols, uint32_t bytes_per_pixel,
                             void *dst, vxl_err *e)
{
    if (bytes_per_pixel != 1 && bytes_per_pixel != 2)
        return BAD("%u-byte pixels are not supported", bytes_per_pixel);
    if (n < 4 || data[0] != 0xFF || data[1] != 0xD8) return BAD("no SOI marker");
    frame_info f;
    memset(&f, 0, sizeof f);
    int have_frame = 0;
    size_t i = 2;
    while (i + 4 <= n) {
        if (data[i] != 0xFF) return BAD("no marker at byte %zu", i);
        const int m = data[i + 1];
        if (m == 0xFF) { /* fill byte */
            i++;
            continue;
        }
        const size_t len = be16(data + i + 2);
        if (len < 2 || i + 2 + len > n) return BAD("marker FF%02X runs past the data", m);
        const uint8_t *seg = data + i + 4;
        const size_t sn = len - 2;
        if (m == 0xC3) { /* SOF3: lossless, Huffman */
            if (sn < 9) return BAD("short frame header");
            f.precision = seg[0];
            f.lines = be16(seg + 1);
            f.samples = be16(seg + 3);
            if (seg[5] != 1) return BAD("%u components are not supported (grey only)", seg[5]);
            f.comp_id = seg[6];
            if (f.precision < 2 || f.precision > 16 || f.precision > 8 * bytes_per_pixel)
                return BAD("%u-bit samples in %u-byte pixels", f.precision, bytes_per_pixel);
            if (f.lines != rows || f.samples != cols)
                return BAD("the frame is %ux%u, the file says %ux%u", f.samples, f.lines, cols, rows);
            have_frame = 1;
        } else if (m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC) {
            return BAD("SOF marker FF%02X is not lossless Huffman (process 14)", m);
        } else if (m == 0xC4) { /* DHT */
            size_t k = 0;
            while (k < sn) {
                const unsigned tc = seg[k] >> 4, th = seg[k] & 15;
                if (tc != 0 || th > 3) return BAD("Huffman table class %u id %u", tc, th);
                const size_t used = read_table(seg + k + 1, sn - k - 1, &f.tables[th]);
                if (!used) return BAD("corrupt Huffman table %u", th);
                k += 1 + used;
            }
        } else if (m == 0xDD) { /* DRI */
            if (sn < 2) return BAD("short restart interval");
            f.restart_interval = be16(seg);
        } else if (m == 0xDA) { /* SOS: the scan follows */
            if (!have_frame) return BAD("a scan before the frame header");
            if (sn < 6 || seg[0] != 1) return BAD("a scan of other than one component");
            if (seg[1] != f.comp_id) return BAD("the scan names another component");
            const unsigned td = seg[2] >> 4;
            const int sv = seg[3], pt = seg[5] & 15;
            if (td > 3 || !f.tables[td].defined) return BAD("Huffman table %u is not defined", td);
            if (sv < 1 || sv > 7) return BAD("predictor %d (1 to 7)", sv);
            if ((unsigned)pt >= f.precision) return BAD("point transform %d", pt);
            uint16_t *work = malloc((size_t)rows * cols * sizeof *work);
            if (!work) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for a %ux%u JPEG frame", cols, rows);
            reader r = {data + i + 2 + len, data + n, 0, 0, 0, 0};
            int rc = decode_scan(&r, &f, &f.tables[td], sv, pt, work, e);
            if (!rc) {
                const size_t count = (size_t)rows * cols;
                if (bytes_per_pixel == 2) {
                    uint16_t *d = dst;
                    for (size_t k = 0; k < count; k++) d[k] = (uint16_t)(work[k] << pt);
                } else {
                    uint8_t *d = dst;
                    for (size_t k = 0; k < count; k++) d[k] = (uint8_t)(work[k] << pt);
                }
            }
            free(work);
            return rc;
        }
        i += 2 + len;
    }
    return BAD("no scan");
}
