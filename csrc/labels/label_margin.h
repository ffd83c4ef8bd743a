/* label_margin.h - the per-voxel margin that makes label boundaries smooth
 * (docs/labels.md "Smooth boundaries"). Built once per label volume on the
 * CPU: for each voxel, how far inside its own label it lies, as that
 * label's indicator (1 on its voxels) smoothed with a Gaussian and read at
 * the voxel, minus 0.5. shaders/lib/labels.glsl reads label L's field at a
 * corner voxel as +margin where the voxel is L and -margin where it is not,
 * interpolates it trilinearly and puts L's surface at its zero. One byte a
 * voxel stands in for a smoothed field per label: beside a boundary between
 * two labels one label's smoothed indicator is 1 minus the other's.
 * The margin is at least VXL_LABEL_MARGIN_MIN, so every voxel centre stays in
 * its own label (nothing is lost that the voxels show, thin parts included). */
#ifndef VXL_LABEL_MARGIN_H
#define VXL_LABEL_MARGIN_H

#include <stdint.h>

#define VXL_LABEL_MARGIN_SIGMA 1.2  /* voxels: the Gaussian (docs/labels.md: steps fade, a sphere shrinks ~sigma^2/r) */
#define VXL_LABEL_MARGIN_RADIUS 4   /* voxels each side: the kernel cut at 3.3 sigma */
#define VXL_LABEL_MARGIN_MIN (2.0 / 510) /* the least margin (2 in the byte): a larger one bumps the surface at every step */

/* out[i] (one byte a voxel, margin * 510 rounded: 255 = 0.5, deep inside)
 * for the dims[0] x dims[1] x dims[2] label volume ids; the labels at the
 * volume's faces go on past them. -1 out of memory. */
int vxl_label_margin_build(uint8_t *out, const uint16_t *ids, const uint32_t dims[3]);

#endif
