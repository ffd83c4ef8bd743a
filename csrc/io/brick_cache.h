/* brick_cache.h - gzip/zlib-compressed volumes read on demand
 * (docs/streaming.md "The brick cache"). A .nii.gz (or gzip NRRD or zlib
 * MetaImage data, from layout->compressed_start) cannot seek, so the first
 * open streams through it once and writes a bricked cache file: the voxels
 * already in texture format, cut into bricks compressed one by one, with
 * the skipping index and a pyramid of 2x means. Later opens read the cache
 * by offset. The cache is keyed by the source's size, mtime and header (and
 * how its voxels are read), so a changed source rebuilds it; a damaged
 * cache is rebuilt, never trusted. */
#ifndef VXL_BRICK_CACHE_H
#define VXL_BRICK_CACHE_H

#include <stdint.h>

#include "brick_source.h"
#include "error.h"
#include "raw_layout.h"
#include "volume.h"

/* Opens (building first when missing, stale or damaged) the bricked cache
 * of layout->path's chosen frame, in opt->cache_dir, else beside the source,
 * else $XDG_CACHE_HOME/voxlight (~/.cache/voxlight) when the source's folder
 * is not writable. Building reports progress through opt->progress and is
 * cancelled (VXL_ERR_CANCELLED) when it returns nonzero; a cancelled or
 * failed build leaves no file behind. opt may be NULL. */
int vxl_brick_cache_open(const vxl_raw_layout *layout, const vxl_load_options *opt, vxl_brick_source **out,
                         vxl_err *e);

/* What the cache knows beyond the brick source's fields. */
typedef struct vxl_brick_cache_info {
    double value_min, value_max; /* finite data range, as vxl_volume_build's */
    double tex_lo, tex_hi;       /* data value = tex_lo + t * (tex_hi - tex_lo) */
    uint64_t nan_count, inf_count;
    uint32_t brick;              /* the cache's brick edge in voxels */
    int built;                   /* 1: this open wrote the cache (the first open, or a rebuild) */
    const char *path;            /* the cache file (valid while the source is open) */
} vxl_brick_cache_info;

/* Fills out for a source made by vxl_brick_cache_open; VXL_ERR_INVALID_ARGUMENT for any other. */
int vxl_brick_cache_get_info(const vxl_brick_source *s, vxl_brick_cache_info *out, vxl_err *e);

/* Sets v's value fields (tex_lo/hi, value_min/max, nan/inf counts) from a
 * cache source, for the loader that wraps it in a streamed vxl_volume. */
int vxl_brick_cache_describe(const vxl_brick_source *s, vxl_volume *v, vxl_err *e);

/* How a cache is cut; vxl_brick_cache_open uses the defaults (tests use
 * small values so small volumes get many bricks and levels). */
typedef struct vxl_brick_cache_tuning {
    uint32_t brick;           /* largest brick edge, halved (down to 8) while a slab of that
                                 many slices exceeds slab_bytes; 0 = 32 */
    uint64_t slab_bytes;      /* 0 = 128 MiB */
    uint64_t coarsest_bytes;  /* levels are added until one holds at most this many texel
                                 bytes (or VXL_SOURCE_MAX_LEVELS); 0 = vxl_source_level_count,
                                 as every source (down to 32 voxels on the longest axis) */
} vxl_brick_cache_tuning;

int vxl_brick_cache_open_tuned(const vxl_raw_layout *layout, const vxl_load_options *opt,
                               const vxl_brick_cache_tuning *tuning, vxl_brick_source **out, vxl_err *e);

/* Between brick_cache.c and its writer and reader (brick_cache_write.c,
 * brick_cache_read.c); t is filled (no zeros). */
int vxl_brick_cache_write(const vxl_raw_layout *l, const vxl_load_options *opt, const vxl_brick_cache_tuning *t,
                          const char *cache_path, vxl_err *e);
/* Opens the cache file at path as a brick source. l NULL: no key check (the
 * fuzz target); else a cache of another source or read is an error. */
int vxl_brick_cache_read_open(const char *path, const vxl_raw_layout *l, uint32_t max_dim, vxl_brick_source **out,
                              vxl_err *e);
/* Marks a source as the cache this open has just built (vxl_brick_cache_info.built). */
void vxl_brick_cache_mark_built(vxl_brick_source *s);

#endif
