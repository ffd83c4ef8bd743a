/* dicom_writer.h - writes small DICOM Part 10 files (explicit VR little
 * endian, or a declared compressed syntax with encapsulated pixel data) for
 * the tests and the fuzz seeds. Written from the standard (PS3.5, PS3.10),
 * independently of dcmtk, which the reader uses. Header-only, C11. */
#ifndef VXL_DICOM_WRITER_H
#define VXL_DICOM_WRITER_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DCMW_EXPLICIT_LE "1.2.840.10008.1.2.1"
#define DCMW_JPEG_BASELINE "1.2.840.10008.1.2.4.50"

typedef struct dcmw_slice {
    const char *series_uid;       /* required */
    const char *modality;         /* NULL = "CT" */
    const char *description;      /* NULL = none */
    const char *transfer_syntax;  /* NULL = explicit VR little endian */
    uint16_t rows, cols;
    uint16_t bits_alloc;          /* 8 or 16 */
    uint16_t bits_stored;         /* 0 = bits_alloc */
    uint16_t pixel_rep;           /* 1 = signed */
    uint32_t frames;              /* 0 = no NumberOfFrames element */
    int instance;
    int temporal_position;        /* 0 = no TemporalPositionIdentifier (4D series: 1, 2, ...) */
    int no_geometry;              /* 1: no ImagePositionPatient/ImageOrientationPatient */
    double ipp[3], iop[6], ps[2]; /* ps: row spacing, column spacing */
    int has_rescale;
    double slope, inter;
    const void *pixels;           /* rows*cols*bits_alloc/8 bytes, little endian */
    size_t pixel_bytes;           /* may be less, to write a truncated element */
} dcmw_slice;

typedef struct dcmw_buf {
    unsigned char *p;
    size_t n, cap;
    int overflow;
} dcmw_buf;

static void dcmw_put(dcmw_buf *b, const void *d, size_t n)
{
    if (b->n + n > b->cap) { b->overflow = 1; return; }
    memcpy(b->p + b->n, d, n);
    b->n += n;
}

static void dcmw_u16(dcmw_buf *b, uint16_t v)
{
    unsigned char x[2] = {(unsigned char)v, (unsigned char)(v >> 8)};
    dcmw_put(b, x, 2);
}

static void dcmw_u32(dcmw_buf *b, uint32_t v)
{
    unsigned char x[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16), (unsigned char)(v >> 24)};
    dcmw_put(b, x, 4);
}

/* One explicit-VR element; values of odd length are padded (UI with NUL,
 * text with a space, binary with 0) as PS3.5 requires. */
static void dcmw_elem(dcmw_buf *b, uint16_t g, uint16_t e, const char vr[2], const void *val, uint32_t len)
{
    int long_form = !memcmp(vr, "OB", 2) || !memcmp(vr, "OW", 2) || !memcmp(vr, "UN", 2) || !memcmp(vr, "SQ", 2);
    uint32_t padded = len + (len & 1);
    dcmw_u16(b, g);
    dcmw_u16(b, e);
    dcmw_put(b, vr, 2);
    if (long_form) { dcmw_u16(b, 0); dcmw_u32(b, padded); }
    else dcmw_u16(b, (uint16_t)padded);
    dcmw_put(b, val, len);
    if (len & 1) {
        unsigned char pad = (!memcmp(vr, "UI", 2) || long_form) ? 0 : ' ';
        dcmw_put(b, &pad, 1);
    }
}

static void dcmw_str(dcmw_buf *b, uint16_t g, uint16_t e, const char vr[2], const char *s)
{
    dcmw_elem(b, g, e, vr, s, (uint32_t)strlen(s));
}

static void dcmw_us(dcmw_buf *b, uint16_t g, uint16_t e, uint16_t v)
{
    unsigned char x[2] = {(unsigned char)v, (unsigned char)(v >> 8)};
    dcmw_elem(b, g, e, "US", x, 2);
}

/* Decimal strings, backslash-separated. */
static void dcmw_ds(dcmw_buf *b, uint16_t g, uint16_t e, const double *v, int n)
{
    char s[256];
    size_t k = 0;
    for (int i = 0; i < n && k < sizeof s - 20; i++)
        k += (size_t)snprintf(s + k, sizeof s - k, "%s%.10g", i ? "\\" : "", v[i]);
    dcmw_elem(b, g, e, "DS", s, (uint32_t)k);
}

