/* paging.h - bricked storage, CPU side (pure, no GL). The volume is cut into
 * page bricks of P^3 voxels; each brick is stored with a one-voxel ghost
 * border copied from its neighbours (the "over-represented sub-volumes" of
 * the table-based mapping), so hardware trilinear filtering inside a brick
 * reads exactly what it would read in one big texture. A brick whose voxels,
 * ghost included, all hold one value is stored as that value and nothing
 * else. The GL side (paged.c) packs the data bricks into a pool texture and
 * writes the page table the shader translates every sample through. */
#ifndef VXL_PAGING_H
#define VXL_PAGING_H

#include <stdint.h>

#include "bricks.h"
#include "error.h"
#include "volume.h"

#define VXL_PAGE_GHOST 1        /* trilinear reads floor(x) and floor(x)+1 of a position in the brick */
#define VXL_DEFAULT_PAGE_BRICK 32

typedef struct vxl_pages {
    uint32_t brick;             /* P: voxels per page brick edge, ghost excluded */
    uint32_t grid[3];           /* page bricks per axis */
    uint32_t bytes_per_voxel;   /* 1, 2 or 4, as the volume's texels */
    uint32_t n_data;            /* bricks that are not constant */
    int32_t *data_index;        /* per brick: its index in data, -1 = constant */
    float *low;                 /* per brick: the constant value, or the minimum (ghost included) */
    uint8_t *data;              /* n_data bricks of (P+2)^3 voxels, x fastest; NULL once dropped */
} vxl_pages;

/* Edge of a stored brick, ghost included. */
static inline uint32_t vxl_page_edge(const vxl_pages *pg) { return pg->brick + 2 * VXL_PAGE_GHOST; }
static inline uint64_t vxl_page_count(const vxl_pages *pg)
{
    return (uint64_t)pg->grid[0] * pg->grid[1] * pg->grid[2];
}

/* Cuts v into bricks of `brick` voxels (8, 16, 32 or 64). */
int vxl_pages_build(vxl_pages *pg, const vxl_volume *v, uint32_t brick, vxl_err *e);
void vxl_pages_free(vxl_pages *pg);
/* Copies page brick b (its grid position) of `brick` voxels with its ghost
 * border from texels of `dims` voxels into dst (edge^3 voxels, x fastest);
 * voxels outside the volume take the nearest edge voxel, as clamp-to-edge
 * sampling of one texture does. A voxel is bytes_per_voxel bytes copied as
 * one: one scalar, or several interleaved components (channel groups). */
void vxl_pages_copy_brick(const void *texels, const uint32_t dims[3], uint32_t bytes_per_voxel, uint32_t brick,
                          const uint32_t b[3], uint8_t *dst);

/* The value of a normalised integer texel, code / (2^bits - 1), in double
 * (the grid rounds it to float once). GL leaves the division's last bit to
 * the driver (llvmpipe's float is 1 ulp off this for some codes), so the
 * GPU grid is snapped to this one definition (skip/skipping.c). */
static inline double vxl_unorm_value(uint32_t code, uint32_t bits) { return code / (double)((1u << bits) - 1); }

/* The skipping grid's min-max: per brick of b->size voxels, the min and max
 * over the brick and a one-voxel apron each way, clamped to the volume
 * (every voxel a trilinear sample inside the brick's box reaches). The CPU
 * copy of brick_minmax.comp, bit for bit (tests/test_kernels.c), which
 * bricked storage needs at set_volume, before anything is on the GL side;
 * fills b->size, b->dims and b->minmax. */
int vxl_bricks_minmax_cpu(vxl_bricks *b, const vxl_volume *v, uint32_t size, vxl_err *e);

/* need[i] = 1 for every candidate brick a frame can read under the
 * occupancy in b (b->distance, 0 = occupied, on the full-resolution grid): a
 * brick within `reach` full-resolution voxels of an occupied skip brick,
 * since gradient taps reach that far from a visible sample. candidate NULL:
 * the data bricks; else candidate[i] != 0 (bricks of a pool derived from the
 * data, constant ones included). pg may be a coarser level whose voxels
 * cover `scale` full-resolution voxels per axis. all != 0 marks every
 * candidate (classifications occupancy cannot bound). Returns the count. */
uint32_t vxl_pages_needed(const vxl_pages *pg, const vxl_bricks *b, uint32_t reach, uint32_t scale, int all,
                          const uint8_t *candidate, uint8_t *need);

/* 1 if brick i and every brick within `voxels` voxels of it are constant
 * with one value: a filter reaching no farther sees a constant there. */
int vxl_pages_flat_around(const vxl_pages *pg, uint64_t i, uint32_t voxels);

/* Where the texels of data brick d lie: slot d of a 3D array of slots of
 * edge `edge` (ghost included), slots[0] x slots[1] x ... of them. The CPU
 * bricks of a vxl_pages are slots 1 x 1 x n_data; a pool read back from the
 * GL side is laid out as the pool. */
typedef struct vxl_brick_store {
    const uint8_t *texels;
    uint32_t slots[2];
    uint32_t edge, bytes_per_voxel;
} vxl_brick_store;

static inline vxl_brick_store vxl_pages_store(const vxl_pages *pg)
{
    vxl_brick_store s = {pg->data, {1, 1}, vxl_page_edge(pg), pg->bytes_per_voxel};
    return s;
}

/* The normalised values (as a sampler returns them) of the voxels lo + l,
 * l < size per axis, of the volume of `dims` voxels cut into pg, each
 * coordinate clamped into the volume; x fastest. */
void vxl_pages_gather(const vxl_pages *pg, const vxl_brick_store *s, const uint32_t dims[3], const int64_t lo[3],
                      const uint32_t size[3], float *out);

#endif
