/* nifti.c - NIfTI-1 / NIfTI-2 reader (.nii, .nii.gz, .hdr/.img[.gz]).
 *
 * Our own reader instead of libnifti: we need one 3D volume at a time, want
 * every header field treated as hostile input, and want failures reported
 * through vxl_fail rather than printed. gz_reader.h reads plain and gzip
 * files alike, so one code path serves both.
 *
 * Flow: find the header file -> read and parse the header into a
 * version-neutral struct -> validate it -> read the chosen volume's raw bytes (frame option, 4D)
 * (from the same file at vox_offset, or from the paired .img) -> swap if the
 * file's byte order is foreign -> hand over to vxl_volume_build, which owns
 * scaling, NaN handling and normalisation. */
#include "hash.h"
#include "files.h"
#include "loader_util.h"
#include "loaders.h"
#include "stream_load.h"
#include "gz_reader.h"
#include "channel_volume.h"
#include "colour_volume.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define NII1_HDR_SIZE 348
#define NII2_HDR_SIZE 540
/* Single-file data may not start before the header plus the 4-byte
 * extension flag. */
#define NII1_MIN_OFFSET 352
#define NII2_MIN_OFFSET 544
/* Extensions (e.g. CIFTI XML) can be megabytes, never anywhere near this;
 * a larger vox_offset is a corrupt header, not a real file. */
#define MAX_VOX_OFFSET (1ull << 30)
#define GZ_BUFFER (256u * 1024u)

/* A 3x4 affine, row-major as NIfTI writes srow_x/y/z. A struct so it can be
 * passed as const without C11's array-qualifier pitfalls. */
typedef struct mat34 {
    double m[3][4];
} mat34;

/* The header fields we use, widened to the NIfTI-2 types so one validation
 * and one affine path serve both versions. */
typedef struct nii_header {
    int version;        /* 1 or 2 */
    int swapped;        /* file byte order differs from ours */
    int paired;         /* "ni1"/"ni2": voxels live in a separate .img */
    int datatype;
    int64_t dim[8];
    double pixdim[8];
    double vox_offset;  /* float in NIfTI-1, so kept as double until checked */
    double scl_slope, scl_inter;
    int qform_code, sform_code;
    int intent_code;
    double quatern[3];  /* b, c, d */
    double qoffset[3];
    mat34 srow;
} nii_header;

/* ------------------------------------------------------------ byte access */

/* Byte order is detected from sizeof_hdr, so we never need to know the
 * host's order: "swapped" just means "reverse every multi-byte field". */
static void swap_bytes(unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n / 2; i++) {
        unsigned char t = p[i];
        p[i] = p[n - 1 - i];
        p[n - 1 - i] = t;
    }
}

static void get_field(void *dst, const unsigned char *buf, size_t off, size_t n, int swapped)
{
    memcpy(dst, buf + off, n);
    if (swapped) swap_bytes(dst, n);
}

static int64_t get_i16(const unsigned char *b, size_t off, int sw)
{
    int16_t v;
    get_field(&v, b, off, sizeof v, sw);
    return v;
}

static int64_t get_i32(const unsigned char *b, size_t off, int sw)
{
    int32_t v;
    get_field(&v, b, off, sizeof v, sw);
    return v;
}

static int64_t get_i64(const unsigned char *b, size_t off, int sw)
{
    int64_t v;
    get_field(&v, b, off, sizeof v, sw);
    return v;
}

static double get_f32(const unsigned char *b, size_t off, int sw)
{
    float v;
    get_field(&v, b, off, sizeof v, sw);
    return v;
}

static double get_f64(const unsigned char *b, size_t off, int sw)
{
    double v;
    get_field(&v, b, off, sizeof v, sw);
    return v;
}

/* Swaps every element of a voxel buffer in place. */
static void swap_voxels(unsigned char *p, uint64_t count, size_t elem)
{
    if (elem < 2) return;
    for (uint64_t i = 0; i < count; i++) swap_bytes(p + i * elem, elem);
}

/* ----------------------------------------------------------------- paths */

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* Returns a malloc'd copy of path with its trailing `from` replaced by `to`,
 * or NULL when path does not end in `from` or memory is short. */
static char *replace_suffix(const char *path, const char *from, const char *to)
{
    if (!ends_with(path, from)) return NULL;
    size_t stem = strlen(path) - strlen(from);
    char *s = malloc(stem + strlen(to) + 1);
    if (!s) return NULL;
    memcpy(s, path, stem);
    strcpy(s + stem, to);
    return s;
}

static int file_exists(const char *path)
{
    vxl_path_info st;
    return vxl_path_stat(path, &st) == 0;
}

/* Given ".img[.gz]", the header is the matching ".hdr", preferring the same
 * compression but accepting the other (some tools gzip only the image).
 * Returns a malloc'd path (the input itself when it is not an .img) or NULL
 * when memory is short. */
