/* illumination_state.h - what the illumination volumes (illumination.h)
 * hold, apart from their functions, so the renderer's state can hold it
 * without depending on the module that builds it. */
#ifndef VXL_ILLUMINATION_STATE_H
#define VXL_ILLUMINATION_STATE_H

#include <stdint.h>

#include "gl_funcs.h"
#include "voxlight.h"

typedef struct vxl_illumination_state {
    GLuint extinction_tex;      /* R32F, extinction_cells: mean optical depth per voxel of path */
    GLuint tex;                 /* R16F, cells stacked `blocks` times along z: light i, then occlusion */
    uint32_t extinction_cells[3]; /* at least as fine as cells: kept when only the lights' grid shrinks */
    uint32_t cells[3];
    uint32_t blocks;
    uint32_t size;              /* cells along the longest side */
    uint64_t bytes;
    uint64_t extinction_key, occlusion_key;
    uint64_t light_key[VXL_MAX_LIGHTS];
    int in_use;                 /* the last prepared frame reads it */
    uint32_t rebuilt;           /* volumes the last prepare rebuilt (lights + occlusion) */
    uint32_t builds;            /* every volume built since the renderer opened (tests) */
} vxl_illumination_state;

#endif
