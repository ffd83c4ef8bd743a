/* skipping.h - the GL side of empty-space skipping (skipping.c): min-max per
 * brick (data only; bricked storage hands over the grid it computed on the
 * CPU) and the distance map texture (re-derived when the classification
 * changes). The grid itself is bricks.h's; the storage reads it to choose
 * the resident bricks. */
#ifndef VXL_SKIPPING_H
#define VXL_SKIPPING_H

#include <stdint.h>

#include "bricks.h"
#include "frame.h"
#include "gpu.h"
#include "storage.h"

typedef struct vxl_skipping_state {
    vxl_gpu *gpu;               /* the GL services */
    vxl_storage_state *storage; /* the volume the grid is derived from */
    vxl_bricks bricks;
    uint32_t texture_bits;      /* the volume texture's: 8 and 16 are normalised integers */
    GLuint brick_tex;
} vxl_skipping_state;

/* Wires sk to the GL services and the storage, and hands the storage its grid. */
void vxl_skipping_init(vxl_skipping_state *sk, vxl_gpu *g, vxl_storage_state *st);
int vxl_skipping_prepare(vxl_skipping_state *sk, const vxl_frame *f);
void vxl_skipping_release(vxl_skipping_state *sk);
/* Takes a min-max grid the storage computed (bricked: on the CPU at
 * set_volume); an empty one leaves the grid to be built from the texture,
 * whose texels have the volume's texture_bits. */
void vxl_skipping_adopt(vxl_skipping_state *sk, vxl_bricks *grid, uint32_t texture_bits);

#endif