static char *header_path_for(const char *path)
{
    static const char *const pairs[][2] = {
        {".img.gz", ".hdr.gz"}, {".img.gz", ".hdr"}, {".img", ".hdr"}, {".img", ".hdr.gz"},
    };
    int is_img = ends_with(path, ".img") || ends_with(path, ".img.gz");
    for (size_t i = 0; is_img && i < sizeof pairs / sizeof pairs[0]; i++) {
        char *cand = replace_suffix(path, pairs[i][0], pairs[i][1]);
        if (cand && file_exists(cand)) return cand;
        free(cand);
    }
    /* Not an .img, or no header found: open the path itself, whose error
     * (or lack of a NIfTI magic) then tells the user what is wrong. When an
     * .img has no header, name the header we looked for. */
    if (is_img) {
        char *want = replace_suffix(path, ends_with(path, ".gz") ? ".img.gz" : ".img",
                                    ends_with(path, ".gz") ? ".hdr.gz" : ".hdr");
        if (want) return want;
    }
    size_t n = strlen(path) + 1;
    char *s = malloc(n);
    if (s) memcpy(s, path, n);
    return s;
}

/* The .img that goes with a .hdr[.gz]; same preference order as above. */
static char *image_path_for(const char *hdr_path)
{
    static const char *const pairs[][2] = {
        {".hdr.gz", ".img.gz"}, {".hdr.gz", ".img"}, {".hdr", ".img"}, {".hdr", ".img.gz"},
    };
    char *first = NULL;
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++) {
        char *cand = replace_suffix(hdr_path, pairs[i][0], pairs[i][1]);
        if (!cand) continue;
        if (file_exists(cand)) {
            free(first);
            return cand;
        }
        if (!first) first = cand; /* reported as missing if nothing exists */
        else free(cand);
    }
    return first;
}

/* ------------------------------------------------------------------- I/O */

static vxl_gz *open_gz(const char *path, vxl_err *e)
{
    return vxl_gz_open(path, GZ_BUFFER, e); /* large: fewer reads of the file */
}

/* Reads up to n bytes; *got says how many arrived. Returns VXL_OK at EOF too
 * (the caller judges a short count), or an error for a broken stream. */
static int read_bytes(vxl_gz *f, void *buf, uint64_t n, uint64_t *got, vxl_err *e)
{
    size_t have = 0;
    int rc = vxl_gz_read(f, buf, (size_t)n, &have, e);
    *got = have;
    return rc;
}

/* ---------------------------------------------------------------- header */

static void parse_nifti1(const unsigned char *b, int sw, nii_header *h)
{
    h->version = 1;
    for (int i = 0; i < 8; i++) {
        h->dim[i] = get_i16(b, 40 + 2 * (size_t)i, sw);
        h->pixdim[i] = get_f32(b, 76 + 4 * (size_t)i, sw);
    }
    h->datatype = (int)get_i16(b, 70, sw);
    h->vox_offset = get_f32(b, 108, sw);
    h->scl_slope = get_f32(b, 112, sw);
    h->scl_inter = get_f32(b, 116, sw);
    h->qform_code = (int)get_i16(b, 252, sw);
    h->sform_code = (int)get_i16(b, 254, sw);
    h->intent_code = (int)get_i16(b, 68, sw);
    for (int i = 0; i < 3; i++) {
        h->quatern[i] = get_f32(b, 256 + 4 * (size_t)i, sw);
        h->qoffset[i] = get_f32(b, 268 + 4 * (size_t)i, sw);
        for (int j = 0; j < 4; j++) h->srow.m[i][j] = get_f32(b, 280 + 16 * (size_t)i + 4 * (size_t)j, sw);
    }
}

static void parse_nifti2(const unsigned char *b, int sw, nii_header *h)
{
    h->version = 2;
    for (int i = 0; i < 8; i++) {
        h->dim[i] = get_i64(b, 16 + 8 * (size_t)i, sw);
        h->pixdim[i] = get_f64(b, 104 + 8 * (size_t)i, sw);
    }
    h->datatype = (int)get_i16(b, 12, sw);
    /* int64 in the file; any value beyond 2^53 is rejected as absurd anyway,
     * so the conversion to double cannot hide a valid offset. */
    h->vox_offset = (double)get_i64(b, 168, sw);
    h->scl_slope = get_f64(b, 176, sw);
    h->scl_inter = get_f64(b, 184, sw);
    h->qform_code = (int)get_i32(b, 344, sw);
    h->sform_code = (int)get_i32(b, 348, sw);
    h->intent_code = (int)get_i32(b, 504, sw);
    for (int i = 0; i < 3; i++) {
        h->quatern[i] = get_f64(b, 352 + 8 * (size_t)i, sw);
        h->qoffset[i] = get_f64(b, 376 + 8 * (size_t)i, sw);
        for (int j = 0; j < 4; j++) h->srow.m[i][j] = get_f64(b, 400 + 32 * (size_t)i + 8 * (size_t)j, sw);
    }
}

