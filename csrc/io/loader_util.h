/* loader_util.h - shared pieces of the text-header loaders (NRRD, MetaImage):
 * bounded header reading, strict number parsing, path joining, size-checked
 * raw and zlib/gzip voxel reads. Everything reports through vxl_fail with the
 * file name; nothing allocates from a header value before the caller has run
 * vxl_volume_check_limits. */
#ifndef VXL_LOADER_UTIL_H
#define VXL_LOADER_UTIL_H

#include <stddef.h>
#include <stdint.h>

#include "volume.h"

/* Longest text header we accept: real ones are a few KiB. */
#define VXL_HEADER_MAX (1u << 20)

/* Reads up to VXL_HEADER_MAX bytes from the start of path into a new
 * NUL-terminated buffer (*len bytes before the NUL; *file_size the whole
 * file's size). The file must be a regular file. */
int vxl_read_head(const char *path, char **text, size_t *len, uint64_t *file_size, vxl_err *e);

/* Requires path to name an existing regular file (not a FIFO, device or
 * directory a hostile header could point at); *size receives its size. */
int vxl_regular_file(const char *path, uint64_t *size, vxl_err *e);

/* Reads n bytes at file offset off, retrying short reads and EINTR: n when
 * all were read, fewer when the file ends first, -1 on a read error (errno
 * says which). The callers word their own errors. */
int64_t vxl_pread_full(int fd, void *buf, size_t n, uint64_t off);

/* Splits off the next line of text[*pos..len): returns it NUL-terminated in
 * place (without \r\n) or NULL at the end; *pos moves past the newline.
 * *had_newline says whether the line was terminated. */
char *vxl_next_line(char *text, size_t len, size_t *pos, int *had_newline);

/* Trims ASCII whitespace at both ends, in place. */
char *vxl_trim(char *s);

/* Strict parsing of whitespace-separated numbers: every token must parse
 * completely and be finite. At most n are stored; returns how many tokens
 * there were (the caller checks it), or -1 on a bad token or more than 64. */
int vxl_parse_doubles(const char *s, double *out, int n);
/* Non-negative integers up to max; -1 on anything else. */
int vxl_parse_u64s(const char *s, uint64_t *out, int n, uint64_t max);

/* dir of base_path joined with name (name returned as is when absolute).
 * malloc'd; NULL when memory is short. */
char *vxl_sibling_path(const char *base_path, const char *name);

/* Reads nbytes of voxel data from path at offset into a new buffer.
 * compressed: 0 raw, 1 zlib or gzip stream (auto-detected) starting at
 * offset, of which skip_after decompressed bytes are discarded first.
 * from_end (raw only): the data is the last nbytes of the file, offset is
 * ignored. Truncation is reported before allocating for raw files. */
int vxl_read_payload(const char *path, uint64_t offset, int from_end, int compressed, uint64_t skip_after,
                     uint64_t nbytes, void **out, vxl_err *e);

/* Reverses the bytes of every elem-byte element. */
void vxl_swap_elements(void *p, uint64_t count, size_t elem);

/* 1 when this host is big-endian. */
int vxl_host_big_endian(void);

/* The load's memory budget in bytes: the options' own, else the default. */
uint64_t vxl_load_budget(const vxl_load_options *opt);

/* Plans a 3D read: checks the dims against the limits (naming path) and
 * returns the raw byte count for dtype. */
int vxl_plan_voxels(const char *path, const uint32_t dims[3], uint32_t dtype, const vxl_load_options *opt,
                    uint64_t *nbytes, vxl_err *e);

/* vxl_plan_voxels for a colour file of `components` (3, 4) interleaved or
 * planar channels of dtype, read whole (its colour has no brick source):
 * the budget takes the raw channels or the scalar's texture with its RGB8
 * colour, whichever is larger; over it the error says streaming is not
 * available for colour. *nbytes: the raw channels' bytes. */
int vxl_plan_colour_voxels(const char *path, const uint32_t dims[3], uint32_t dtype, uint32_t components,
                           const vxl_load_options *opt, uint64_t *nbytes, vxl_err *e);

/* The same for a multi-channel file of `channels` planes of dtype, read
 * whole: the budget takes the raw channels or the scalar's texture with its
 * 16-bit channels, whichever is larger. *nbytes: one channel's raw bytes. */
int vxl_plan_channel_voxels(const char *path, const uint32_t dims[3], uint32_t dtype, uint32_t channels,
                            const vxl_load_options *opt, uint64_t *nbytes, vxl_err *e);

/* The whole read of interleaved voxels as NRRD and MetaImage build it:
 * `channels` (2..8) as a multi-channel volume, else `components` (3, 4) as
 * colour, else one scalar; the notes name the input as "<format>
 * <channel_axis>" ("NRRD channel axis") or "<format> RGB(A)". streaming_on:
 * the load asked to stream, which channels and colour do not (noted). An
 * error is wrapped with path. */
int vxl_build_interleaved(const char *path, const void *raw, uint32_t dtype, uint32_t channels, uint32_t components,
                          const uint32_t dims[3], const double sp[3], const double A[16], const vxl_load_options *opt,
                          const char *format, const char *channel_axis, int streaming_on, vxl_volume **out,
                          vxl_err *e);

/* Wraps an error from a helper with the file name, keeping its code. */
int vxl_fail_in(vxl_err *e, const char *path, const vxl_err *inner);

/* Fills a column-major affine from 3 direction columns (each already scaled
 * by the voxel size) and an origin. Returns 1 if finite and invertible. */
int vxl_affine_from(const double dir[3][3], const double origin[3], double A[16]);

/* vxl_load_options.voxel_size when the caller's struct has it (struct_size),
 * each axis defaulting to 1 mm. */
void vxl_load_voxel_size(const vxl_load_options *opt, double out[3]);

/* vxl_load_options.frame and .series when struct_size covers them (0 and
 * NULL otherwise). */
uint32_t vxl_load_frame(const vxl_load_options *opt);
const char *vxl_load_series(const vxl_load_options *opt);

/* Folds every run of white space in a third-party message (OpenImageIO,
 * OpenVDB) into one space, in place, and trims both ends: our errors are one
 * line, and a message padded with hundreds of spaces would otherwise fill
 * the error buffer before its meaning (OpenVDB 11's "KeyError: Map   ...
 * is not registered"). Returns s. */
char *vxl_one_line(char *s);

#endif
