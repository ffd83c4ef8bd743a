/* storage.h - the storage interface. How the volume is held on the GL side
 * (dense: one texture; bricked, sparse, compressed: bricks in a pool behind a
 * page table, docs/storage.md) is one table of operations per mode. The rest
 * of the renderer calls the table of the volume in use and never asks which
 * mode it is: adding a mode is a new table (storage.c lists them). */
#ifndef VXL_STORAGE_H
#define VXL_STORAGE_H

#include <stdint.h>

#include "bricks.h"
#include "frame.h"
#include "gl_funcs.h"
#include "gpu.h"
#include "lod.h"
#include "paging.h"
#include "volume.h"
#include "voxlight.h"

typedef struct vxl_storage_state vxl_storage_state;

/* The volumes derived from the data that the storage builds (whole or per brick). */
enum { VXL_DERIVED_GRADIENTS, VXL_DERIVED_BSPLINE, VXL_DERIVED_COUNT };

/* The derived volume a gradient filter samples (VXL_DERIVED_*), -1 for none. */
static inline int vxl_derived_for_filter(uint32_t filter)
{
    return filter == VXL_FILTER_PRECOMPUTED ? VXL_DERIVED_GRADIENTS : filter == VXL_FILTER_CUBIC ? VXL_DERIVED_BSPLINE : -1;
}

/* A derived volume as the subsystem that computes it registers it with the
 * storage (gradients.h): "build a derived volume" is a storage operation
 * that runs the kernels its subsystem supplies, over the whole texture
 * (dense) or per brick into a pool with its own page table (bricked modes).
 * The storage never includes the deriving subsystem, and each frees only its
 * own: when bricked storage must make room for one pool it asks the others
 * to release theirs through these entries. */
typedef struct vxl_derived {
    void *state;               /* the deriving subsystem's own state */
    /* over one texture of the whole volume; arg: the gradient store, or unused */
    int (*whole)(void *state, int arg);
    /* per brick; make_room(room), when given, runs right before a pool is (re)built */
    int (*per_brick)(void *state, int arg, void (*make_room)(void *room), void *room);
    void (*release)(void *state);
    /* Bytes the pool of `level` needs for the last frame's visibility
     * (UINT64_MAX: over the texture limit); fills want (a mask of the
     * level's page count) and *count (may be NULL). */
    uint64_t (*pool_bytes)(const void *state, uint32_t level, int arg, uint8_t *want, uint32_t *count);
    /* Bricked: the pool's page table and size (0 when there is none), bound
     * for sampling on page_unit under the uniforms page_name and dims_name. */
    const GLuint *page_tex;
    const uint32_t *pool_dims;
    GLint page_unit;
    const char *page_name, *dims_name;
    /* Computed on the GL side from the pool (not from the CPU bricks): the
     * bricks within read_reach voxels of a visible sample, and support
     * voxels around those, must be resident. */
    int reads_pool;
    uint32_t support, read_reach;
} vxl_derived;

/* A volume made ready for the GL side (checked against the texture limit
 * and the budget, cut into bricks on the CPU) before the renderer lets go of
 * its current volume, so a failed set_volume loses nothing. */
typedef struct vxl_storage_plan {
    uint32_t mode;      /* VXL_STORAGE_* decided by the plan (AUTO resolved) */
    vxl_pages levels[VXL_LOD_LEVELS];
    uint32_t level_dims[VXL_LOD_LEVELS][3];
    uint32_t n_levels;
    vxl_bricks bricks;  /* the skipping grid's min-max (bricked modes: from the CPU voxels) */
    uint64_t bytes;     /* what the plan asked the budget for (GL side, at set_volume); what is
                           planned beside the volume (a multi-channel volume's channels) adds to it */
} vxl_storage_plan;