/* sizeof_hdr is the byte-order mark: 348/540 read natively or swapped. */
static int detect_version(const unsigned char *b, int *version, int *swapped)
{
    int32_t native, foreign;
    memcpy(&native, b, 4);
    foreign = native;
    swap_bytes((unsigned char *)&foreign, 4);
    *swapped = 0;
    if (native == NII1_HDR_SIZE || native == NII2_HDR_SIZE) {
        *version = native == NII1_HDR_SIZE ? 1 : 2;
        return 1;
    }
    if (foreign == NII1_HDR_SIZE || foreign == NII2_HDR_SIZE) {
        *version = foreign == NII1_HDR_SIZE ? 1 : 2;
        *swapped = 1;
        return 1;
    }
    return 0;
}

/* Sets h->paired from the magic, or fails: without a valid magic a 348-byte
 * header is Analyze 7.5, whose orientation rules we do not implement. */
static int check_magic(const unsigned char *b, nii_header *h, const char *path, vxl_err *e)
{
    if (h->version == 1) {
        const unsigned char *m = b + 344;
        if (memcmp(m, "n+1\0", 4) == 0 || memcmp(m, "ni1\0", 4) == 0) {
            h->paired = m[1] == 'i';
            return VXL_OK;
        }
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s': bad NIfTI-1 magic (expected \"n+1\" or \"ni1\"; an Analyze 7.5 "
                        "header or a corrupt file?)", path);
    }
    /* The 4 bytes after "n+2\0" (\r\n\032\n) exist to detect text-mode
     * transfer damage, so they are checked too. */
    const unsigned char *m = b + 4;
    if ((memcmp(m, "n+2\0", 4) == 0 || memcmp(m, "ni2\0", 4) == 0) &&
        memcmp(m + 4, "\r\n\032\n", 4) == 0) {
        h->paired = m[1] == 'i';
        return VXL_OK;
    }
    return vxl_fail(e, VXL_ERR_FORMAT,
                    "'%s': bad NIfTI-2 magic (expected \"n+2\" or \"ni2\" followed by \\r\\n\\032\\n; "
                    "corrupt or damaged by a text-mode transfer?)", path);
}

/* Reads and parses the header from f (positioned at 0). */
static int read_header(vxl_gz *f, const char *path, nii_header *h, vxl_err *e)
{
    unsigned char b[NII2_HDR_SIZE];
    uint64_t got;
    int rc = read_bytes(f, b, NII1_HDR_SIZE, &got, e);
    if (rc) return rc;
    if (got < 4 || !detect_version(b, &h->version, &h->swapped)) {
        if (got < 4)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s' is not a NIfTI file: only %llu bytes long", path,
                            (unsigned long long)got);
        int32_t s;
        memcpy(&s, b, 4);
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s' is not a NIfTI file: sizeof_hdr is %d, expected 348 or 540 (either "
                        "byte order)", path, (int)s);
    }
    size_t want = h->version == 1 ? NII1_HDR_SIZE : NII2_HDR_SIZE;
    if (got == NII1_HDR_SIZE && want > got) {
        uint64_t more;
        rc = read_bytes(f, b + got, want - got, &more, e);
        if (rc) return rc;
        got += more;
    }
    if (got < want)
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s': truncated header: expected %zu bytes, got %llu", path, want,
                        (unsigned long long)got);
    if (h->version == 1) parse_nifti1(b, h->swapped, h);
    else parse_nifti2(b, h->swapped, h);
    return check_magic(b, h, path, e);
}

/* ------------------------------------------------------------ validation */

static const char *datatype_name(int code)
{
    switch (code) {
    case 0: return "UNKNOWN";
    case 1: return "BINARY";
    case 2: return "UINT8";
    case 4: return "INT16";
    case 8: return "INT32";
    case 16: return "FLOAT32";
    case 32: return "COMPLEX64";
    case 64: return "FLOAT64";
    case 128: return "RGB24";
    case 256: return "INT8";
    case 512: return "UINT16";
    case 768: return "UINT32";
    case 1024: return "INT64";
    case 1280: return "UINT64";
    case 1536: return "FLOAT128";
    case 1792: return "COMPLEX128";
    case 2048: return "COMPLEX256";
    case 2304: return "RGBA32";
    default: return "not a NIfTI datatype";
    }
}

static uint32_t vxl_dtype_from_nifti(int code)
{
    switch (code) {
    case 2: return VXL_DTYPE_U8;
    case 256: return VXL_DTYPE_I8;
    case 4: return VXL_DTYPE_I16;
    case 512: return VXL_DTYPE_U16;
    case 8: return VXL_DTYPE_I32;
    case 768: return VXL_DTYPE_U32;
    case 16: return VXL_DTYPE_F32;
    case 64: return VXL_DTYPE_F64;
    default: return 0;
    }
}

/* Checks dim[] and fills the 3D grid. Axes past dim[0] are absent (= 1);
 * axes 4..7 must still be positive (they count the volumes of a 4D file). */
