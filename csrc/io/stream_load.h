/* stream_load.h - whether a file loader streams, and the
 * streamed volume it then makes: the NIfTI, NRRD and MetaImage loaders
 * parse their header, fill a vxl_raw_layout and hand it here instead of
 * reading the voxels (docs/streaming.md). An uncompressed file is read by
 * offset (raw_source.h); a gzip stream through a bricked cache
 * (brick_cache.h). */
#ifndef VXL_STREAM_LOAD_H
#define VXL_STREAM_LOAD_H

#include <stdint.h>

#include "error.h"
#include "raw_layout.h"
#include "volume.h"

/* vxl_load_options.streaming where the caller's struct has it, else AUTO. */
uint32_t vxl_load_streaming(const vxl_load_options *opt);

/* Plans a 3D read of dims voxels of dtype. *stream = 1 when the file is to
 * stream (ON, or AUTO with texture bytes over half the memory budget); then
 * only the per-axis limit and overflow are checked and *nbytes is the raw
 * size. Else today's whole-read checks (vxl_plan_voxels). not_streamable:
 * NULL when this file can stream, else what it is ("attached gzip NRRD
 * data"): it is read whole, and over the budget the error says streaming is
 * not available for it. */
int vxl_stream_plan(const char *path, const uint32_t dims[3], uint32_t dtype, const vxl_load_options *opt,
                    const char *not_streamable, int *stream, uint64_t *nbytes, vxl_err *e);

/* Fails with msg (a whole read's budget error) ended by why streaming did
 * not help: "(streaming is not available for <what>)". msg may be e->msg. */
int vxl_fail_not_streamable(vxl_err *e, int rc, const char *msg, const char *what);

/* Whether the file can hold what its header claims (raw: offset + nbytes
 * within it; compressed: within deflate's 1032:1 bound), checked in AUTO
 * mode before streaming: when it cannot, the loader reads whole, whose
 * checks report the budget or the truncation as they always have. Always 1
 * under ON (the source reports a short file itself). */
int vxl_stream_file_holds(const char *path, uint64_t offset, int compressed, uint64_t nbytes,
                          const vxl_load_options *opt);

/* Starts a layout: zeroes it, then path (length-checked), offset, dims,
 * dtype, spacing and affine, slope 1, one frame, and file_size and mtime_ns
 * from the file. The loader adds compressed, swap, scaling, the affine's
 * source, frames and the header hash. */
int vxl_layout_init(vxl_raw_layout *l, const char *path, uint64_t offset, const uint32_t dims[3], uint32_t dtype,
                    const double spacing[3], const double affine[16], vxl_err *e);

/* 1 when path starts with the gzip magic (a .nii.gz, a detached .raw.gz). */
int vxl_file_is_gzip(const char *path);

/* The streamed volume of l: texels NULL, source set, storage_bytes the
 * whole texture's size, value range and counts from the source's pass. */
int vxl_stream_load(const vxl_raw_layout *l, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);

#endif
