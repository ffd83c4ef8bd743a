/* modes.h - the GL side of render modes (voxlight.h's
 * VXL_MODE_*; the marches are shaders/lib/modes.glsl): the program flags of
 * a frame's mode and MatCap, and the brick min-max grid as a texture, which
 * MIP, MinIP and ISO skip bricks by. */
#ifndef VXL_MODES_H
#define VXL_MODES_H

#include <stdint.h>

#include "frame.h"
#include "gpu.h"
#include "skipping.h"
#include "storage.h"

typedef struct vxl_modes_state {
    vxl_gpu *gpu;
    const vxl_skipping_state *skipping; /* whose min-max grid is uploaded */
    const vxl_storage_state *storage;
    GLuint minmax_tex;
    const float *minmax_src;            /* the grid minmax_tex holds (released with the volume) */
    uint64_t bytes;                     /* what minmax_tex holds (its holding) */
} vxl_modes_state;

void vxl_modes_init(vxl_modes_state *s, vxl_gpu *g, const vxl_skipping_state *sk, const vxl_storage_state *st);
/* With the volume: the grid goes with it. */
void vxl_modes_release(vxl_modes_state *s);
/* The ray caster's program flags with f's mode and MatCap bits (gpu.h). */
uint32_t vxl_modes_flags(const vxl_frame *f, uint32_t flags);
/* Binds what f's mode reads (after vxl_skipping_prepare): the iso value and,
 * when bricks can be skipped, the min-max grid. */
int vxl_modes_bind(vxl_modes_state *s, const vxl_frame *f, GLuint prog);

#endif
