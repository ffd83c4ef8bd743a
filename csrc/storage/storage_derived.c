/* storage_derived.c - the volumes bricked storage derives from its bricks
 * (precomputed gradients, cubic B-spline coefficients), as the storage
 * tables run them. Storage that pages is short of memory, so one derived
 * pool is kept at a time: building one lets the other go. Each subsystem
 * frees only its own; the policy lives here. */
#include "renderer_internal.h"

int vxl_paged_gradients(vxl_renderer *r, int store) { return vxl_paged_gradients_ensure(r, store, vxl_bspline_release); }

int vxl_paged_bspline(vxl_renderer *r) { return vxl_paged_bspline_ensure(r, vxl_gradients_release); }

/* Bytes a frame derives from the pool of `level` (pool_part bytes): the
 * derived filter's pool (cubic coefficients, precomputed gradients) and the
 * pre-classified pool, so the level chosen fits all of them. */
uint64_t vxl_paged_derived_bytes(const vxl_renderer *r, const vxl_frame *f, uint32_t level, uint64_t pool_part,
                                 uint8_t *scratch)
{
    if (!f) return 0;
    const uint32_t filter = vxl_frame_filter(f);
    uint64_t b = filter == VXL_FILTER_CUBIC         ? vxl_paged_bspline_bytes(r, level, scratch, NULL)
                 : filter == VXL_FILTER_PRECOMPUTED ? vxl_paged_gradient_bytes(r, level, (int)f->store, scratch, NULL)
                                                    : 0;
    if (b != UINT64_MAX && f->classify == VXL_CLASSIFY_PRE) b += pool_part / r->storage.levels[level].bytes_per_voxel * 4;
    return b;
}
