/* transfer.h - transfer-function presets and the window that maps data onto
 * a table. Tables are straight RGBA; alpha is opacity per voxel of path. */
#ifndef VXL_TRANSFER_H
#define VXL_TRANSFER_H

#include <stdint.h>

#define VXL_PRESET_TABLE_SIZE 256

/* Fills rgba[VXL_PRESET_TABLE_SIZE*4] for a preset (VXL_PRESET_AUTO must be
 * resolved first). Returns 0 for an unknown preset. */
int vxl_preset_table(uint32_t preset, float *rgba);

/* Resolves AUTO from the data range (CT if it reaches Hounsfield air). */
uint32_t vxl_preset_resolve(uint32_t preset, double value_min, double value_max);

/* The default window of a preset for data in [value_min, value_max]. */
void vxl_preset_window(uint32_t preset, double value_min, double value_max, double *lo, double *hi);

#endif
