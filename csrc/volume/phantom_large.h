/* phantom_large.h - the large sparse phantom (VXL_PHANTOM_LARGE_SPARSE):
 * Gaussian ellipsoids on a 12x8x2 lattice, hash-chosen 30% of the sites,
 * stored as 8 bits. Built by writing only the voxels near each ball, so a
 * 2500x1500x400 volume takes seconds, not a pass over 1.5 G voxels. */
#ifndef VXL_PHANTOM_LARGE_H
#define VXL_PHANTOM_LARGE_H

#include <stdint.h>

#include "volume.h"

#define VXL_LARGE_SPARSE_DIMS {2500u, 1500u, 400u} /* the default size */

/* Value and gradient (d/du) at u in [-1,1]^3. */
double vxl_large_sparse_field(const double u[3], double g[3]);
/* The volume of dims; affine maps voxels onto [-1,1]^3 like every phantom. */
int vxl_large_sparse_create(const uint32_t dims[3], const double affine[16], vxl_volume **out);

#endif
