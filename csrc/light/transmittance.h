/* transmittance.h - the volume's shadow on the scene
 * (vxl_scene_transmittance): for every pixel of a frame's scene depth, the
 * transmittance from that scene point to one light through the volume, read
 * from the light's illumination volume (illumination.h) where the point's
 * path to the light enters the volume's box (at the point itself when it
 * lies inside), so it is the same light the volume's own samples get, mesh
 * shadows included. 1 where the path misses the box and where the depth is
 * +inf (no geometry), NaN or not positive. By
 * shaders/compute/scene_transmittance.comp. */
#ifndef VXL_TRANSMITTANCE_H
#define VXL_TRANSMITTANCE_H

#include "frame.h"
#include "illumination.h"

/* Needs s prepared for f (vxl_illumination_prepare, a shading model with
 * illumination volumes) and f->scene_depth; light < f->light_count. out:
 * f->width * f->height floats, row 0 = bottom. */
int vxl_scene_transmittance_pass(vxl_illumination_state *s, const vxl_frame *f, int light, float *out);

#endif