static int check_dims(const nii_header *h, uint32_t dims[3], const char *path, vxl_err *e)
{
    int64_t nd = h->dim[0];
    if (nd < 1 || nd > 7)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': bad dimensions: dim[0] is %lld, must be 1..7", path,
                        (long long)nd);
    for (int a = 1; a <= nd; a++) {
        if (h->dim[a] < 1)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': bad dimensions: dim[%d] is %lld, must be >= 1",
                            path, a, (long long)h->dim[a]);
    }
    for (int a = 0; a < 3; a++) {
        int64_t d = a + 1 <= nd ? h->dim[a + 1] : 1;
        if (d > (int64_t)UINT32_MAX)
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s': dim[%d] = %lld exceeds the per-axis limit", path,
                            a + 1, (long long)d);
        dims[a] = (uint32_t)d;
    }
    return VXL_OK;
}

/* vox_offset must be a whole, sane byte offset; for single files it must
 * also clear the header and extension flag. */
static int check_vox_offset(const nii_header *h, uint64_t *offset, const char *path, vxl_err *e)
{
    double v = h->vox_offset;
    if (!isfinite(v) || v < 0 || v != floor(v))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': bad vox_offset %g: must be a whole number >= 0", path,
                        v);
    if (v > (double)MAX_VOX_OFFSET)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': absurd vox_offset %.0f (more than %llu bytes of "
                        "header)", path, v, (unsigned long long)MAX_VOX_OFFSET);
    uint64_t min = h->paired ? 0 : h->version == 1 ? NII1_MIN_OFFSET : NII2_MIN_OFFSET;
    if ((uint64_t)v < min)
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s': vox_offset %.0f is inside the header (must be >= %llu)", path, v,
                        (unsigned long long)min);
    *offset = (uint64_t)v;
    return VXL_OK;
}

/* ---------------------------------------------------------------- geometry */

/* pixdim[1..3] as voxel size: the sign carries no meaning there (qfac lives
 * in pixdim[0]), and 0 / non-finite means "unknown", i.e. 1 mm. */
static void spacing_from(const nii_header *h, double sp[3])
{
    for (int a = 0; a < 3; a++) {
        double p = fabs(h->pixdim[a + 1]);
        sp[a] = (isfinite(p) && p > 0) ? p : 1.0;
    }
}

static void set_colmajor(double A[16], const mat34 *M)
{
    memset(A, 0, 16 * sizeof *A);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) A[c * 4 + r] = M->m[r][c];
    A[15] = 1.0;
}

/* A transform is usable when finite and invertible: writers that set a code
 * but leave the rows zero do exist, and we would rather fall back to the
 * next source than render a flat volume. */
static int usable(const mat34 *T)
{
    const double (*M)[4] = T->m;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            if (!isfinite(M[r][c])) return 0;
    double det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                 M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                 M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
    return isfinite(det) && det != 0.0;
}

/* nifti1.h "METHOD 2": R from the unit quaternion (a,b,c,d), columns scaled
 * by the voxel size, the third negated when qfac < 0, offsets appended.
 * Mirrors quatern_to_mat44 from nifti1_io.c, except that the voxel size is
 * our cleaned spacing (|pixdim|, 0 -> 1) instead of "<= 0 -> 1". */
static int qform_matrix(const nii_header *h, const double sp[3], mat34 *Q)
{
    double (*M)[4] = Q->m;
    double b = h->quatern[0], c = h->quatern[1], d = h->quatern[2];
    double n2 = b * b + c * c + d * d;
    if (!isfinite(n2)) return 0;
    double a = 1.0 - n2;
    if (a < 1e-7) { /* |(b,c,d)| ~ 1: a 180 degree rotation; renormalise */
        double s = 1.0 / sqrt(n2);
        b *= s; c *= s; d *= s;
        a = 0.0;
    } else {
        a = sqrt(a);
    }
    double xd = sp[0], yd = sp[1], zd = sp[2];
    if (h->pixdim[0] < 0) zd = -zd; /* qfac: left-handed voxel grid */
    M[0][0] = (a * a + b * b - c * c - d * d) * xd;
    M[0][1] = 2.0 * (b * c - a * d) * yd;
    M[0][2] = 2.0 * (b * d + a * c) * zd;
    M[1][0] = 2.0 * (b * c + a * d) * xd;
    M[1][1] = (a * a + c * c - b * b - d * d) * yd;
    M[1][2] = 2.0 * (c * d - a * b) * zd;
    M[2][0] = 2.0 * (b * d - a * c) * xd;
    M[2][1] = 2.0 * (c * d + a * b) * yd;
    M[2][2] = (a * a + d * d - c * c - b * b) * zd;
    for (int r = 0; r < 3; r++) M[r][3] = h->qoffset[r];
    return usable(Q);
}

/* Picks sform, then qform, then diag(spacing), as the standard orders them.
 * Returns the affine_source code (2, 1, 0). */
static uint32_t choose_affine(const nii_header *h, const double sp[3], double A[16])
{
    mat34 M;
    if (h->sform_code > 0 && usable(&h->srow)) {
        set_colmajor(A, &h->srow);
        return 2;
    }
    if (h->qform_code > 0 && qform_matrix(h, sp, &M)) {
        set_colmajor(A, &M);
        return 1;
    }
    memset(&M, 0, sizeof M);
    for (int a = 0; a < 3; a++) M.m[a][a] = sp[a];
    set_colmajor(A, &M);
    return 0;
}

