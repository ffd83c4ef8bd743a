/* vdb_write.h - the classified grids (vxl_classified_grid's density and
 * colour) as an OpenVDB file, and the stream that carries them to the
 * helper process voxlight-write-vdb (helper_write_vdb.c), which alone links
 * libopenvdb: the library links only the C runtime.
 *
 * The stream, on the helper's standard input, native byte order (the host
 * and the helper run on one machine):
 *   8 bytes     "VXLVDBW1"
 *   uint32 x 3  dims: cells per axis, each >= 1
 *   double x 16 index -> world, column-major (vxl_grid_info.index_to_world;
 *               any affine map with a non-zero determinant)
 *   float x n   density per cell, x fastest (n = the dims' product), >= 0
 *   float x 3n  linear RGB per cell
 * and nothing after. The output path is the helper's one argument. On
 * success the helper exits 0 and prints nothing; on failure it exits
 * non-zero with one line on standard error saying why. */
#ifndef VXL_VDB_WRITE_H
#define VXL_VDB_WRITE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define VXL_VDB_STREAM_MAGIC "VXLVDBW1"

/* Writes a float grid "density" (a fog volume) and a vec3 grid "color" to
 * path, each active where the density is above 0 (empty cells are the
 * background, 0, so the file stays sparse), both with the index -> world
 * transform m. Returns 0, or non-zero with a message in err. */
int vxl_vdb_write(const char *path, const uint32_t dims[3], const double m[16], const float *density,
                  const float *rgb, char *err, size_t err_size);

#ifdef __cplusplus
}
#endif
#endif
