/* bricks.h - empty-space skipping. The brick min-max grid depends only on
 * the volume data (built once per volume on the GL side, kept on the CPU);
 * the occupancy and its Chebyshev distance map depend on the transfer
 * function, window and opacity scale (re-derived in O(bricks) when those
 * change, without touching the volume texture). */
#ifndef VXL_BRICKS_H
#define VXL_BRICKS_H

#include <stdint.h>

#define VXL_DEFAULT_BRICK 8
#define VXL_FINE_BRICK 4
#define VXL_FINE_BRICK_MAX_COUNT (1u << 21)

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

/* What occupancy depends on, as plain values (the renderer fills it from
 * its frame: vxl_frame_occupancy_rule in frame.h), so skipping needs no
 * render parameters. */
typedef struct vxl_occupancy_rule {
    uint64_t table_key;     /* hash of the table, window and opacity scale: equal keys, equal occupancy */
    const float *tf;        /* tf_size straight RGBA entries, alpha per voxel of path */
    uint32_t tf_size;
    float window_offset, window_scale, opacity_scale; /* normalised value -> table position in [0,1] */
    int iso;                /* iso-surface opacity: occupancy follows the surface, not the table */
    float iso_pos, iso_thickness; /* iso: the surface's normalised value and its thickness */
    uint32_t filter;        /* VXL_FILTER_* of the gradients (iso: bounds how far taps reach) */
    float sample_distance;  /* voxels between gradient taps */
} vxl_occupancy_rule;

/* The skipping grid's brick edge: VXL_DEFAULT_BRICK, or VOXLIGHT_BRICK_SIZE. */
uint32_t vxl_skip_brick_size(void);
/* The edge of a grid built on the GPU for one dense volume of dims
 * (skipping.c): VXL_FINE_BRICK while that grid has at most
 * VXL_FINE_BRICK_MAX_COUNT bricks (up to 512^3 voxels: 16 MiB of min-max,
 * 2 MiB of distances), else VXL_DEFAULT_BRICK; VOXLIGHT_BRICK_SIZE overrides.
 * Finer bricks fit the tissue's edge closer: 16-38% fewer samples on the
 * brain volumes at identical images (docs/skipping.md). The paged storages
 * keep VXL_DEFAULT_BRICK: their grids come from CPU indexes of 8^3 bricks
 * (a streamed volume's smallest), and sparse and streamed storage must page
 * alike. */
uint32_t vxl_skip_brick_size_for(const uint32_t dims[3]);
/* Occupancy + distance map under the rule; returns 1 if it changed (the
 * caller re-uploads), 0 if the cached one still holds, -1 out of memory. */
int vxl_bricks_classify(vxl_bricks *b, const vxl_occupancy_rule *c);
void vxl_bricks_free(vxl_bricks *b);
/* In place: an occupancy grid (0 occupied, 255 empty) of dims becomes its
 * Chebyshev distance map (bricks.distance's meaning); -1 out of memory.
 * Also the label bricks' (labels/label_bricks.c). */
int vxl_bricks_chebyshev(uint8_t *d, const uint32_t dims[3]);
/* Voxels around a brick that gradient taps sample_distance apart (filter
 * VXL_FILTER_*) and their trilinear footprint reach, when the filter's
 * |gradient| is bounded by the adjacent differences there (central,
 * forward3, Sobel); 0 = no such bound. */
uint32_t vxl_bricks_gradient_apron(uint32_t filter, float sample_distance);

#endif