/* --------------------------------------------------------------- voxels */

/* For an uncompressed file the size is known up front: report truncation
 * before allocating a buffer a hostile header may have sized. */
static int precheck_size(vxl_gz *f, const char *path, uint64_t offset, uint64_t nbytes, vxl_err *e)
{
    vxl_path_info st;
    if (!vxl_gz_direct(f) || vxl_path_stat(path, &st) != 0) return VXL_OK;
    uint64_t size = st.size;
    uint64_t have = size > offset ? size - offset : 0;
    if (have < nbytes)
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s': truncated file: expected %llu bytes of voxel data at offset %llu, "
                        "got %llu", path, (unsigned long long)nbytes, (unsigned long long)offset,
                        (unsigned long long)have);
    return VXL_OK;
}

/* Reads one volume's nbytes at offset into a new buffer. */
static int read_voxels(vxl_gz *f, const char *path, uint64_t offset, uint64_t nbytes, void **out,
                       vxl_err *e)
{
    *out = NULL;
    int rc = precheck_size(f, path, offset, nbytes, e);
    if (rc) return rc;
    /* on gzip streams the reader inflates and discards up to offset; a seek
     * past the end shows up as a short read below */
    rc = vxl_gz_seek(f, offset, e);
    if (rc) return rc;
    void *buf = malloc((size_t)nbytes);
    if (!buf)
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for %llu bytes of voxel data", path,
                        (unsigned long long)nbytes);
    uint64_t got;
    rc = read_bytes(f, buf, nbytes, &got, e);
    if (!rc && got < nbytes)
        rc = vxl_fail(e, VXL_ERR_FORMAT,
                      "'%s': truncated file: expected %llu bytes of voxel data, got %llu", path,
                      (unsigned long long)nbytes, (unsigned long long)got);
    if (rc) {
        free(buf);
        return rc;
    }
    *out = buf;
    return VXL_OK;
}

/* Re-raises an error from a helper that does not know the file name, keeping
 * its code, so the message says which file was at fault. */
static int fail_with_path(vxl_err *e, const char *path, const vxl_err *inner)
{
    return vxl_fail(e, inner->code, "'%s': %s", path, inner->msg);
}

/* ------------------------------------------------------------------ load */

typedef struct nii_load {
    const char *path;    /* as given by the caller */
    char *hdr_path;
    char *img_path;      /* paired files only */
    vxl_gz *hdr_file, *img_file;
    void *raw;
} nii_load;

static void load_cleanup(nii_load *L)
{
    if (L->img_file) vxl_gz_close(L->img_file);
    if (L->hdr_file) vxl_gz_close(L->hdr_file);
    free(L->raw);
    free(L->img_path);
    free(L->hdr_path);
}

/* Opens the header, reads it, and opens the file holding the voxels.
 * On success data and data_path name that file. */
static int open_files(nii_load *L, nii_header *h, vxl_gz **data, const char **data_path, vxl_err *e)
{
    L->hdr_path = header_path_for(L->path);
    if (!L->hdr_path) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory opening '%s'", L->path);
    L->hdr_file = open_gz(L->hdr_path, e);
    if (!L->hdr_file) return VXL_ERR_IO;
    int rc = read_header(L->hdr_file, L->hdr_path, h, e);
    if (rc) return rc;
    if (!h->paired) {
        *data = L->hdr_file;
        *data_path = L->hdr_path;
        return VXL_OK;
    }
    /* The caller may have named the .img itself: use it as given. */
    if (ends_with(L->path, ".img") || ends_with(L->path, ".img.gz")) {
        size_t n = strlen(L->path) + 1;
        L->img_path = malloc(n);
        if (L->img_path) memcpy(L->img_path, L->path, n);
    } else if (ends_with(L->hdr_path, ".hdr") || ends_with(L->hdr_path, ".hdr.gz")) {
        L->img_path = image_path_for(L->hdr_path);
    } else {
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s': header says the voxels are in a separate .img file, but the file "
                        "name does not end in .hdr", L->hdr_path);
    }
    if (!L->img_path) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory opening '%s'", L->path);
    L->img_file = open_gz(L->img_path, e);
    if (!L->img_file) return VXL_ERR_IO;
    *data = L->img_file;
    *data_path = L->img_path;
    return VXL_OK;
}

/* NIfTI's intent codes of a vector per voxel (nifti1.h). */
#define NII_INTENT_VECTOR 1007
#define NII_INTENT_RGB_VECTOR 2003
#define NII_INTENT_RGBA_VECTOR 2004

/* How a colour file holds its channels: RGB24 and RGBA32 interleave 8-bit
 * channels per voxel; a vector file (dim[0] 5, dim[5] 3 or 4, a vector
 * intent) stores each channel as a whole volume after the other, in any
 * datatype. components 0: a grey file (as before). */
