/* nifti_writer.h - test-side NIfTI-1/NIfTI-2 writer, independent of the
 * library's reader so round-trip tests check the reader against the format
 * rather than against itself.
 *
 * The file form follows the name: ".nii" single file, ".hdr" header + ".img"
 * pair; a trailing ".gz" gzips (each file of a pair). Any byte order: set
 * swap to write the opposite of the host's. Fields are set in a plain
 * struct, and `patch` can overwrite raw header bytes afterwards to build
 * corrupt files. Header only (static functions), needs zlib. */
#ifndef VXL_TEST_NIFTI_WRITER_H
#define VXL_TEST_NIFTI_WRITER_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

typedef struct tnw_header {
    int version;             /* 1 or 2 */
    int swap;                /* 1: opposite of host byte order */
    int datatype, bitpix;
    int64_t dim[8];
    double pixdim[8];
    double vox_offset;       /* 0: 352 / 544 for single files, 0 for pairs */
    double scl_slope, scl_inter;
    int qform_code, sform_code;
    double quatern[3];       /* b, c, d */
    double qoffset[3];
    double srow[3][4];
    /* applied to the built header bytes last; patch_len 0 = none */
    size_t patch_at, patch_len;
    unsigned char patch[16];
} tnw_header;

static size_t tnw_dtype_size(int datatype)
{
    switch (datatype) {
    case 2: case 256: return 1;
    case 4: case 512: return 2;
    case 8: case 768: case 16: return 4;
    case 64: return 8;
    default: return 1;
    }
}

/* A 3D volume nx*ny*nz of datatype, unit spacing, no transforms. */
static void tnw_init(tnw_header *h, int version, int datatype, int64_t nx, int64_t ny, int64_t nz)
{
    memset(h, 0, sizeof *h);
    h->version = version;
    h->datatype = datatype;
    h->bitpix = (int)(8 * tnw_dtype_size(datatype));
    h->dim[0] = 3;
    h->dim[1] = nx;
    h->dim[2] = ny;
    h->dim[3] = nz;
    for (int i = 4; i < 8; i++) h->dim[i] = 1;
    for (int i = 0; i < 8; i++) h->pixdim[i] = 1.0;
    h->scl_slope = 1.0;
}

static void tnw_reverse(unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n / 2; i++) {
        unsigned char t = p[i];
        p[i] = p[n - 1 - i];
        p[n - 1 - i] = t;
    }
}

static void tnw_put(unsigned char *buf, size_t off, const void *v, size_t n, int swap)
{
    memcpy(buf + off, v, n);
    if (swap) tnw_reverse(buf + off, n);
}

static void tnw_i16(unsigned char *b, size_t off, int64_t v, int sw)
{
    int16_t x = (int16_t)v;
    tnw_put(b, off, &x, 2, sw);
}

static void tnw_i32(unsigned char *b, size_t off, int64_t v, int sw)
{
    int32_t x = (int32_t)v;
    tnw_put(b, off, &x, 4, sw);
}

static void tnw_i64(unsigned char *b, size_t off, int64_t v, int sw) { tnw_put(b, off, &v, 8, sw); }

static void tnw_f32(unsigned char *b, size_t off, double v, int sw)
{
    float x = (float)v;
    tnw_put(b, off, &x, 4, sw);
}

static void tnw_f64(unsigned char *b, size_t off, double v, int sw) { tnw_put(b, off, &v, 8, sw); }

static void tnw_build_v1(const tnw_header *h, int pair, double vox_offset, unsigned char *b)
{
    int s = h->swap;
    tnw_i32(b, 0, 348, s);
    for (int i = 0; i < 8; i++) {
        tnw_i16(b, 40 + 2 * (size_t)i, h->dim[i], s);
        tnw_f32(b, 76 + 4 * (size_t)i, h->pixdim[i], s);
    }
    tnw_i16(b, 70, h->datatype, s);
    tnw_i16(b, 72, h->bitpix, s);
    tnw_f32(b, 108, vox_offset, s);
    tnw_f32(b, 112, h->scl_slope, s);
    tnw_f32(b, 116, h->scl_inter, s);
    tnw_i16(b, 252, h->qform_code, s);
    tnw_i16(b, 254, h->sform_code, s);
    for (int i = 0; i < 3; i++) {
        tnw_f32(b, 256 + 4 * (size_t)i, h->quatern[i], s);
        tnw_f32(b, 268 + 4 * (size_t)i, h->qoffset[i], s);
        for (int j = 0; j < 4; j++) tnw_f32(b, 280 + 16 * (size_t)i + 4 * (size_t)j, h->srow[i][j], s);
    }
    memcpy(b + 344, pair ? "ni1\0" : "n+1\0", 4);
}

