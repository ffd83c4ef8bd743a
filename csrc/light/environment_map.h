/* environment_map.h - the World's latitude-longitude map (voxlight.h's
 * vxl_environment) reduced on the CPU to VXL_ENV_CELLS direction cells of
 * equal solid angle: VXL_ENV_BANDS bands of equal height in z (equal area,
 * Archimedes), each cut into VXL_ENV_SECTORS sectors of world azimuth. A
 * cell's radiance is the solid-angle-weighted mean of the map over it, so a
 * uniform map gives every cell its colour, and the irradiance volume
 * (illumination.comp's environment pass) weighs each cell by 1 / cells. */
#ifndef VXL_ENVIRONMENT_MAP_H
#define VXL_ENVIRONMENT_MAP_H

#include <stdint.h>

#include "gpu.h"

#define VXL_ENV_BANDS 4
#define VXL_ENV_SECTORS 8
/* A cell's radiance saturates here: half float's largest, what the
 * irradiance volume can hold; anything near it saturates every sample. */
#define VXL_ENV_MAX_RADIANCE 65504.0
_Static_assert(VXL_ENV_BANDS * VXL_ENV_SECTORS == VXL_ENV_CELLS, "the cells are bands times sectors");

/* The world unit direction (towards the sky it stands for) of cell k's
 * centre: mid-height of its band, mid-azimuth of its sector. */
void vxl_environment_cell_direction(int k, double out[3]);

/* The map (width x height x 3 linear floats, row 0 the nadir; finite and
 * >= 0, as frame_environment.c checks) times strength, turned by
 * rotation_deg about +Z (voxlight.h's convention), averaged over each cell.
 * Maps coarser than 128 x 64 are read several times per pixel, so every
 * cell is covered whatever the map's size (a 1x1 map fills all of them).
 * Each cell saturates at VXL_ENV_MAX_RADIANCE. */
void vxl_environment_reduce(const float *rgb, uint32_t width, uint32_t height, float strength, float rotation_deg,
                            float out[VXL_ENV_CELLS][3]);

#endif
