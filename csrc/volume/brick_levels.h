/* brick_levels.h - the coarser levels of a brick source: each the
 * 2x2x2 mean of the level before, computed as vxl_volume_downsample2
 * (storage/lod.c) does, bit for bit (the same eight texels summed in the
 * same order in double, then rounded into the texel format), so a streamed
 * volume's level k equals the whole volume's. Slice by slice, so a pass
 * over a file larger than memory can build them holding two slices per
 * level. CPU only. */
#ifndef VXL_BRICK_LEVELS_H
#define VXL_BRICK_LEVELS_H

#include <stddef.h>
#include <stdint.h>

#include "brick_source.h"
#include "error.h"

/* One slice of the next level (ceil(w/2) x ceil(h/2) texels) from slices
 * z0 and z1 of this one (z1 = z0 where the level ends on an odd z). */
void vxl_downsample2_slice(uint32_t texture_bits, const void *s0, const void *s1, uint32_t w, uint32_t h, void *out);

/* ceil(dims/2) texels from a box of dims texels: the box must be aligned to
 * 2 voxels and end either on an even coordinate or at the level's end, so
 * clamping at its end is the level's own clamping. */
void vxl_downsample2_box(uint32_t texture_bits, const void *src, const uint32_t dims[3], void *out);

/* The texel stored where slice z0 holds value a throughout and z1 value b
 * (four of each summed, rounded as the slices are): two constant slices
 * make a constant slice. */
double vxl_downsample2_const(uint32_t texture_bits, double a, double b);

/* Texel value as a double: code / (2^bits - 1) or the float itself (as
 * vxl_volume_texel). */
double vxl_texel_at(uint32_t texture_bits, const void *texels, size_t i);
/* Stores value (in [0,1]) as a texel: lround(value * (2^bits - 1)) or float. */
void vxl_texel_store(uint32_t texture_bits, void *texels, size_t i, double value);

/* Levels 1 .. n_levels-1 built from level-0 slices fed in z order. A level
 * of at most keep_bytes is kept (whole, in memory); the others are only
 * passed through on the way to the coarser ones. */
typedef struct vxl_level_slice {
    uint8_t *texels;       /* one slice of the level (NULL when constant) */
    int is_const;
    double value;          /* the constant texel value */
    int full;              /* a slice is waiting for its z partner */
    uint32_t z;            /* next output z of the coarser level */
} vxl_level_slice;

typedef struct vxl_level_build {
    uint32_t texture_bits, n_levels;
    uint32_t dims[VXL_SOURCE_MAX_LEVELS][3];
    uint8_t *kept[VXL_SOURCE_MAX_LEVELS];       /* level k's texels, or NULL when not kept (k >= 1) */
    vxl_level_slice pending[VXL_SOURCE_MAX_LEVELS]; /* per level: the even slice waiting for its odd one */
    uint8_t *scratch[VXL_SOURCE_MAX_LEVELS];    /* per level: one slice (its output, or a constant spelled out) */
    uint64_t bytes;                             /* what it holds */
} vxl_level_build;

int vxl_level_build_begin(vxl_level_build *b, const uint32_t dims[3], uint32_t texture_bits, uint32_t n_levels,
                          uint64_t keep_bytes, vxl_err *e);
/* Level-0 slice z (texels, or NULL with is_const and value for a constant one). */
void vxl_level_build_slice(vxl_level_build *b, const void *texels, int is_const, double value);
/* Flushes the odd ends; the kept levels stay in b->kept (the caller takes
 * them, setting the pointers to NULL, before vxl_level_build_free). */
void vxl_level_build_finish(vxl_level_build *b);
void vxl_level_build_free(vxl_level_build *b);

/* Copies the box lo .. lo+size-1 of a level held whole (ldims texels) into out. */
void vxl_level_copy_box(uint32_t texture_bits, const uint8_t *level, const uint32_t ldims[3], const uint32_t lo[3],
                        const uint32_t size[3], void *out);

#endif