typedef struct nii_colour {
    uint32_t components;
    int planar;
    const char *what; /* for the note */
} nii_colour;

static nii_colour colour_of(const nii_header *h)
{
    nii_colour c = {0, 0, NULL};
    if (h->datatype == 128) c = (nii_colour){3, 0, "NIfTI RGB24"};
    else if (h->datatype == 2304) c = (nii_colour){4, 0, "NIfTI RGBA32"};
    else if (h->dim[0] == 5 && h->dim[4] == 1 && (h->dim[5] == 3 || h->dim[5] == 4) &&
             (h->intent_code == NII_INTENT_VECTOR || h->intent_code == NII_INTENT_RGB_VECTOR ||
              h->intent_code == NII_INTENT_RGBA_VECTOR))
        c = (nii_colour){(uint32_t)h->dim[5], 1, h->dim[5] == 3 ? "NIfTI RGB vector" : "NIfTI RGBA vector"};
    return c;
}

/* Multi-channel NIfTI (docs/channels.md): dim[5] (NIfTI's vector axis) as
 * channels, stored one whole volume after another, each frame of dim[4]
 * inside each channel. AUTO takes 2..VXL_MAX_CHANNELS channels where the
 * file is not colour and dim[6..7] are 1; ON also takes an RGB(A) vector
 * file's 3-4 as channels; OFF none (dim[5] counts frames, as before). 0: not
 * a multi-channel read. */
static int channels_of(const nii_header *h, const nii_colour *colour, const char *path, const vxl_load_options *opt,
                       uint32_t *count, vxl_err *e)
{
    *count = 0;
    uint32_t mode, scalar;
    int rc = vxl_load_channels_mode(opt, &mode, &scalar, e);
    if (rc || mode == VXL_CHANNELS_OFF || h->dim[0] < 5 || h->dim[5] <= 1) return rc;
    if (colour->components && !(colour->planar && mode == VXL_CHANNELS_ON)) return VXL_OK; /* colour */
    const int fits = h->dim[5] <= VXL_MAX_CHANNELS && (h->dim[0] < 6 || h->dim[6] <= 1) && (h->dim[0] < 7 || h->dim[7] <= 1);
    if (!fits) {
        if (mode == VXL_CHANNELS_ON)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                            "'%s': channels on, but dim[5..7] = %lld, %lld, %lld: a multi-channel volume has 2 to %d "
                            "channels along dim[5] only",
                            path, (long long)h->dim[5], (long long)(h->dim[0] >= 6 ? h->dim[6] : 1),
                            (long long)(h->dim[0] >= 7 ? h->dim[7] : 1),
                            VXL_MAX_CHANNELS);
        return VXL_OK; /* frames, as before */
    }
    *count = (uint32_t)h->dim[5];
    return VXL_OK;
}

/* Channel c of frame `frame` of a multi-channel file lies at
 * offset + (frame + dim[4] * c) * nbytes: the channels' planes of that
 * frame read into one planar buffer (forward seeks only, so .nii.gz
 * inflates each byte once). */
static int read_channel_voxels(vxl_gz *f, const char *path, uint64_t offset, uint64_t nbytes, uint32_t channels,
                               uint32_t frame, uint32_t frames, void **out, vxl_err *e)
{
    *out = NULL;
    const uint64_t last = offset + ((uint64_t)frame + (uint64_t)frames * (channels - 1)) * nbytes;
    int rc = precheck_size(f, path, last, nbytes, e);
    if (rc) return rc;
    char *buf = malloc((size_t)(nbytes * channels));
    if (!buf)
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for %u channels of %llu bytes", path, channels,
                        (unsigned long long)nbytes);
    for (uint32_t c = 0; c < channels && !rc; c++) {
        rc = vxl_gz_seek(f, offset + ((uint64_t)frame + (uint64_t)frames * c) * nbytes, e);
        uint64_t got = 0;
        if (!rc) rc = read_bytes(f, buf + c * nbytes, nbytes, &got, e);
        if (!rc && got < nbytes)
            rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s': truncated file: channel %u has %llu of %llu bytes", path, c,
                          (unsigned long long)got, (unsigned long long)nbytes);
    }
    if (rc) {
        free(buf);
        return rc;
    }
    *out = buf;
    return VXL_OK;
}

/* Validates the header and works out what to read: whole (today's checks
 * against the budget, before anything is allocated) or streamed
 * (*stream = 1, stream_load.h). */
static int plan_read(const nii_header *h, const nii_colour *colour, const char *path, const vxl_load_options *opt,
                     uint32_t dims[3], uint32_t *dtype, uint64_t *offset, uint64_t *nbytes, int *stream, vxl_err *e)
{
    int rc = check_dims(h, dims, path, e);
    if (rc) return rc;
    if (colour->components && !colour->planar) *dtype = VXL_DTYPE_U8; /* RGB24, RGBA32: 8-bit channels */
    else *dtype = vxl_dtype_from_nifti(h->datatype);
    if (!*dtype)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unsupported datatype %d (%s)", path, h->datatype,
                        datatype_name(h->datatype));
    rc = check_vox_offset(h, offset, path, e);
    if (rc) return rc;
    if (colour->components) {
        *stream = 0;
        return vxl_plan_colour_voxels(path, dims, *dtype, colour->components, opt, nbytes, e);
    }
    /* The budget check vxl_volume_build makes, but before we allocate the
     * raw buffer; it also guarantees the voxel count below cannot overflow.
     * The raw buffer is at most 2x the texture (f64 -> float texture), so
     * the address-space check only trips on 32-bit hosts. */
    return vxl_stream_plan(path, dims, *dtype, opt, NULL, stream, nbytes, e);
}

