/* classification.h - classification caches (classification.c): the
 * pre-classified volume (RGBA8, keyed by the classification) and the
 * pre-integration table (keyed by the classification, the step and the
 * table size). */
#ifndef VXL_CLASSIFICATION_H
#define VXL_CLASSIFICATION_H

#include <stdint.h>

#include "frame.h"
#include "gpu.h"
#include "storage.h"

typedef struct vxl_classification_state {
    vxl_gpu *gpu;               /* the GL services */
    vxl_storage_state *storage; /* the volume classified texel for texel */
    GLuint classified_tex, preint_tex;
    uint64_t classified_key, preint_key;
    uint64_t classified_bytes;
    uint32_t classified_dims[3];
} vxl_classification_state;

/* Wires cl to the GL services and the storage; registers holder VXL_HOLD_CLASSIFIED. */
void vxl_classification_init(vxl_classification_state *cl, vxl_gpu *g, vxl_storage_state *st);
int vxl_classification_prepare(vxl_classification_state *cl, const vxl_frame *f);
void vxl_classification_release(vxl_classification_state *cl);

#endif
