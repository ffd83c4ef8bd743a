/* lod.h - coarser levels for the level-of-detail fallback of sparse
 * storage: when the bricks a classification can see do not fit the memory
 * budget, the renderer falls back to a level whose voxels average 2^k x 2^k
 * x 2^k of the original, and says so in its stats. */
#ifndef VXL_LOD_H
#define VXL_LOD_H

#include "error.h"
#include "volume.h"

#define VXL_LOD_LEVELS 4 /* full resolution plus 2x, 4x, 8x coarser */

/* A volume of ceil(dims/2) voxels, each the mean of its 2x2x2 (edge voxels
 * repeated at odd sizes), in the same texel format. Destroy with
 * vxl_volume_destroy. */
int vxl_volume_downsample2(const vxl_volume *v, vxl_volume **out, vxl_err *e);

#endif
