/* zarr.h - OME-Zarr images (OME-NGFF v0.4 on Zarr v2, v0.5 on Zarr v3):
 * the store's metadata (zarr_store.c), one chunk decoded (zarr_chunk.c:
 * raw, gzip/zlib, zstd, blosc) and one multiscale level read into a volume
 * (zarr_read.c). Built into the helper voxlight-read-zarr only (it links
 * libzstd and libblosc, which libvoxlight.so must not: reader_stream.h).
 *
 * Chunks are addressed by their index on the level's chunk grid, so a
 * reader that wants one brick at a time (a later brick source) calls
 * vxl_zarr_read_chunk per brick; vxl_zarr_read loads one level whole. */
#ifndef VXL_ZARR_H
#define VXL_ZARR_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "volume.h"

#define VXL_ZARR_MAX_NDIM 5     /* t, c, z, y, x */
#define VXL_ZARR_MAX_LEVELS 32
#define VXL_ZARR_MAX_CHUNK_BYTES (1ull << 30) /* one decoded chunk */
#define VXL_ZARR_MAX_CHUNKS (1ull << 24)      /* chunks one level read may visit */

/* Axis roles; vxl_zarr_store.axis[role] is the array dimension or -1. */
enum { VXL_ZARR_T, VXL_ZARR_C, VXL_ZARR_Z, VXL_ZARR_Y, VXL_ZARR_X, VXL_ZARR_ROLES };

enum { VXL_ZARR_RAW, VXL_ZARR_ZLIB /* gzip or zlib stream */, VXL_ZARR_ZSTD, VXL_ZARR_BLOSC };

/* One array (a multiscale level). */
typedef struct vxl_zarr_array {
    int ndim;
    uint64_t shape[VXL_ZARR_MAX_NDIM];
    uint64_t chunks[VXL_ZARR_MAX_NDIM];
    uint32_t dtype;     /* VXL_DTYPE_* */
    int big_endian;     /* stored byte order */
    int codec;          /* VXL_ZARR_RAW ... */
    double fill;        /* value of a missing chunk */
    int zarr_format;    /* 2 or 3 */
    char separator;     /* '.' or '/' between chunk indices */
    int key_prefix;     /* Zarr v3 "default" encoding: keys start with "c" */
    char path[4096];    /* the array's folder */
} vxl_zarr_array;

typedef struct vxl_zarr_store {
    int zarr_format;
    int ndim;
    int axis[VXL_ZARR_ROLES];
    char unit[32];      /* the x axis' unit as written ("" when none) */
    int nlevels;
    vxl_zarr_array level[VXL_ZARR_MAX_LEVELS];
    /* world = scale * index + translation, per array dimension (the
     * dataset's transforms, then the multiscale's) */
    double scale[VXL_ZARR_MAX_LEVELS][VXL_ZARR_MAX_NDIM];
    double translation[VXL_ZARR_MAX_LEVELS][VXL_ZARR_MAX_NDIM];
} vxl_zarr_store;

/* Reads the group's multiscales and every level's array metadata. */
int vxl_zarr_open(const char *root, vxl_zarr_store *s, vxl_err *e);

/* The metadata parsers on text (name: the file, for messages), for
 * vxl_zarr_open and the fuzz target. Group: .zattrs (v2, is_v3 0) or the
 * group zarr.json (v3); fills s's axes and each level's relative path into
 * level[i].path and the transforms. Array: .zarray or array zarr.json. */
int vxl_zarr_parse_group(const char *text, size_t len, int is_v3, const char *name, vxl_zarr_store *s,
                         vxl_err *e);
int vxl_zarr_parse_array(const char *text, size_t len, int is_v3, const char *name, vxl_zarr_array *a,
                         vxl_err *e);

/* Reads a whole file of at most max bytes into a malloc'd, NUL-terminated
 * buffer. Returns VXL_OK, a vxl_fail code, or (without failing, so the
 * caller words it) VXL_ZARR_FILE_MISSING or VXL_ZARR_FILE_TOO_LARGE (*size
 * set). */
#define VXL_ZARR_FILE_MISSING (-1)
#define VXL_ZARR_FILE_TOO_LARGE (-2)
int vxl_zarr_read_file(const char *path, uint64_t max, char **text, size_t *len, uint64_t *size, vxl_err *e);

/* Bytes of one decoded chunk (the product of chunks times the element
 * size); 0 when over VXL_ZARR_MAX_CHUNK_BYTES. */
uint64_t vxl_zarr_chunk_bytes(const vxl_zarr_array *a);

/* Decodes chunk idx[0..ndim) of a into out (vxl_zarr_chunk_bytes bytes),
 * native byte order; a missing chunk file is filled with a->fill. */
int vxl_zarr_read_chunk(const vxl_zarr_array *a, const uint64_t *idx, void *out, vxl_err *e);

/* Decodes one stored chunk (src, n bytes, named name) into out, exactly
 * nbytes after decompression or an error; native byte order. */
int vxl_zarr_decode(const vxl_zarr_array *a, const void *src, size_t n, void *out, uint64_t nbytes,
                    const char *name, vxl_err *e);

/* The helper's reader: path is the store's folder, optionally followed by
 * "#level=N&c=N" (level: 0 = finest; absent = the finest that fits the
 * memory budget; c: the channel, default 0); opt->frame picks t. */
int vxl_zarr_read(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);

#endif
