/* preint.h - the pre-integration table: for a segment of `step` voxels whose
 * value goes linearly from table position x_f to x_b, the premultiplied
 * colour and opacity of the whole segment (Engel, Kraus and Ertl 2001). */
#ifndef VXL_PREINT_H
#define VXL_PREINT_H

#include <stdint.h>

/* tf: tf_size straight RGBA entries (alpha per voxel of path), sampled as a
 * GL_LINEAR texture; opacity_scale multiplies alpha. out: n*n*4 floats,
 * out[(b*n + f)*4 + c] for front index f and back index b (row = back).
 * O(n^2) from O(n) prefix integrals. Returns 0 on success, -1 on bad args
 * or memory. */
int vxl_preint_build(const float *tf, uint32_t tf_size, float opacity_scale, double step, uint32_t n, float *out);

#endif