/* Serialises the slice into buf (cap bytes); returns its size, 0 if cap is short. */
static size_t dcmw_encode(const dcmw_slice *d, unsigned char *buf, size_t cap)
{
    const char *ts = d->transfer_syntax ? d->transfer_syntax : DCMW_EXPLICIT_LE;
    const char *sop_class = "1.2.840.10008.5.1.4.1.1.2"; /* CT Image Storage */
    char sop_uid[96];
    snprintf(sop_uid, sizeof sop_uid, "%s.%d", d->series_uid, d->instance + 1);
    dcmw_buf b = {buf, 0, cap, 0};
    static const unsigned char zero[128];
    dcmw_put(&b, zero, 128);
    dcmw_put(&b, "DICM", 4);
    /* File meta group: its length element counts what follows it. */
    unsigned char meta[512];
    dcmw_buf m = {meta, 0, sizeof meta, 0};
    static const unsigned char version[2] = {0, 1};
    dcmw_elem(&m, 0x0002, 0x0001, "OB", version, 2);
    dcmw_str(&m, 0x0002, 0x0002, "UI", sop_class);
    dcmw_str(&m, 0x0002, 0x0003, "UI", sop_uid);
    dcmw_str(&m, 0x0002, 0x0010, "UI", ts);
    unsigned char gl[4] = {(unsigned char)m.n, (unsigned char)(m.n >> 8), 0, 0};
    dcmw_elem(&b, 0x0002, 0x0000, "UL", gl, 4);
    dcmw_put(&b, meta, m.n);
    /* Data set, tags ascending. */
    dcmw_str(&b, 0x0008, 0x0016, "UI", sop_class);
    dcmw_str(&b, 0x0008, 0x0018, "UI", sop_uid);
    dcmw_str(&b, 0x0008, 0x0060, "CS", d->modality ? d->modality : "CT");
    if (d->description) dcmw_str(&b, 0x0008, 0x103E, "LO", d->description);
    dcmw_str(&b, 0x0020, 0x000D, "UI", "1.2.826.0.1.3680043.9.7777.1");
    dcmw_str(&b, 0x0020, 0x000E, "UI", d->series_uid);
    char inst[16];
    snprintf(inst, sizeof inst, "%d", d->instance + 1);
    dcmw_str(&b, 0x0020, 0x0013, "IS", inst);
    if (!d->no_geometry) {
        dcmw_ds(&b, 0x0020, 0x0032, d->ipp, 3);
        dcmw_ds(&b, 0x0020, 0x0037, d->iop, 6);
    }
    if (d->temporal_position) {
        char tp[16];
        snprintf(tp, sizeof tp, "%d", d->temporal_position);
        dcmw_str(&b, 0x0020, 0x0100, "IS", tp);
    }
    dcmw_us(&b, 0x0028, 0x0002, 1);
    dcmw_str(&b, 0x0028, 0x0004, "CS", "MONOCHROME2");
    if (d->frames) {
        char fr[16];
        snprintf(fr, sizeof fr, "%u", d->frames);
        dcmw_str(&b, 0x0028, 0x0008, "IS", fr);
    }
    dcmw_us(&b, 0x0028, 0x0010, d->rows);
    dcmw_us(&b, 0x0028, 0x0011, d->cols);
    dcmw_ds(&b, 0x0028, 0x0030, d->ps, 2);
    uint16_t stored = d->bits_stored ? d->bits_stored : d->bits_alloc;
    dcmw_us(&b, 0x0028, 0x0100, d->bits_alloc);
    dcmw_us(&b, 0x0028, 0x0101, stored);
    dcmw_us(&b, 0x0028, 0x0102, (uint16_t)(stored - 1));
    dcmw_us(&b, 0x0028, 0x0103, d->pixel_rep);
    if (d->has_rescale) {
        dcmw_ds(&b, 0x0028, 0x1052, &d->inter, 1);
        dcmw_ds(&b, 0x0028, 0x1053, &d->slope, 1);
    }
    if (strcmp(ts, DCMW_EXPLICIT_LE) != 0) {
        /* encapsulated: undefined length, empty offset table, one fragment */
        dcmw_u16(&b, 0x7FE0); dcmw_u16(&b, 0x0010); dcmw_put(&b, "OB", 2); dcmw_u16(&b, 0); dcmw_u32(&b, 0xFFFFFFFFu);
        dcmw_u16(&b, 0xFFFE); dcmw_u16(&b, 0xE000); dcmw_u32(&b, 0);
        uint32_t fl = (uint32_t)(d->pixel_bytes + (d->pixel_bytes & 1));
        dcmw_u16(&b, 0xFFFE); dcmw_u16(&b, 0xE000); dcmw_u32(&b, fl);
        dcmw_put(&b, d->pixels, d->pixel_bytes);
        if (d->pixel_bytes & 1) dcmw_put(&b, zero, 1);
        dcmw_u16(&b, 0xFFFE); dcmw_u16(&b, 0xE0DD); dcmw_u32(&b, 0);
    } else {
        dcmw_elem(&b, 0x7FE0, 0x0010, d->bits_alloc == 8 ? "OB" : "OW", d->pixels, (uint32_t)d->pixel_bytes);
    }
    return b.overflow ? 0 : b.n;
}

/* Writes the slice to path; 0 on success. */
static int dcmw_write(const char *path, const dcmw_slice *d)
{
    size_t cap = 4096 + d->pixel_bytes;
    unsigned char *buf = (unsigned char *)malloc(cap);
    if (!buf) return -1;
    size_t n = dcmw_encode(d, buf, cap);
    int rc = -1;
    FILE *f = n ? fopen(path, "wb") : NULL;
    if (f) {
        rc = fwrite(buf, 1, n, f) == n ? 0 : -1;
        if (fclose(f)) rc = -1;
    }
    free(buf);
    return rc;
}

/* Axial defaults: identity orientation, 1 mm pixels. */
static dcmw_slice dcmw_axial(const char *uid, uint16_t cols, uint16_t rows, double z, const void *px, size_t bytes)
{
    dcmw_slice d;
    memset(&d, 0, sizeof d);
    d.series_uid = uid;
    d.rows = rows;
    d.cols = cols;
    d.bits_alloc = 16;
    d.ipp[2] = z;
    d.iop[0] = 1;
    d.iop[4] = 1;
    d.ps[0] = d.ps[1] = 1;
    d.pixels = px;
    d.pixel_bytes = bytes;
    return d;
}

#endif