typedef struct vxl_storage_ops {
    /* Checks v and prepares what install uploads; `asked` may be AUTO. */
    int (*plan)(vxl_storage_state *st, const vxl_volume *v, uint32_t asked, vxl_storage_plan *out);
    /* Uploads the planned volume; takes the plan's bricks but leaves its
     * min-max grid, which the caller hands to skipping. */
    int (*install)(vxl_storage_state *st, const vxl_volume *v, vxl_storage_plan *plan);
    /* Refuses, with a message, filters and classifications the mode cannot serve. */
    int (*check_filter)(vxl_storage_state *st, uint32_t filter, uint32_t classify);
    /* Makes resident what frame f can read (f NULL: everything, for probes). */
    int (*prepare)(vxl_storage_state *st, const vxl_frame *f);
    /* Program flags (VXL_FLAG_*) of shaders that sample this volume. */
    uint32_t (*sample_flags)(const vxl_storage_state *st);
    /* Binds the values on VXL_VOLUME_UNIT and what translates samples, for prog. */
    void (*bind)(vxl_storage_state *st, GLuint prog);
    /* The texture holding the values texel for texel, and its size: what a
     * derived volume computed texel for texel (pre-classification) reads. */
    GLuint (*texels)(const vxl_storage_state *st, const uint32_t **dims);
    /* GL-side bytes of the volume (pool, page table, codes). */
    uint64_t (*resident_bytes)(const vxl_storage_state *st);
    /* The storage fields of the frame's stats. */
    void (*report)(const vxl_storage_state *st, vxl_render_stats *s);
    /* Builds derived volume `which` (VXL_DERIVED_*, arg as its entry
     * takes it) over the whole volume or per brick, as registered. */
    int (*derive)(vxl_storage_state *st, uint32_t which, int arg);
    /* Whether empty-space skipping's grid is needed whatever the frame asks
     * (the resident set follows it). */
    int needs_occupancy;
    /* Whether texels() is one texture of the volume's own size, so a pass
     * over the whole volume (the skipping grid's min-max, the gradient
     * bound) can read it; else the storage gives the min-max grid itself. */
    int one_texture;
    void (*release)(vxl_storage_state *st);
} vxl_storage_ops;

/* The tables: storage_dense.c, storage_bricked.c (bricked, sparse),
 * storage_compressed.c. */
extern const vxl_storage_ops vxl_storage_dense, vxl_storage_bricked, vxl_storage_sparse, vxl_storage_compressed;
/* storage_streamed.c: sparse storage of a streamed volume (v->source), whose
 * bricks come from the source on demand; the storage every streamed volume gets. */
extern const vxl_storage_ops vxl_storage_streamed;


/* The storage subsystem's state: the volume on the GL side and what holds
 * it. Dense: volume_tex. Bricked modes: samples go through the page table
 * into the pool; SPARSE keeps the CPU bricks (levels[].data) to make bricks
 * resident when the classification changes. */
struct vxl_storage_state {
    vxl_gpu *gpu;                 /* the GL services (gpu.h) */
    /* the volume on the GL side, set once installed; see set_volume for what depends on it */
    int has_volume;
    vxl_volume_geom geom;
    /* the skipping grid (min-max, occupancy) the resident set follows; owned by skipping */
    const vxl_bricks *grid;
    vxl_derived derived[VXL_DERIVED_COUNT]; /* registered by the deriving subsystems */
    const vxl_storage_ops *ops;   /* the table of the mode in use; NULL without a volume */
    uint32_t mode;                /* VXL_STORAGE_* in use; 0 without a volume */
    uint32_t request;             /* VXL_STORAGE_* asked for */
    uint32_t page_brick_request;  /* from the options; 0 = default */
    int compressed_domain;        /* from the options */
    GLuint volume_tex;            /* dense */
    uint64_t volume_bytes;
    vxl_pages levels[VXL_LOD_LEVELS]; /* [0] full resolution; coarser ones only when sparse */
    uint32_t level_dims[VXL_LOD_LEVELS][3];
    uint32_t n_levels, level;         /* level in the pool now (0 unless the budget forced a fallback) */
    uint64_t lod_wanted_bytes;        /* what full resolution would need when level > 0 */
    GLuint pool_tex, page_tex;
    uint32_t pool_dims[3];
    uint8_t *resident;            /* per page brick: 1 if its data is in the pool */
    float *page_entries;          /* RGBA per page brick, as uploaded */
    uint32_t pages_resident, pages_constant;
    uint64_t pool_bytes;
    uint64_t pool_generation;     /* counts pool uploads: what is derived from the pool texel for texel keys on it */
    /* What the last frame could see, for pools derived from the data
     * (gradients, coefficients): bricks within visible_reach voxels of an
     * occupied skip brick, or every brick (visible_all: bricked storage,
     * probes, classifications occupancy cannot bound). */
    uint32_t visible_reach;
    int visible_all;
    /* Compressed storage (compress.h): the codes of every data brick in
     * code_tex (R8UI, slot = data index) and their palettes in palette_tex
     * (16 rows of 256 per texel row). pool_tex is the linear cache the
     * needed bricks are decoded into (deferred filtering), or code_tex itself
     * when filtering in the compressed domain. */
    GLuint code_tex, palette_tex;
    uint32_t code_slots[3];
    uint64_t code_bytes;          /* code pool + palettes */
    double decode_ms;             /* the decode of this frame, 0 if none */
    /* Streamed volumes (storage_streamed.c): the pool is a cache
     * of bricks of every level read on demand by a loader thread. */
    struct vxl_stream *stream;
};

