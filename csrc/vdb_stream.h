/* vdb_stream.h - OpenVDB files are read in a separate process
 * (vdb_spawn.c starts build/voxlight-vdb-read, vdb_helper_main.c), because
 * Debian's libopenvdb aborts the whole process on some malformed files
 * before any check of ours can run (tests/fuzz/upstream/README.md), and
 * Blender's process must survive a corrupt import. This is what both sides
 * share: the in-process reader and the pipe protocol. */
#ifndef VXL_VDB_STREAM_H
#define VXL_VDB_STREAM_H

#include <stdint.h>

#include "error.h"
#include "voxlight.h"

/* The helper's file name; it sits next to libvoxlight.so. */
#define VXL_VDB_HELPER_NAME "voxlight-vdb-read"
/* Overrides where the helper is (tests, unusual installs). */
#define VXL_VDB_HELPER_ENV "VOXLIGHT_VDB_HELPER"
/* Overrides the helper's time limit in seconds (tests). */
#define VXL_VDB_TIMEOUT_ENV "VOXLIGHT_VDB_TIMEOUT"

#define VXL_VDB_MAGIC "VXLVDB1"
#define VXL_VDB_MSG_MAX 1024 /* longest error message the helper may send */

/* The helper writes this header to the pipe, then either msg_len bytes of
 * error message (status != 0) or nbytes of float32 voxels, x fastest.
 * Both ends are the same build on the same machine: native layout. */
typedef struct vxl_vdb_header {
    char magic[8];         /* VXL_VDB_MAGIC, NUL-padded */
    uint32_t status;       /* VXL_OK or the VXL_ERR_* of the failure */
    uint32_t dtype;        /* VXL_DTYPE_F32 */
    uint32_t dims[3];
    uint32_t msg_len;
    double spacing[3];
    double affine[16];     /* column-major voxel -> world */
    uint64_t nbytes;       /* voxel bytes that follow */
} vxl_vdb_header;

/* One dense scalar grid as read by OpenImageIO's OpenVDB reader. */
typedef struct vxl_vdb_grid {
    uint32_t dims[3];
    double spacing[3];
    double affine[16];
    float *voxels;         /* malloc'd dims product floats; free() it */
} vxl_vdb_grid;

/* The in-process read (vdb.cpp). Only the helper calls it: in a host
 * process an OpenVDB assertion would take the host down. */
int vxl_vdb_read_dense(const char *path, const vxl_load_options *opt, vxl_vdb_grid *out, vxl_err *e);

#endif
