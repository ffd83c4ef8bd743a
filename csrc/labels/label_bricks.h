/* label_bricks.h - the label volume's own skipping grid
 * (docs/labels.md "Speed"). Built once per label volume on the CPU: per brick
 * of VXL_LABEL_BRICK^3 label voxels, the distinct ids in the brick and its
 * apron (the voxels labels.glsl reads from a point in the brick: the 8
 * corners of its cell, and for a crossing's normal those of the cells half a
 * voxel away).
 * Re-derived in O(bricks + listed ids) whenever the frame's table key
 * changes (hide, recolour): one 32-bit word per brick, uploaded as a small
 * R32UI texture that shaders/lib/labels.glsl leaps by:
 *   bits 0-7  Chebyshev distance in bricks to the nearest brick where a
 *             visible label can be (0: one can be here), as bricks.h's map;
 *   bit 8     UNIFORM: every voxel of the brick and its apron is one visible
 *             id, so every point of the brick is in it (every corner is that id);
 *   bits 16-31 that id. */
#ifndef VXL_LABEL_BRICKS_H
#define VXL_LABEL_BRICKS_H

#include <stdint.h>

#define VXL_LABEL_BRICK 4   /* label voxels per brick edge (labels.glsl's LABEL_BRICK): 4 leaps closer to boundaries and finds more uniform bricks than 8 (docs/labels.md) */
/* A point q of brick b (floor(q / BRICK) = b) reads voxels floor(q) ..
 * floor(q) + 1, and its normal's taps at q +- 0.5 reach floor(q) - 1 ..
 * floor(q) + 2; two voxels on each side cover them (and the rounding of q). */
#define VXL_LABEL_APRON 2
#define VXL_LABEL_UNIFORM 0x100u

typedef struct vxl_label_bricks {
    uint32_t dims[3];  /* bricks per axis */
    uint32_t *start;   /* bricks + 1 offsets: brick i's ids are ids[start[i] .. start[i + 1]) */
    uint16_t *ids;     /* the distinct ids of each brick with its apron */
    uint8_t *clipped;  /* per brick: 1 when its apron reaches past the volume (never uniform) */
    uint8_t *distance; /* scratch of the last classification */
    uint32_t *words;   /* per brick, the texture's word (above) under the last table */
} vxl_label_bricks;

/* Lists the ids of the dims[0] x dims[1] x dims[2] label volume ids per
 * brick; -1 out of memory (b is then empty). */
int vxl_label_bricks_build(vxl_label_bricks *b, const uint16_t *ids, const uint32_t dims[3]);
/* b->words under the visibility bitset visible (bit id set: the id is
 * listed and visible, 8192 bytes); -1 out of memory. */
int vxl_label_bricks_classify(vxl_label_bricks *b, const uint8_t *visible);
uint64_t vxl_label_bricks_count(const vxl_label_bricks *b);
/* CPU bytes the grid holds (the lists and the words). */
uint64_t vxl_label_bricks_bytes(const vxl_label_bricks *b);
void vxl_label_bricks_free(vxl_label_bricks *b);

#endif