/* 4D and beyond: every axis past the third counts volumes (fMRI time,
 * cardiac phases, ...), stored one after another. Picks the requested one by
 * moving *offset past the volumes before it, so opening frame N reads only
 * frame N (a seek in .nii; zlib decompresses and discards in .nii.gz). */
static int select_frame(const nii_header *h, const char *path, const vxl_load_options *opt, uint64_t nbytes,
                        uint64_t *offset, uint32_t *count, uint32_t *frame, vxl_err *e)
{
    uint64_t n = 1;
    for (int a = 4; a <= h->dim[0] && a <= 7; a++) {
        if ((uint64_t)h->dim[a] > UINT32_MAX / n)
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s': dim[4..7] give more than %u volumes", path, UINT32_MAX);
        n *= (uint64_t)h->dim[a];
    }
    *count = (uint32_t)n;
    *frame = vxl_load_frame(opt);
    if (*frame >= n)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': frame %u requested, the file has %u (0..%u)", path,
                        *frame, *count, *count - 1);
    /* frame < 2^32 and nbytes is within the memory budget: no overflow
     * short of a 2^64-byte file, which the size check then reports */
    if (*frame && nbytes > UINT64_MAX / *frame) /* a streamed volume's nbytes is not budget-bounded */
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': frame %u lies beyond any possible file size", path, *frame);
    uint64_t skip = (uint64_t)*frame * nbytes;
    if (skip > (uint64_t)INT64_MAX - *offset)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': frame %u lies beyond any possible file size", path, *frame);
    *offset += skip;
    return VXL_OK;
}

/* NIfTI: slope 0 or non-finite means "no scaling"; a non-finite intercept
 * with a usable slope is treated as 0 rather than poisoning every value. */
static void scaling_from(const nii_header *h, double *slope, double *inter)
{
    *slope = h->scl_slope;
    *inter = h->scl_inter;
    if (!isfinite(*slope) || *slope == 0.0) {
        *slope = 0.0; /* vxl_volume_build: 0 = unscaled, inter ignored */
        *inter = 0.0;
    } else if (!isfinite(*inter)) {
        *inter = 0.0;
    }
}

/* Streams the chosen volume instead of reading it: the layout
 * of its voxels for a raw source (.nii, .img) or a bricked cache (.nii.gz,
 * .img.gz), keyed by the header. */
static int stream_volume(const nii_header *h, const char *data_path, const uint32_t dims[3],
                         uint32_t dtype, uint64_t offset, uint32_t frame_count, uint32_t frame,
                         const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    double sp[3], A[16];
    spacing_from(h, sp);
    const uint32_t affine_source = choose_affine(h, sp, A);
    vxl_raw_layout l;
    int rc = vxl_layout_init(&l, data_path, offset, dims, dtype, sp, A, e);
    if (rc) return rc;
    l.compressed = vxl_file_is_gzip(data_path);
    l.swap = h->swapped;
    scaling_from(h, &l.slope, &l.inter);
    if (l.slope == 0.0) l.slope = 1.0; /* raw_layout: unscaled is slope 1, inter 0 */
    l.affine_source = affine_source;
    l.nifti_version = (uint32_t)h->version;
    l.frame_count = frame_count;
    l.frame = frame;
    l.header_hash = vxl_fnv(14695981039346656037ull, h, sizeof *h); /* the parsed header (zeroed padding) */
    return vxl_stream_load(&l, opt, out, e);
}

/* A multi-channel file (channels_of): frame vxl_load_frame(opt) of dim[4],
 * every channel, read whole and built by vxl_volume_build_channels. */
