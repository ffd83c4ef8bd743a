/* reference.h - what the reference renderer's files share (reference.c: the
 * primary rays and Phong; reference_light.c: shadows, occlusion and
 * scattering, voxlight.h's VXL_SHADING_*). Internal to the ground truth. */
#ifndef VXL_REFERENCE_H
#define VXL_REFERENCE_H

#include "frame.h"
#include "volume.h"
#include "voxlight_dev.h"

typedef struct ref_ctx {
    const vxl_phantom_desc *d;
    const vxl_volume *vol;
    const vxl_frame *f;
    double inv_mvp[16], mv[16], normal[9];
    double inv_model[16];       /* world -> voxel */
    double step;                /* primary rays, voxels */
} ref_ctx;

/* The opacity of a sample at voxel-space point p for a segment of `step`
 * voxels, as the ray caster classifies and composites it (transfer function,
 * classification mode, gradient opacity); 0 where it is empty. col receives
 * the classified colour (straight; col[3] the table's opacity), g the
 * analytic gradient and *gm its magnitude in normalised value per voxel. */
double vxl_ref_sample(const ref_ctx *c, const double p[3], double step, double col[4], double g[3], double *gm);

/* SHADOWED and SCATTER shading of one sample (VXL_SHADING_*): rgb in and
 * out, g its voxel-space gradient, gm its magnitude (normalised value per
 * voxel), p its voxel-space position, pos its view-space position, v the
 * unit vector towards the eye in view space. */
void vxl_ref_shade_lit(const ref_ctx *c, double rgb[3], const double g[3], double gm, const double p[3],
                       const double pos[3], const double v[3]);

#endif
