/* zarr.h - OME-Zarr images (OME-NGFF v0.4 on Zarr v2, v0.5 on Zarr v3):
 * the store's metadata (zarr_store.c), one chunk decoded (zarr_chunk.c:
 * raw, gzip/zlib, zstd, blosc), one multiscale level read into a volume
 * (zarr_read.c, run by the helper voxlight-read-zarr for whole reads) and
 * the brick source that streams chunks on demand (zarr_source.c, in the
 * library). The same objects are built into libvoxlight.so and the helper:
 * libzstd and libblosc are never linked, they are opened with dlopen when
 * the first chunk that needs one is met (zarr_codecs.c), so the library
 * still links only the C runtime.
 *
 * Chunks are addressed by their index on the level's chunk grid:
 * vxl_zarr_read_chunk decodes one; vxl_zarr_read loads one level whole. */
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

#define VXL_ZARR_MAX_WINDOWS 64 /* omero channels whose window is kept */

typedef struct vxl_zarr_store {
    int zarr_format;
    int ndim;
    int axis[VXL_ZARR_ROLES];
    char unit[32];      /* the x axis' unit as written ("" when none) */
    /* Per array dimension: the factor from its unit to mm (micrometer
     * 0.001, ...), already applied to scale and translation below; 1 for
     * no unit or one that is not a length (docs/zarr.md). */
    double to_mm[VXL_ZARR_MAX_NDIM];
    /* omero "window" per channel (its "min"/"max", else "start"/"end"):
     * the value range of float data when present (window_set[c]). */
    int window_count;
    unsigned char window_set[VXL_ZARR_MAX_WINDOWS];
    double window[VXL_ZARR_MAX_WINDOWS][2];
    /* omero channels' "label", "color" ("RRGGBB", sRGB), display "window"
     * start/end and "active", for the first VXL_MAX_CHANNELS channels: what a
     * multi-channel read reports (docs/channels.md); a malformed entry is
     * left unknown and said in meta_notes. */
    vxl_channel_meta meta[VXL_MAX_CHANNELS];
    char meta_notes[160];
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

/* The decoders of libzstd and libblosc, opened with dlopen on the first
 * chunk that needs one (gzip/zlib is zlib, which the library links). One
 * table per reader (a source, a whole read); thread-safe; a missing library
 * is an error naming it and the codec, met only when such a chunk is. */
typedef struct vxl_zarr_codecs vxl_zarr_codecs;
vxl_zarr_codecs *vxl_zarr_codecs_new(void);
void vxl_zarr_codecs_free(vxl_zarr_codecs *c); /* NULL is a no-op */

/* Bytes of one decoded chunk (the product of chunks times the element
 * size); 0 when over VXL_ZARR_MAX_CHUNK_BYTES. */
uint64_t vxl_zarr_chunk_bytes(const vxl_zarr_array *a);

/* Decodes chunk idx[0..ndim) of a into out (vxl_zarr_chunk_bytes bytes),
 * native byte order; a missing chunk file is filled with a->fill. */
int vxl_zarr_read_chunk(const vxl_zarr_array *a, const uint64_t *idx, vxl_zarr_codecs *codecs, void *out,
                        vxl_err *e);
/* The same, also adding the bytes read from disk to *bytes_read (NULL: not
 * counted). */
int vxl_zarr_read_chunk_counted(const vxl_zarr_array *a, const uint64_t *idx, vxl_zarr_codecs *codecs, void *out,
                                uint64_t *bytes_read, vxl_err *e);

/* Decodes one stored chunk (src, n bytes, named name) into out, exactly
 * nbytes after decompression or an error; native byte order. */
int vxl_zarr_decode(const vxl_zarr_array *a, vxl_zarr_codecs *codecs, const void *src, size_t n, void *out,
                    uint64_t nbytes, const char *name, vxl_err *e);

/* The helper's reader: path is the store's folder, optionally followed by
 * "#level=N&c=N" (level: 0 = finest; absent = the finest that fits the
 * memory budget; c: one channel; absent: every channel of a c axis of
 * 2..VXL_MAX_CHANNELS as a multi-channel volume, else channel 0);
 * opt->frame picks t. */
int vxl_zarr_read(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);

/* The "#level=N&c=N" after a store's folder: level -1 when not given;
 * c_given 0 when "c=" is absent (a c axis of 2..VXL_MAX_CHANNELS then loads
 * as channels unless vxl_load_options.channels is OFF). */
typedef struct vxl_zarr_choice {
    int level;
    int c_given;
    uint64_t c;
} vxl_zarr_choice;
int vxl_zarr_parse_path(const char *path, char *folder, size_t size, vxl_zarr_choice *ch, vxl_err *e);
/* The channels a whole read of the store takes together: the c extent of
 * level 0 when it is 2..VXL_MAX_CHANNELS, no "c=" was given and opt's
 * channels mode is not OFF (ON with more is an error naming the limit);
 * else 0 (one channel, ch->c). */
int vxl_zarr_channels(const char *path, const vxl_zarr_store *s, const vxl_zarr_choice *ch,
                      const vxl_load_options *opt, uint32_t *channels, vxl_err *e);

/* Checks level and the choice of t (opt->frame) and c against the store:
 * sel[VXL_ZARR_T], sel[VXL_ZARR_C] (others 0) and the t extent *nt, or an
 * error naming path. */
int vxl_zarr_select(const char *path, const vxl_zarr_store *s, int level, const vxl_load_options *opt,
                    const vxl_zarr_choice *ch, uint64_t sel[VXL_ZARR_ROLES], uint64_t *nt, vxl_err *e);

/* The brick source of a store (zarr_source.c; docs/zarr.md, streaming.md):
 * path as vxl_zarr_read's; its levels are the store's multiscale levels
 * from the chosen one (0 unless "#level=N") that are each 2x smaller per
 * axis than the one before (others are skipped). Also fills the volume
 * geometry and value range the streamed volume needs (*info). */
typedef struct vxl_zarr_source_info {
    uint32_t dtype;           /* VXL_DTYPE_* of the array */
    double tex_lo, tex_hi;    /* value = tex_lo + t * (tex_hi - tex_lo) */
    double value_min, value_max;
    double spacing[3];        /* mm */
    double affine[16];
    uint32_t frame_count, frame;
} vxl_zarr_source_info;
int vxl_zarr_open_source(const char *path, const vxl_load_options *opt, vxl_brick_source **out,
                         vxl_zarr_source_info *info, vxl_err *e);

/* The dispatch's entry (volume_load.c): a streamed volume when
 * vxl_load_options.streaming asks for it (ON, or AUTO when the chosen
 * level's voxels exceed half the memory budget), else vxl_zarr_load's
 * whole read in the helper. */
int vxl_zarr_load_any(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);

#endif
