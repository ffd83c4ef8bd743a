/* gradients.h - the derived volumes the gradient filters sample: precomputed
 * gradients (precompute.c over the whole texture; paged_gradients.c per
 * brick) and cubic B-spline coefficients (bspline.c; paged_bspline.c). Both
 * depend only on the volume data (and the gradient store): rebuilt on
 * set_volume or a format change, never per frame. Each is registered with
 * the storage as a derived volume (storage.h, vxl_derived), which runs it
 * over the whole volume or per brick, and with the budget as a holder
 * (holdings.h). Each state frees only its own. */
#ifndef VXL_GRADIENTS_H
#define VXL_GRADIENTS_H

#include <stdint.h>

#include "gpu.h"
#include "lod.h"
#include "storage.h"

typedef struct vxl_gradient_state {
    vxl_gpu *gpu;              /* the GL services */
    vxl_storage_state *storage; /* the volume the gradients are derived from */
    GLuint tex;
    GLuint page_tex;           /* bricked: the gradient pool's page table */
    uint32_t pool_dims[3];
    int store;                 /* VXL_GRADIENT_STORE_* of tex */
    float max;                 /* largest |gradient| (value per voxel): tex holds g / max */
    uint64_t bytes;
    uint8_t *covered;          /* bricked: per page brick of `level`, 1 if in the gradient pool */
    uint32_t level;
    float max_level[VXL_LOD_LEVELS]; /* bricked: the whole level's maximum from the CPU bricks, < 0 unknown */
} vxl_gradient_state;

typedef struct vxl_bspline_state {
    vxl_gpu *gpu;
    vxl_storage_state *storage;
    GLuint tex, page_tex;      /* bricked: a pool of coefficient bricks and its page table */
    uint32_t pool_dims[3];
    uint8_t *covered;          /* bricked: per page brick of `level`, 1 if in the coefficient pool */
    uint32_t level;
    uint64_t bytes;
} vxl_bspline_state;

/* precompute.c: wires gr to the GL services and the storage, and registers
 * it with both (derived volume VXL_DERIVED_GRADIENTS, holder VXL_HOLD_GRADIENTS). */
void vxl_gradients_init(vxl_gradient_state *gr, vxl_gpu *g, vxl_storage_state *st);
int vxl_gradients_ensure(vxl_gradient_state *gr, int store);
/* The blur, max and store programs of precomputed gradients (paged: bricked
 * storage), after asking the budget (budget.h) for `need` bytes: the gradients' own, transient blur included. */
int vxl_gradient_programs(vxl_gradient_state *gr, int paged, int store, uint64_t need, GLuint progs[3]);
void vxl_gradients_release(vxl_gradient_state *gr);
/* Releases, and forgets what was known about the volume (the largest gradient per level). */
void vxl_gradients_forget_volume(vxl_gradient_state *gr);

/* bspline.c: as vxl_gradients_init (VXL_DERIVED_BSPLINE, VXL_HOLD_BSPLINE). */
void vxl_bspline_init(vxl_bspline_state *bs, vxl_gpu *g, vxl_storage_state *st);
int vxl_bspline_ensure(vxl_bspline_state *bs);
void vxl_bspline_release(vxl_bspline_state *bs);

/* paged_gradients.c, paged_bspline.c: the derived pools of bricked storage
 * (precomputed gradients, cubic coefficients). make_room(room), when given,
 * runs right before a pool is (re)built: the storage decides what else goes. */
int vxl_paged_gradients_ensure(vxl_gradient_state *gr, int store, void (*make_room)(void *room), void *room);
int vxl_paged_bspline_ensure(vxl_bspline_state *bs, void (*make_room)(void *room), void *room);
/* Bytes the cubic / precomputed pool of `level` needs for the last frame's
 * visibility (UINT64_MAX: over the texture limit); fills want (a mask of the
 * level's page count) and *count. */
uint64_t vxl_paged_bspline_bytes(const vxl_bspline_state *bs, uint32_t level, uint8_t *want, uint32_t *count);
uint64_t vxl_paged_gradient_bytes(const vxl_gradient_state *gr, uint32_t level, int store, uint8_t *want,
                                  uint32_t *count);

#endif
