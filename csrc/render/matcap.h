/* matcap.h - the MatCap image (voxlight.h's vxl_matcap) on the
 * GL side: a 2D texture uploaded when its key changes (the caller's key, or
 * a hash of the pixels when that is 0), charged to the budget as a holding,
 * bound at VXL_MATCAP_UNIT for lib/matcap.glsl. */
#ifndef VXL_MATCAP_H
#define VXL_MATCAP_H

#include <stdint.h>

#include "frame.h"
#include "gpu.h"

typedef struct vxl_matcap_state {
    vxl_gpu *gpu;
    GLuint tex;
    uint64_t key;      /* of the image in tex */
    uint64_t bytes;    /* what tex holds (its holding) */
} vxl_matcap_state;

void vxl_matcap_init(vxl_matcap_state *m, vxl_gpu *g);
void vxl_matcap_release(vxl_matcap_state *m);
/* The key of f's MatCap: the caller's, or the pixels' hash (never 0). */
uint64_t vxl_matcap_key(const vxl_frame *f);
/* Uploads f's MatCap unless the same key is resident, binds it to
 * VXL_MATCAP_UNIT and sets prog's u_matcap; nothing when f has none. */
int vxl_matcap_prepare(vxl_matcap_state *m, const vxl_frame *f, GLuint prog);

#endif