static int load_channels(nii_load *L, const nii_header *h, vxl_gz *data, const char *data_path, uint32_t channels,
                         const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    uint32_t dims[3];
    uint64_t offset = 0, nbytes = 0;
    int rc = check_dims(h, dims, L->hdr_path, e);
    if (rc) return rc;
    const uint32_t dtype = vxl_dtype_from_nifti(h->datatype);
    if (!dtype || h->datatype == 128 || h->datatype == 2304)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': datatype %d (%s) cannot hold channels", L->hdr_path, h->datatype,
                        datatype_name(h->datatype));
    if ((rc = check_vox_offset(h, &offset, L->hdr_path, e))) return rc;
    if ((rc = vxl_plan_channel_voxels(L->hdr_path, dims, dtype, channels, opt, &nbytes, e))) return rc;
    const uint32_t frames = h->dim[4] > 1 ? (uint32_t)h->dim[4] : 1, frame = vxl_load_frame(opt);
    if (frame >= frames)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': frame %u requested, the file has %u (0..%u)", L->hdr_path,
                        frame, frames, frames - 1);
    if ((rc = read_channel_voxels(data, data_path, offset, nbytes, channels, frame, frames, &L->raw, e))) return rc;
    if (h->swapped) swap_voxels(L->raw, nbytes * channels / vxl_dtype_size(dtype), vxl_dtype_size(dtype));
    double sp[3], A[16], slope, inter;
    spacing_from(h, sp);
    const uint32_t source = choose_affine(h, sp, A);
    scaling_from(h, &slope, &inter);
    vxl_err inner = {0};
    rc = vxl_volume_build_channels(L->raw, dtype, channels, 0, dims, sp, A, slope, inter, opt, "NIfTI dim[5]", out,
                                   &inner);
    if (rc) return fail_with_path(e, L->hdr_path, &inner);
    (*out)->nifti_version = (uint32_t)h->version;
    (*out)->affine_source = source;
    (*out)->frame_count = frames;
    (*out)->frame = frame;
    if (vxl_load_streaming(opt) == VXL_STREAMING_ON)
        vxl_volume_note(*out, "read whole: a multi-channel volume does not stream");
    return VXL_OK;
}

int vxl_nifti_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    if (!out) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (!path || !*path) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path is empty");

    nii_load L = {.path = path};
    nii_header h;
    memset(&h, 0, sizeof h);
    vxl_gz *data = NULL;
    const char *data_path = NULL;
    uint32_t dims[3], dtype = 0, frame_count = 1, frame = 0;
    uint64_t offset = 0, nbytes = 0;
    int stream = 0;
    int rc = open_files(&L, &h, &data, &data_path, e);
    nii_colour colour = colour_of(&h);
    uint32_t channels = 0;
    if (!rc) rc = channels_of(&h, &colour, L.hdr_path, opt, &channels, e);
    if (!rc && channels) {
        rc = load_channels(&L, &h, data, data_path, channels, opt, out, e);
        load_cleanup(&L);
        return rc;
    }
    if (!rc) rc = plan_read(&h, &colour, L.hdr_path, opt, dims, &dtype, &offset, &nbytes, &stream, e);
    if (!rc && colour.planar && vxl_load_frame(opt) != 0) /* dim[4] is 1: one volume of channels */
        rc = vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': frame %u requested, the vector file has one volume",
                      L.hdr_path, vxl_load_frame(opt));
    else if (!rc && !colour.planar)
        rc = select_frame(&h, L.hdr_path, opt, nbytes, &offset, &frame_count, &frame, e);
    if (!rc && stream && !vxl_stream_file_holds(data_path, offset, vxl_file_is_gzip(data_path), nbytes, opt)) {
        stream = 0; /* AUTO and a file too short to stream: today's whole-read checks say why */
        rc = vxl_plan_voxels(L.hdr_path, dims, dtype, opt, &nbytes, e);
    }
    if (!rc && stream) {
        /* the files' buffers are not needed: the source opens its own */
        if (L.img_file) vxl_gz_close(L.img_file);
        vxl_gz_close(L.hdr_file);
        L.img_file = L.hdr_file = NULL;
        rc = stream_volume(&h, data_path, dims, dtype, offset, frame_count, frame, opt, out, e);
        load_cleanup(&L);
        return rc;
    }
    if (!rc) rc = read_voxels(data, data_path, offset, nbytes, &L.raw, e);
    if (rc) {
        load_cleanup(&L);
        return rc;
    }
    /* The file handles are done with: close them before the texture is
     * allocated so their buffers do not add to the peak. */
    if (L.img_file) vxl_gz_close(L.img_file);
    vxl_gz_close(L.hdr_file);
    L.img_file = L.hdr_file = NULL;

    if (h.swapped) swap_voxels(L.raw, nbytes / vxl_dtype_size(dtype), vxl_dtype_size(dtype));
    double sp[3], A[16], slope, inter;
    spacing_from(&h, sp);
    uint32_t source = choose_affine(&h, sp, A);
    scaling_from(&h, &slope, &inter);

    vxl_err inner = {0};
    if (colour.components)
        rc = vxl_volume_build_colour(L.raw, dtype, colour.components, colour.planar, dims, sp, A, slope, inter, opt,
                                     colour.what, out, &inner);
    else
        rc = vxl_volume_build(L.raw, dtype, dims, sp, A, slope, inter, opt, out, &inner);
    if (rc) rc = fail_with_path(e, L.hdr_path, &inner);
    else {
        (*out)->nifti_version = (uint32_t)h.version;
        (*out)->affine_source = source;
        (*out)->frame_count = frame_count;
        (*out)->frame = frame;
        if (colour.components && vxl_load_streaming(opt) == VXL_STREAMING_ON)
            vxl_volume_note(*out, "read whole: a colour volume does not stream");
    }
    load_cleanup(&L);
    return rc;
}
