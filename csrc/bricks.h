/* bricks.h - empty-space skipping. The brick min-max grid depends only on
 * the volume data (built once per volume on the GL side, kept on the CPU);
 * the occupancy and its Chebyshev distance map depend on the transfer
 * function, window and opacity scale (re-derived in O(bricks) when those
 * change, without touching the volume texture). */
#ifndef VXL_BRICKS_H
#define VXL_BRICKS_H

#include <stdint.h>

#include "frame.h"

#define VXL_DEFAULT_BRICK 8

typedef struct vxl_bricks {
    uint32_t size;          /* voxels per brick edge */
    uint32_t dims[3];       /* bricks per axis */
    float *minmax;          /* 2 per brick: normalised min, max (apron included) */
    uint8_t *distance;      /* 0 = occupied; k = Chebyshev distance in bricks to the nearest occupied, max 255 */
    uint64_t tf_key;        /* hash of what the occupancy was derived from */
    uint32_t occupied;      /* occupied bricks under that classification */
    /* Iso-surface opacity only (built on first use): per brick, a bound on
     * |gradient| of the difference filters over taps reaching gbound_apron
     * voxels around the brick; NULL = none, every brick counts as occupied. */
    float *gbound;
    uint32_t gbound_apron;
} vxl_bricks;

/* Occupancy + distance map for the frame's classification; returns 1 if it
 * changed (the caller re-uploads), 0 if the cached one still holds. */
int vxl_bricks_classify(vxl_bricks *b, const vxl_frame *f);
void vxl_bricks_free(vxl_bricks *b);
/* Voxels around a brick that a frame's gradient taps and their trilinear
 * footprint reach, when the filter's |gradient| is bounded by the adjacent
 * differences there (central, forward3, Sobel); 0 = no such bound. */
uint32_t vxl_bricks_gradient_apron(const vxl_frame *f);

#endif
