/* bspline_bricks.h - CPU work on page bricks for the filters whose data is
 * derived from the volume (pure, no GL): the cubic filter's B-spline
 * coefficients brick by brick, and the precomputed filter's global maximum
 * gradient magnitude. Both reproduce what the dense compute shaders give for
 * one texture (bspline_prefilter.comp; gradients.comp),
 * so bricked and sparse storage render what dense storage renders. */
#ifndef VXL_BSPLINE_BRICKS_H
#define VXL_BSPLINE_BRICKS_H

#include <stddef.h>
#include <stdint.h>

#include "paging.h"

/* The recursive prefilter's pole is sqrt(3) - 2: a value k voxels away weighs
 * 0.268^k. Past the margin (and the ghost) that is 0.268^13 ~ 4e-8 of the
 * value range, under float rounding, so a window this much wider than the
 * brick gives the whole line's coefficients. */
#define VXL_BSPLINE_MARGIN 12

/* The precomputed filter's blur and Sobel reach 2 voxels each way: a brick
 * whose voxels within that hold one value has zero gradient, and its
 * gradient texels read by a visible sample (trilinear, through the brick of
 * the nearest texel) lie within 2 voxels of it. */
#define VXL_GRADIENT_SUPPORT 2
#define VXL_GRADIENT_READ_REACH 2

/* Floats of scratch vxl_bspline_brick needs for bricks of pg. */
size_t vxl_bspline_scratch_floats(const vxl_pages *pg);

/* Coefficients of page brick i of pg (a volume of dims voxels; data in s)
 * with its one-voxel ghost: (P+2)^3 floats, x fastest, into out. Voxel l of
 * the brick stands for volume voxel i*P + l - 1 clamped into the volume, as
 * clamp-to-edge sampling of one coefficient texture reads it. */
void vxl_bspline_brick(const vxl_pages *pg, const vxl_brick_store *s, const uint32_t dims[3], uint64_t i,
                       float *scratch, float *out);

/* Largest |gradient| of the precomputed filter ([1,2,1]^3 blur, then the
 * 26-neighbour Sobel, clamped at the volume's border) over the whole volume:
 * what the dense MAX pass finds, from the CPU bricks, so sparse storage
 * scales its gradients exactly as dense storage does. -1: out of memory. */
float vxl_pages_gradient_max(const vxl_pages *pg, const vxl_brick_store *s, const uint32_t dims[3]);

#endif
