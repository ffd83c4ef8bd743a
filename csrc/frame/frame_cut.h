/* frame_cut.h - a frame's cutaways (voxlight.h's vxl_cutaway)
 * resolved against the volume: clip planes and the crop box in voxel space,
 * where the ray caster marches, and the cutter meshes checked. Pure CPU;
 * the reference renderer clips its rays with the same numbers
 * (vxl_frame_cut_interval) that the GL side hands raycast.frag
 * (shaders/lib/cut.glsl). */
#ifndef VXL_FRAME_CUT_H
#define VXL_FRAME_CUT_H

#include <stdint.h>

#include "error.h"
#include "voxlight.h"

typedef struct vxl_frame_cutter {
    uint32_t remove_outside;
    const float *vertices;      /* the caller's: world xyz per vertex */
    const uint32_t *indices;    /* the caller's: 3 per triangle, checked < vertex_count */
    uint32_t vertex_count, triangle_count;
} vxl_frame_cutter;

typedef struct vxl_frame_cut {
    int any;                    /* something is cut: planes, a crop box or cutters */
    int caps;                   /* cut surfaces are capped (caps_off == 0) */
    uint32_t plane_count;
    /* voxel space, scaled so that dot(plane.xyz, p) + plane.w is the signed
     * world distance of voxel point p from the caller's plane: kept where it
     * is >= 0, and <= thickness when thickness > 0 (a slab) */
    double plane[VXL_MAX_CLIP_PLANES][4];
    double thickness[VXL_MAX_CLIP_PLANES];
    int has_crop;
    double crop[16];            /* voxel -> box space, column-major: kept inside [-1, 1]^3 */
    uint32_t cutter_count;
    vxl_frame_cutter cutters[VXL_MAX_CUTTERS];
} vxl_frame_cut;

/* Validates p->cutaway into *c, naming the field at fault; model is the
 * frame's voxel -> world matrix, technique its VXL_TECHNIQUE_* (the slicing
 * techniques do not cut). Part of vxl_frame_resolve. */
int vxl_frame_cut_resolve(vxl_frame_cut *c, const vxl_render_params *p, const double model[16], uint32_t technique,
                          vxl_err *e);

/* Narrows [*t0, *t1] of the ray o + t dir (voxel space) to the part the
 * clip planes and the crop box keep. Returns 0 when nothing is left. cap
 * receives the gradient-space normal of the cut surface the ray enters the
 * kept part through at the new *t0 (the gradient of the plane's or box
 * face's function in voxel space, as a data gradient would be), or zero
 * when *t0 did not move. Cutters are not looked at. */
/* The clip planes as the shaders take them (u_cut_planes, u_cut_thickness):
 * floats, slots past plane_count zero. */
void vxl_frame_cut_plane_floats(const vxl_frame_cut *c, float planes[VXL_MAX_CLIP_PLANES][4],
                                float thickness[VXL_MAX_CLIP_PLANES]);

int vxl_frame_cut_interval(const vxl_frame_cut *c, const double o[3], const double dir[3], double *t0, double *t1,
                           double cap[3]);

/* Whether the clip planes and the crop box keep voxel-space point p (the
 * same tests as vxl_frame_cut_interval, at a point): 1 kept, 0 cut away.
 * Cutters are not looked at. */
int vxl_frame_cut_keeps(const vxl_frame_cut *c, const double p[3]);

#endif