/* storage.c: starts the state on g; it reports its bytes to g's budget. */
void vxl_storage_init(vxl_storage_state *st, vxl_gpu *g);

/* storage.c: makes prog (used from here on) sample the volume the way the
 * ray caster does: the mode's bind, the volume unit and u_dims. The
 * filters' derived volumes are the caller's (render.c binds them). */
int vxl_storage_bind_sampling(vxl_storage_state *st, GLuint prog);

/* storage.c: frees what a plan holds (a plan that was not installed, or
 * what install left in it). */
void vxl_storage_plan_free(vxl_storage_plan *plan);
/* storage.c: the table of a mode (AUTO: the bricked table, whose plan
 * decides), NULL for an unknown mode. */
const vxl_storage_ops *vxl_storage_ops_for(uint32_t mode);
/* The table that serves v in `mode`: the streamed one for a streamed volume. */
const vxl_storage_ops *vxl_storage_ops_for_volume(const vxl_volume *v, uint32_t mode);
/* DENSE when asked, or (AUTO) when one texture fits the limit and budget;
 * else what was asked (AUTO: the bricked plan picks bricked or sparse). */
uint32_t vxl_storage_choose(const vxl_storage_state *st, const vxl_volume *v);

/* storage_pool.c: what every storage mode and every pool of bricks shares */
/* Serves every filter and classification (the check_filter of most modes). */
int vxl_storage_serves_all(vxl_storage_state *st, uint32_t filter, uint32_t classify);
/* Slots per axis for n bricks of edge e within the texture limit; 0 if they cannot fit. */
int vxl_pool_layout(const vxl_storage_state *st, uint32_t n, uint32_t edge, uint32_t slots[3]);
/* Where slot k of a pool of slots[0] x slots[1] x ... slots of edge e
 * begins, in texels (x fastest, as every pool is filled). */
static inline void vxl_slot_origin(uint32_t k, const uint32_t slots[3], uint32_t e, uint32_t o[3])
{
    o[0] = k % slots[0] * e;
    o[1] = k / slots[0] % slots[1] * e;
    o[2] = k / (slots[0] * slots[1]) * e;
}
/* Uploads a page table (RGBA32F, one texel per brick of pg: xyz where the
 * brick lies in its pool, w < 0 there, else its one value), creating *tex on
 * first use. */
void vxl_page_table_upload(vxl_storage_state *st, GLuint *tex, const vxl_pages *pg, const float *entries);
/* Runs prog over bricks first .. first + count - 1 of edge e (one
 * invocation per voxel, groups of 4^3), in chunks the dispatch limit allows
 * (sets u_first). */
void vxl_dispatch_bricks(vxl_storage_state *st, GLuint prog, uint32_t first, uint32_t count, uint32_t e);
/* The current level's bricks on the CPU: its own when kept, else (bricked)
 * the pool read back into *owned, which the caller frees. */
