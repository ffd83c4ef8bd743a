/* cutaway.h - the GL side of a frame's cutaways (docs/cutaways.md).
 * Clip planes and the crop box are uniforms of the ray caster
 * (shaders/lib/cut.glsl narrows each ray to what they keep). Cutter meshes
 * are depth-peeled from the camera every frame: their triangles are
 * rasterised (render/cut_peel.*) into a buffer of up to VXL_CUT_LAYERS
 * crossings per pixel (planar view depth, the face's normal, the cutter),
 * which the ray caster sorts into the intervals it keeps. A pixel with more
 * crossings than that is over-full: its ray is dropped (drawn empty), so a
 * lost crossing never shows tissue a cutter should remove. */
#ifndef VXL_CUTAWAY_H
#define VXL_CUTAWAY_H

#include <stdint.h>

#include "frame.h"
#include "gpu.h"

#define VXL_CUT_LAYERS 8 /* crossings kept per pixel: = CUT_LAYERS in shaders/lib/cut.glsl */

typedef struct vxl_cut_state {
    vxl_gpu *gpu;
    GLuint layers;          /* SSBO: per pixel a count, then VXL_CUT_LAYERS crossings of 2 words */
    GLuint fbo, target;     /* the peel's framebuffer: an R8 target nothing is written to (no colour) */
    GLuint vao, vbo;        /* the cutters' triangles, 3 corners each: world xyz, normal xyz, cutter */
    uint32_t width, height; /* of the layers and the target */
    uint64_t vbo_bytes;     /* allocated vertex buffer */
    uint64_t bytes;         /* everything held, for the budget */
} vxl_cut_state;

/* Wires s to the GL services and registers its bytes with the budget. */
void vxl_cut_init(vxl_cut_state *s, vxl_gpu *g);
/* The ray caster's program flags frame f needs (VXL_FLAG_CUT_*): 0 without cutaways. */
uint32_t vxl_cut_flags(const vxl_frame *f);
/* Peels f's cutter meshes into the layers (nothing for a frame without
 * cutters, whose layers are released). Uses a program of its own and its
 * own framebuffer and vertex array: call it before the ray caster's
 * program is bound. */
int vxl_cut_prepare(vxl_cut_state *s, const vxl_frame *f);
/* The ray caster's cutaway uniforms and the layers, on prog (in use). */
void vxl_cut_bind(vxl_cut_state *s, GLuint prog, const vxl_frame *f);
void vxl_cut_release(vxl_cut_state *s);

#endif
