/* slices.h - the slicing comparison modes (VXL_TECHNIQUE_SLICES2D
 * and SLICES3D): proxy polygons through the volume box, composited slice by
 * slice with the ray caster's classification, gradients and shading. Not a
 * default; the benchmark measures them against the ray caster. */
#ifndef VXL_SLICES_H
#define VXL_SLICES_H

#include "frame.h"
#include "renderer_internal.h"

/* VXL_OK when this frame's settings can be sliced; an error naming the
 * technique and what it cannot do otherwise. */
int vxl_slices_check(vxl_renderer *r, const vxl_frame *f);

/* Draws the slices of f->technique with prog (VXL_PROG_SLICES, its volume
 * textures and frame uniforms bound by render.c) into r's framebuffer, which
 * render.c cleared: colour and depth as the ray caster leaves them. */
int vxl_slices_draw(vxl_renderer *r, const vxl_frame *f, GLuint prog);

#endif
