/* brick_source.h - a volume read on demand (issue 21, docs/streaming.md).
 * A streamed vxl_volume has no texels: its `source` reads any box of voxels
 * of any resolution level, already in the volume's texture format, when the
 * GL side (or a pass over the data) asks for it. What a source is made from
 * (a file read by offset, a bricked cache of a .nii.gz, an OME-Zarr store,
 * a volume in memory for the tests) is hidden behind the table below, as the
 * storage modes are behind storage.h. CPU only, no GL.
 *
 * The index (min-max per index brick of the full-resolution level, with a
 * one-voxel apron, as vxl_bricks.minmax) is filled when the source is made,
 * so skipping and the sparse plan need no pass over the data later. */
#ifndef VXL_BRICK_SOURCE_H
#define VXL_BRICK_SOURCE_H

#include <stdint.h>

#include "error.h"

#define VXL_SOURCE_MAX_LEVELS 8 /* full resolution plus up to 7 coarser levels, each 2x per axis */

typedef struct vxl_brick_source vxl_brick_source;

typedef struct vxl_brick_source_ops {
    /* Reads the voxels lo .. lo + size - 1 (inside level `level`'s dims) of
     * that level into out, in the volume's texture format (8/16-bit unsigned
     * normalised or float in [0, 1], texture_bits), x fastest. Thread-safe:
     * the renderer's loader thread and the caller's thread may read at once.
     * Adds what it read from disk to bytes_read. */
    int (*read)(vxl_brick_source *s, uint32_t level, const uint32_t lo[3], const uint32_t size[3], void *out,
                vxl_err *e);
    /* Frees ctx (files, caches); vxl_brick_source_free frees the rest. */
    void (*close)(vxl_brick_source *s);
} vxl_brick_source_ops;

struct vxl_brick_source {
    const vxl_brick_source_ops *ops;
    void *ctx;
    uint32_t texture_bits;                       /* 8, 16 or 32, as the volume's */
    uint32_t n_levels;                           /* >= 1; level k is 2^k times coarser per axis */
    uint32_t level_dims[VXL_SOURCE_MAX_LEVELS][3]; /* level k: ceil(dims / 2^k) */
    /* The index: per brick of index_brick voxels of level 0, the min and max
     * normalised texel over the brick and a one-voxel apron (2 floats per
     * brick, x fastest), the grid vxl_bricks_minmax_cpu would give. */
    uint32_t index_brick;
    uint32_t index_dims[3];
    float *minmax;
    uint64_t bytes_read;                         /* from the file or cache, all readers together: add with
                                                    __atomic_fetch_add (this header is read by C++ too) */
    uint64_t resident_bytes;                     /* CPU bytes held: index, caches, ctx */
};

/* Closes s (its ops' close, then the index and s itself); NULL is a no-op. */
void vxl_brick_source_free(vxl_brick_source *s);

#endif
