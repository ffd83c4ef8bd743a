/* colour_volume.h - colour volumes (RGB, RGBA) on the CPU side: the scalar
 * the whole pipeline renders (the opacity source: luminance, one channel or
 * alpha) built by vxl_volume_build, and beside it the voxels' own colour as
 * RGB8 (vxl_volume.colour), which the ray caster reads in place of the
 * transfer function's colour (docs/colour.md). */
#ifndef VXL_COLOUR_VOLUME_H
#define VXL_COLOUR_VOLUME_H

#include <stdint.h>

#include "volume.h"

#define VXL_COLOUR_BYTES_PER_VOXEL 3u /* RGB8 */

/* Builds a colour volume from `components` (3 or 4) values of dtype per
 * voxel: interleaved (planar 0: the channel fastest) or planar (each
 * channel a whole volume after the other, as vector NIfTI stores them).
 * slope/inter scale the scalar (its data values, for the window) as
 * vxl_volume_build does; colour of 8-bit unsigned data is kept as it is,
 * any other type is windowed over its range of R, G and B into 8 bits (a
 * note says so). opt's opacity_source picks the scalar (CHANNEL out of
 * range or ALPHA of RGB: VXL_ERR_INVALID_ARGUMENT). Checks the budget with
 * the colour's 3 bytes a voxel before allocating. `what` names the input
 * in the note ("NIfTI RGB24"). */
int vxl_volume_build_colour(const void *raw, uint32_t dtype, uint32_t components, int planar, const uint32_t dims[3],
                            const double spacing[3], const double *affine, double slope, double inter,
                            const vxl_load_options *opt, const char *what, vxl_volume **out, vxl_err *e);

/* The opacity source and channel of opt as given (struct_size covering
 * them; else luminance, channel 0), unchecked: what a reader helper is told. */
void vxl_load_opacity_source(const vxl_load_options *opt, uint32_t *source, uint32_t *channel);

/* The opacity source and channel of opt (struct_size covering them; else
 * luminance), checked against `components`. */
int vxl_colour_opacity_source(const vxl_load_options *opt, uint32_t components, uint32_t *source, uint32_t *channel,
                              vxl_err *e);

/* Bytes of v's colour (0 for a grey volume). */
uint64_t vxl_volume_colour_bytes(const vxl_volume *v);

#endif
