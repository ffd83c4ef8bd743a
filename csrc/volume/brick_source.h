/* brick_source.h - a volume read on demand (docs/streaming.md).
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
#include "voxlight.h"

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
    /* Holders besides the volume (0 from calloc: the volume alone). A
     * renderer that streams from s retains it, since the caller may destroy
     * the vxl_volume after set_volume (voxlight.h). Atomic, as bytes_read. */
    uint32_t refs;
};

/* What every read checks first: level < n_levels and the box lo .. lo +
 * size - 1 non-empty and inside that level's dims; else a vxl_fail. */
int vxl_brick_source_check_box(const vxl_brick_source *s, uint32_t level, const uint32_t lo[3],
                               const uint32_t size[3], vxl_err *e);

/* One more holder of s: each retain is matched by one vxl_brick_source_free. */
void vxl_brick_source_retain(vxl_brick_source *s);
/* Lets go of s; the last holder closes it (its ops' close, then the index
 * and s itself); NULL is a no-op. */
void vxl_brick_source_free(vxl_brick_source *s);

/* ---- shared by every source (brick_source.c, brick_levels.c,
 * memory_source.c) ---- */

#define VXL_SOURCE_INDEX_BRICK 8                 /* the index brick when the grid fits the cap below */
#define VXL_SOURCE_INDEX_MAX_BYTES (32ull << 20) /* past it the index brick doubles (16, 32, ...): a
                                                    24 GB file keeps a few MB of index, not 400 MB.
                                                    A brick of 2^k x 8 covers 8^3 sub-bricks, so its
                                                    min-max bounds each of theirs (conservative). */
#define VXL_SOURCE_KEEP_LEVEL_BYTES (64ull << 20) /* coarse levels up to this size stay in memory */

/* The index brick for a level-0 grid of dims: VXL_SOURCE_INDEX_BRICK, doubled
 * until 2 floats per brick fit VXL_SOURCE_INDEX_MAX_BYTES. */
uint32_t vxl_source_index_brick(const uint32_t dims[3]);

/* How many levels a source of dims offers: halving until the largest axis
 * is <= 32 voxels, at most VXL_SOURCE_MAX_LEVELS. */
uint32_t vxl_source_level_count(const uint32_t dims[3]);

/* Fills s->n_levels (clamped to 1..VXL_SOURCE_MAX_LEVELS) and
 * s->level_dims (level k: ceil(dims / 2^k)). */
void vxl_brick_source_set_levels(vxl_brick_source *s, const uint32_t dims[3], uint32_t n_levels);

/* The index built one z slice at a time, in z order (0 .. dims[2]-1, each
 * once), from level-0 texels: what a source's first pass over its data
 * calls. Equal, float for float, to vxl_bricks_minmax_cpu over the whole
 * volume (storage/paging.c): min and max of each brick plus a one-voxel
 * apron, normalised integer texels as code / (2^bits - 1). Memory: the
 * index and one row of bricks, never a slab of voxels. */
typedef struct vxl_index_build {
    uint32_t dims[3], texture_bits, brick, grid[3];
    float *minmax;      /* grid product x 2, the result */
    float *slice;       /* 2 x grid[0] x grid[1]: the current slice's row of bricks */
} vxl_index_build;

int vxl_index_build_begin(vxl_index_build *b, const uint32_t dims[3], uint32_t texture_bits, uint32_t brick,
                          vxl_err *e);
/* Slice z: dims[0] x dims[1] texels, x fastest. */
void vxl_index_build_slice(vxl_index_build *b, uint32_t z, const void *texels);
/* The same where only the rows y with data[y] != 0 are read: the others
 * hold `value` throughout (holes of a sparse file), costing O(bricks) per
 * row instead of O(voxels). */
void vxl_index_build_slice_rows(vxl_index_build *b, uint32_t z, const void *texels, const uint8_t *data,
                                double value);
/* Slice z holds one value throughout (a hole of a sparse file): as
 * vxl_index_build_slice on a slice of that texel, in O(bricks). value: the
 * texel as vxl_index_build reads it (code / (2^bits - 1), or the float). */
void vxl_index_build_const(vxl_index_build *b, uint32_t z, double value);
/* Hands the finished index to s (index_brick, index_dims, minmax; adds its
 * bytes to resident_bytes) and frees the rest of b. */
void vxl_index_build_finish(vxl_index_build *b, vxl_brick_source *s);
void vxl_index_build_free(vxl_index_build *b);

/* Progress of a long pass: calls opt->progress (when the options carry one)
 * with fraction and stage; VXL_ERR_CANCELLED (with a message) when it asks
 * to stop. */
int vxl_source_progress(const vxl_load_options *opt, double fraction, const char *stage, vxl_err *e);

/* The index of a source that can already read level 0 (memory, OME-Zarr,
 * cache): reads it through s->ops->read in z slabs (bounded memory),
 * reporting progress through opt (may be NULL). Sets index_brick,
 * index_dims and minmax. */
int vxl_brick_source_build_index(vxl_brick_source *s, const vxl_load_options *opt, vxl_err *e);

/* A source over a copy of whole's texels (tests, and a volume handed over
 * from memory): n_levels (1..VXL_SOURCE_MAX_LEVELS; 0 = vxl_source_level_count)
 * levels, each the 2x2x2 mean of the one before as vxl_volume_downsample2
 * (storage/lod.c) computes it, bit for bit; the index built. whole must
 * have texels. In memory_source.c. */
int vxl_brick_source_from_volume(const vxl_volume *whole, uint32_t n_levels, vxl_brick_source **out,
                                 vxl_err *e);

#endif
