/* storage_derived.c - "build a derived volume" (precomputed gradients, cubic
 * B-spline coefficients) as the storage tables run it: the deriving
 * subsystem registers its kernels (storage.h, vxl_derived), the storage
 * runs them over the whole texture or per brick. Storage that pages is
 * short of memory, so one derived pool is kept at a time: building one lets
 * the others go. Each subsystem frees only its own; the policy lives here. */

#include "storage.h"

int vxl_whole_derive(vxl_storage_state *st, uint32_t which, int arg)
{
    const vxl_derived *d = &st->derived[which];
    return d->whole(d->state, arg);
}

typedef struct eviction {
    vxl_storage_state *st;
    uint32_t keep;
} eviction;

/* Every derived pool but the one being built lets go. */
static void make_room(void *room)
{
    const eviction *e = room;
    for (uint32_t k = 0; k < VXL_DERIVED_COUNT; k++)
        if (k != e->keep && e->st->derived[k].release) e->st->derived[k].release(e->st->derived[k].state);
}

int vxl_paged_derive(vxl_storage_state *st, uint32_t which, int arg)
{
    eviction e = {st, which};
    const vxl_derived *d = &st->derived[which];
    return d->per_brick(d->state, arg, make_room, &e);
}

/* Bytes a frame derives from the pool of `level` (pool_part bytes): the
 * derived filter's pool (cubic coefficients, precomputed gradients) and the
 * pre-classified pool, so the level chosen fits all of them. */
uint64_t vxl_paged_derived_bytes(const vxl_storage_state *st, const vxl_frame *f, uint32_t level, uint64_t pool_part,
                                 uint8_t *scratch)
{
    if (!f) return 0;
    const int which = vxl_derived_for_filter(vxl_frame_filter(f));
    const vxl_derived *d = which < 0 ? NULL : &st->derived[which];
    uint64_t b = d ? d->pool_bytes(d->state, level, (int)f->store, scratch, NULL) : 0;
    if (b != UINT64_MAX && f->classify == VXL_CLASSIFY_PRE) b += pool_part / st->levels[level].bytes_per_voxel * 4;
    return b;
}
