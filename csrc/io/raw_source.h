/* raw_source.h - a brick source over an uncompressed file: the
 * voxels of NIfTI (.nii, .img), NRRD and MetaImage data read by offset,
 * one box at a time with pread (no mmap: mapped pages would count as the
 * process's resident memory), converted into the texture format exactly as
 * vxl_volume_build converts a whole volume (volume.c), bytes swapped as the
 * layout says.
 *
 * Opening makes one streaming pass over the file in z slabs (bounded
 * memory; floats, whose texels depend on the data range, take a range pass
 * first) that finds the value range and NaN/Inf counts, the brick index and
 * the coarse levels (kept whole while a level is at most
 * VXL_SOURCE_KEEP_LEVEL_BYTES; the finer ones are averaged from level-0
 * reads on demand; VOXLIGHT_SOURCE_KEEP_BYTES overrides the size for
 * tests). Holes of a sparse file (raw zero) are found with
 * lseek(SEEK_DATA/SEEK_HOLE) and never read. */
#ifndef VXL_RAW_SOURCE_H
#define VXL_RAW_SOURCE_H

#include "brick_source.h"
#include "error.h"
#include "raw_layout.h"
#include "volume.h"

/* Opens layout->path (layout->compressed must be 0) and makes the pass,
 * reporting progress through opt (may be NULL; nonzero from the callback:
 * VXL_ERR_CANCELLED). A file shorter than the header's voxels, sizes that
 * overflow or exceed opt->max_dim are errors naming the file. */
int vxl_raw_source_open(const vxl_raw_layout *layout, const vxl_load_options *opt, vxl_brick_source **out,
                        vxl_err *e);

/* Sets v's value fields (tex_lo/hi, value_min/max, nan/inf counts) from a
 * raw source's pass, as vxl_volume_build would for the whole volume;
 * VXL_ERR_INVALID_ARGUMENT for any other source. */
int vxl_raw_source_describe(const vxl_brick_source *s, vxl_volume *v, vxl_err *e);

#endif