int vxl_paged_brick_store(vxl_storage_state *st, vxl_brick_store *s, uint8_t **owned);
/* Which bricks of `level` a pool derived from the data needs (not flat
 * within `support` voxels, readable within `read_reach` of a visible
 * sample), and whether one made for `covered` at `level` still serves. */
uint32_t vxl_paged_derived_want(const vxl_storage_state *st, uint32_t level, uint32_t support, uint32_t read_reach,
                                uint8_t *want);
int vxl_paged_derived_current(const vxl_storage_state *st, const uint8_t *covered, uint32_t level, const uint8_t *want);

/* paged.c: what the bricked modes (bricked, sparse, compressed) share on
 * the GL side; storage_bricked.c and storage_compressed.c make their tables. */
int vxl_paged_plan(vxl_storage_state *st, const vxl_volume *v, uint32_t asked, vxl_storage_plan *out);
/* Takes the plan's bricks (the page table's CPU side; nothing uploaded yet). */
int vxl_paged_adopt(vxl_storage_state *st, const vxl_volume *v, vxl_storage_plan *plan);
/* Uploads every data brick of the full level (bricked; the compressed
 * domain's code pool), then drops the CPU bricks. */
int vxl_paged_upload_all(vxl_storage_state *st);
/* Notes what frame f can see, for the derived pools (f NULL, iso opacity or
 * `every`: every brick), then (sparse) makes resident the bricks it can
 * read, at the finest level that fits the budget (f NULL: every data brick). */
void vxl_paged_see(vxl_storage_state *st, const vxl_frame *f, int every);
int vxl_paged_make_resident(vxl_storage_state *st, const vxl_frame *f);
void vxl_paged_release(vxl_storage_state *st);
/* storage_bricked.c: the operations the bricked modes share */
uint32_t vxl_paged_sample_flags(const vxl_storage_state *st);
void vxl_paged_bind(vxl_storage_state *st, GLuint prog);
GLuint vxl_paged_texels(const vxl_storage_state *st, const uint32_t **dims);
uint64_t vxl_paged_resident_bytes(const vxl_storage_state *st);
void vxl_paged_report(const vxl_storage_state *st, vxl_render_stats *s);
/* A bricked mode's table: what it does its own way, the rest shared. */
#define VXL_PAGED_OPS(install_, prepare_, check_filter_, sample_flags_, bind_)                                        \
    {                                                                                                                  \
        .plan = vxl_paged_plan, .install = install_, .check_filter = check_filter_, .prepare = prepare_,              \
        .sample_flags = sample_flags_, .bind = bind_, .texels = vxl_paged_texels,                                      \
        .resident_bytes = vxl_paged_resident_bytes, .report = vxl_paged_report, .derive = vxl_paged_derive,           \
        .needs_occupancy = 1, .release = vxl_paged_release                                                             \
    }
/* storage_derived.c: the derived volumes over the whole texture (dense), and
 * per brick (bricked modes: one pool at a time), and what a frame derives
 * from the pool of `level` (pool_part bytes) */
int vxl_whole_derive(vxl_storage_state *st, uint32_t which, int arg);
int vxl_paged_derive(vxl_storage_state *st, uint32_t which, int arg);
uint64_t vxl_paged_derived_bytes(const vxl_storage_state *st, const vxl_frame *f, uint32_t level, uint64_t pool_part,
                                 uint8_t *scratch);

#define VXL_PALETTES_PER_ROW 16 /* palettes per texel row of palette_tex (as shaders/lib/palette.glsl) */

/* compressed_pool.c: compressed storage on the GL side */
uint64_t vxl_code_bytes_for(const vxl_storage_state *st, const vxl_pages *pg); /* UINT64_MAX: over the texture limit */
int vxl_compressed_upload(vxl_storage_state *st);
int vxl_compressed_decode(vxl_storage_state *st, const int32_t *source, uint32_t count, const uint32_t slots[3]);
void vxl_compressed_release(vxl_storage_state *st);

#endif
