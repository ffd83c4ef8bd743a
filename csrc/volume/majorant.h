/* majorant.h - the PATH shading model's majorant: per skipping brick, an
 * extinction no sample in the brick can exceed under a classification,
 * from the brick's min-max (apron included) and the transfer function. */
#ifndef VXL_MAJORANT_H
#define VXL_MAJORANT_H

#include "bricks.h"

/* -ln(2^-24): extinction per voxel of path where the opacity is 1 (a voxel
 * that keeps 6e-8 of the light), the cap vxl_classified_grid also uses. */
#define VXL_MAX_VOXEL_EXTINCTION 16.635532333438686

/* Extinction per voxel of path of opacity a in [0, 1], capped. */
double vxl_voxel_extinction(double a);
/* out[i] (one float per brick of b) = a bound on the extinction of every
 * sample brick i can hold under rule f (post-classification with linear
 * table interpolation), 0 exactly where the table is transparent over the
 * brick's range. whole_table: every brick gets the bound over the whole
 * table (for storage whose samples the grid does not bound: coarser levels,
 * lossy palettes). */
void vxl_bricks_majorant(const vxl_bricks *b, const vxl_occupancy_rule *f, int whole_table, float *out);

#endif