static void tnw_build_v2(const tnw_header *h, int pair, double vox_offset, unsigned char *b)
{
    int s = h->swap;
    tnw_i32(b, 0, 540, s);
    memcpy(b + 4, pair ? "ni2\0\r\n\032\n" : "n+2\0\r\n\032\n", 8);
    tnw_i16(b, 12, h->datatype, s);
    tnw_i16(b, 14, h->bitpix, s);
    for (int i = 0; i < 8; i++) {
        tnw_i64(b, 16 + 8 * (size_t)i, h->dim[i], s);
        tnw_f64(b, 104 + 8 * (size_t)i, h->pixdim[i], s);
    }
    /* NIfTI-2 stores vox_offset as int64; clamp so a test can ask for "huge" */
    int64_t off = vox_offset >= 9.2e18 ? INT64_MAX : (int64_t)vox_offset;
    tnw_i64(b, 168, off, s);
    tnw_f64(b, 176, h->scl_slope, s);
    tnw_f64(b, 184, h->scl_inter, s);
    tnw_i32(b, 344, h->qform_code, s);
    tnw_i32(b, 348, h->sform_code, s);
    for (int i = 0; i < 3; i++) {
        tnw_f64(b, 352 + 8 * (size_t)i, h->quatern[i], s);
        tnw_f64(b, 376 + 8 * (size_t)i, h->qoffset[i], s);
        for (int j = 0; j < 4; j++) tnw_f64(b, 400 + 32 * (size_t)i + 8 * (size_t)j, h->srow[i][j], s);
    }
}

static int tnw_ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcmp(s + n - m, suffix) == 0;
}

/* Writes bytes to path, gzipped or not ("T" = zlib's transparent mode). */
static int tnw_write_file(const char *path, int gz, const void *a, size_t na, const void *b, size_t nb)
{
    gzFile f = gzopen(path, gz ? "wb" : "wbT");
    if (!f) return -1;
    int ok = (na == 0 || gzwrite(f, a, (unsigned)na) == (int)na) &&
             (nb == 0 || gzwrite(f, b, (unsigned)nb) == (int)nb);
    return (gzclose(f) == Z_OK && ok) ? 0 : -1;
}

/* data: native byte order, data_bytes of it (may be short, to truncate). */
static int tnw_write(const char *path, const tnw_header *h, const void *data, size_t data_bytes)
{
    int gz = tnw_ends_with(path, ".gz");
    int pair = tnw_ends_with(path, ".hdr") || tnw_ends_with(path, ".hdr.gz");
    size_t hsize = h->version == 1 ? 348 : 540;
    double off = h->vox_offset != 0 ? h->vox_offset : pair ? 0 : (double)hsize + 4;

    /* Header (+ extension flag + padding up to vox_offset for single files,
     * unless the offset is deliberately absurd). */
    size_t pre = pair ? hsize : hsize + 4;
    size_t pad_to = (off > (double)pre && off < (double)(1u << 20)) ? (size_t)off : pre;
    unsigned char *head = calloc(1, pad_to);
    unsigned char *body = malloc(data_bytes ? data_bytes : 1);
    if (!head || !body) {
        free(head);
        free(body);
        return -1;
    }
    if (h->version == 1) tnw_build_v1(h, pair, off, head);
    else tnw_build_v2(h, pair, off, head);
    if (h->patch_len) memcpy(head + h->patch_at, h->patch, h->patch_len);

    if (data_bytes) memcpy(body, data, data_bytes);
    size_t es = tnw_dtype_size(h->datatype);
    for (size_t i = 0; h->swap && es > 1 && i + es <= data_bytes; i += es)
        tnw_reverse(body + i, es);

    int rc;
    if (!pair) {
        rc = tnw_write_file(path, gz, head, pad_to, body, data_bytes);
    } else {
        size_t n = strlen(path);
        char *img = malloc(n + 1);
        rc = -1;
        if (img) {
            memcpy(img, path, n + 1);
            memcpy(img + n - (gz ? 7 : 4), ".img", 4); /* .hdr[.gz] -> .img[.gz] */
            /* the .img starts with vox_offset bytes of padding, if any */
            size_t img_pad = (off > 0 && off < (double)(1u << 20)) ? (size_t)off : 0;
            unsigned char *zeros = calloc(1, img_pad ? img_pad : 1);
            if (zeros && tnw_write_file(path, gz, head, hsize, NULL, 0) == 0)
                rc = tnw_write_file(img, gz, zeros, img_pad, body, data_bytes);
            free(zeros);
            free(img);
        }
    }
    free(head);
    free(body);
    return rc;
}

#endif
