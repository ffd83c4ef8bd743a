/* path.h - the GL side of the PATH shading model (voxlight.h's
 * VXL_SHADING_PATH; the tracer is shaders/render/path.frag): the majorant
 * grid as a texture, re-derived when the classification or the brick grid
 * changes, and the tracer's uniforms. */
#ifndef VXL_PATH_H
#define VXL_PATH_H

#include <stdint.h>

#include "frame.h"
#include "gpu.h"
#include "skipping.h"
#include "storage.h"

typedef struct vxl_path_state {
    vxl_gpu *gpu;
    const vxl_skipping_state *skipping; /* whose min-max grid bounds the samples */
    const vxl_storage_state *storage;
    GLuint majorant_tex;
    const float *minmax_src;            /* the grid the texture was derived from (released with the volume) */
    uint64_t key;                       /* the classification and whole_table it was derived under */
    uint64_t bytes;                     /* what majorant_tex holds (its holding) */
} vxl_path_state;

void vxl_path_init(vxl_path_state *s, vxl_gpu *g, const vxl_skipping_state *sk, const vxl_storage_state *st);
/* With the volume: the grid goes with it. */
void vxl_path_release(vxl_path_state *s);
/* For a PATH frame, after vxl_skipping_prepare: the majorant on
 * VXL_MAJORANT_UNIT and the tracer's uniforms on prog. */
int vxl_path_bind(vxl_path_state *s, const vxl_frame *f, GLuint prog);

#endif
