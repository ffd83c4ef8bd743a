/* renderer_internal.h - the renderer's state. Everything GL lives on the
 * renderer's own thread; API functions package their arguments into a job. */
#ifndef VXL_RENDERER_INTERNAL_H
#define VXL_RENDERER_INTERNAL_H

#include <stdint.h>

#include "bricks.h"
#include "paging.h"
#include "context.h"
#include "error.h"
#include "gl_funcs.h"
#include "gl_thread.h"
#include "lod.h"
#include "frame.h"
#include "voxlight.h"

#define VXL_MAX_PROGRAMS 1024 /* every raycast variant (7*4*3*3, dense and paged) plus compute programs */
#define VXL_MAX_SAMPLES_PER_RAY 16384 /* bounds every ray, whatever the step */
#define VXL_MAX_IMAGE_SIDE 16384
#define VXL_SCRATCH_UNIT 7 /* texture unit used only to create and fill textures */

/* Program kinds in the cache key. */
#define VXL_PROG_RAYCAST 0
#define VXL_PROG_PROBE 1
#define VXL_PROG_GRAD_BLUR 2
#define VXL_PROG_GRAD_MAX 3
#define VXL_PROG_GRAD_STORE 4
#define VXL_PROG_BSPLINE_COPY 5
#define VXL_PROG_BSPLINE_AXIS 6
#define VXL_PROG_BRICK_MINMAX 7
#define VXL_PROG_CLASSIFY_VOLUME 8
#define VXL_PROG_PAGED_BLUR 9
/* 10: was the bricked texture's max pass, now on the CPU */
#define VXL_PROG_PAGED_GRAD_STORE 11
#define VXL_PROG_DECODE_BRICKS 12 /* flags: the cache's bytes per voxel - 1 */

typedef struct vxl_program_entry {
    uint32_t key;
    GLuint program;
} vxl_program_entry;

struct vxl_renderer {
    vxl_gl_thread thread;
    vxl_context ctx;
    vxl_gl gl;
    vxl_err err;               /* last failure on this handle */
    uint64_t budget;           /* GPU storage budget, bytes */
    char *shader_dir;          /* NULL = embedded shaders */
    vxl_renderer_info info;

    /* the volume on the GL side; see set_volume for what depends on it */
    int has_volume;
    uint32_t dims[3];
    double tex_lo, tex_hi, value_min, value_max;
    double affine[16];
    GLuint volume_tex;
    uint64_t volume_bytes;

    /* Bricked storage (paged.c): storage is the VXL_STORAGE_* in use. When
     * bricked, volume_tex is 0 and samples go through the page table into
     * the pool. SPARSE keeps the CPU bricks (pages.data) to make bricks
     * resident when the classification changes. */
    uint32_t storage;
    uint32_t page_brick_request;  /* from the options; 0 = default */
    uint32_t storage_request;     /* VXL_STORAGE_* asked for */
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
    int compressed_domain;        /* from the options */
    double decode_ms;             /* the decode of this frame, 0 if none */

    /* Precomputed gradients depend only on the volume data and the storage
     * format: rebuilt on set_volume or a format change, never per frame. */
    GLuint gradient_tex;
    GLuint gpage_tex;          /* bricked: the gradient pool's page table */
    uint32_t gpool_dims[3];
    int gradient_store;        /* VXL_GRADIENT_STORE_* of gradient_tex */
    float gradient_max;        /* largest |gradient| (value per voxel): gradient_tex holds g / gradient_max */
    uint64_t gradient_bytes;
    uint8_t *gradient_covered; /* bricked: per page brick of gradient_level, 1 if in the gradient pool */
    uint32_t gradient_level;
    float gradient_max_level[VXL_LOD_LEVELS]; /* sparse: the whole level's maximum from the CPU bricks, < 0 unknown */

    /* Cubic B-spline coefficients: depend only on the volume data. Bricked,
     * a pool of coefficient bricks with its page table (paged_bspline.c). */
    GLuint bspline_tex, cpage_tex;
    uint32_t cpool_dims[3];
    uint8_t *bspline_covered;  /* bricked: per page brick of bspline_level, 1 if in the coefficient pool */
    uint32_t bspline_level;
    uint64_t bspline_bytes;

    /* Empty-space skipping: min-max per brick (data only) and the distance
     * map texture (re-derived when the classification changes). */
    vxl_bricks bricks;
    GLuint brick_tex;

    /* Classification caches: the pre-classified volume (RGBA8, keyed by the
     * classification) and the pre-integration table (keyed by the
     * classification, the step and the table size). */
    GLuint classified_tex, preint_tex;
    uint64_t classified_key, preint_key;
    uint64_t classified_bytes;
    uint32_t classified_dims[3];

    vxl_program_entry programs[VXL_MAX_PROGRAMS];
    int n_programs;
    GLuint vao, fbo, color_tex, depth_tex, scene_depth_tex, tf_tex, ssbo[3]; /* probe in/out, stats */
    uint32_t fb_w, fb_h;
    vxl_render_stats stats;    /* of the last successful frame */
};

/* gl_util.c */
int vxl_program_get(vxl_renderer *r, uint32_t kind, uint32_t filter, uint32_t flags, GLuint *out);
void vxl_uniform_i(vxl_renderer *r, GLuint prog, const char *name, int v);
void vxl_uniform_f(vxl_renderer *r, GLuint prog, const char *name, float v);
GLuint vxl_texture_new(vxl_renderer *r, GLenum target, GLint filter);
int vxl_gl_check(vxl_renderer *r, const char *what);
void vxl_programs_delete(vxl_renderer *r);

/* precompute.c */
int vxl_gradients_ensure(vxl_renderer *r, int store);
/* The blur, max and store programs of precomputed gradients (paged: bricked
 * storage), after checking that `need` bytes in all fit the budget. */
int vxl_gradient_programs(vxl_renderer *r, int paged, int store, uint64_t need, GLuint progs[3]);
void vxl_gradients_release(vxl_renderer *r);
int vxl_bspline_ensure(vxl_renderer *r);
void vxl_bspline_release(vxl_renderer *r);

/* classification.c */
int vxl_classification_prepare(vxl_renderer *r, const vxl_frame *f);
void vxl_classification_release(vxl_renderer *r);

/* skipping.c */
int vxl_skipping_prepare(vxl_renderer *r, const vxl_frame *f);
void vxl_skipping_release(vxl_renderer *r);

/* paged.c: bricked storage on the GL side */
/* A volume cut into bricks on the CPU, checked against the budget and the
 * texture limit before the renderer lets go of its current volume. */
typedef struct vxl_paged_volume {
    vxl_pages levels[VXL_LOD_LEVELS];
    uint32_t level_dims[VXL_LOD_LEVELS][3];
    uint32_t n_levels;
    vxl_bricks bricks;
    uint32_t storage;   /* BRICKED or SPARSE */
} vxl_paged_volume;
int vxl_paged_plan(vxl_renderer *r, const vxl_volume *v, uint32_t storage, vxl_paged_volume *out);
int vxl_paged_install(vxl_renderer *r, vxl_paged_volume *pv); /* takes pv's storage */
int vxl_paged_prepare(vxl_renderer *r, const vxl_frame *f); /* f NULL: every data brick (probes) */
int vxl_paged_check_filter(vxl_renderer *r, uint32_t filter, uint32_t classify);
void vxl_paged_release(vxl_renderer *r);
uint32_t vxl_skip_brick_size(void);
int vxl_paged_gradients_ensure(vxl_renderer *r, int store); /* paged_gradients.c */
/* paged_bspline.c: the cubic filter's coefficient pool, and what it shares
 * with the gradient pool: which bricks a derived pool needs (not flat within
 * `support` voxels, readable within `read_reach` of a visible sample) and
 * whether one made for `covered` at `level` still serves. */
int vxl_paged_bspline_ensure(vxl_renderer *r);
uint32_t vxl_paged_derived_want(const vxl_renderer *r, uint32_t level, uint32_t support, uint32_t read_reach,
                                uint8_t *want);
/* Bytes the cubic / precomputed pool of `level` needs for the last frame's
 * visibility (UINT64_MAX: over the texture limit); fills want (a mask of the
 * level's page count) and *count. */
uint64_t vxl_paged_bspline_bytes(const vxl_renderer *r, uint32_t level, uint8_t *want, uint32_t *count);
uint64_t vxl_paged_gradient_bytes(const vxl_renderer *r, uint32_t level, int store, uint8_t *want, uint32_t *count);
int vxl_paged_derived_current(const vxl_renderer *r, const uint8_t *covered, uint32_t level, const uint8_t *want);
/* The current level's bricks on the CPU: its own when kept, else (bricked)
 * the pool read back into *owned, which the caller frees. */
int vxl_paged_brick_store(vxl_renderer *r, vxl_brick_store *s, uint8_t **owned);
int vxl_pool_layout(const vxl_renderer *r, uint32_t n, uint32_t edge, uint32_t slots[3]);
/* Runs prog over bricks first .. first + count - 1 of edge e (one
 * invocation per voxel, groups of 4^3), in chunks the dispatch limit allows
 * (sets u_first). */
void vxl_dispatch_bricks(vxl_renderer *r, GLuint prog, uint32_t first, uint32_t count, uint32_t e);
#define VXL_GPAGE_UNIT 9 /* texture unit of the gradient pool's page table */
#define VXL_CPAGE_UNIT 12 /* texture unit of the coefficient pool's page table */
#define VXL_PAGE_UNIT 8 /* texture unit of the page table */
#define VXL_FLAG_PAGED 64u /* program flag: sample through the page table */
#define VXL_FLAG_COMPRESSED_DOMAIN 128u /* with PAGED: the pool holds codes, every tap decodes its 8 neighbours */
#define VXL_CODE_UNIT 10    /* texture unit of the code pool while decoding */
#define VXL_PALETTE_UNIT 11 /* texture unit of the palettes */
#define VXL_PALETTES_PER_ROW 16 /* palettes per texel row of palette_tex (as shaders/palette.glsl) */

/* The sampling flags of programs reading the volume (raycast, probe). */
static inline uint32_t vxl_volume_flags(const vxl_renderer *r)
{
    return r->volume_tex ? 0u : r->pool_tex && r->pool_tex == r->code_tex ? VXL_FLAG_PAGED | VXL_FLAG_COMPRESSED_DOMAIN : VXL_FLAG_PAGED;
}

/* compressed_pool.c: compressed storage on the GL side */
uint64_t vxl_code_bytes_for(const vxl_renderer *r, const vxl_pages *pg); /* UINT64_MAX: over the texture limit */
int vxl_compressed_upload(vxl_renderer *r);
int vxl_compressed_decode(vxl_renderer *r, const int32_t *source, uint32_t count, const uint32_t slots[3]);
void vxl_compressed_release(vxl_renderer *r);

/* render.c helpers shared with probe.c */
int vxl_bind_volume_textures(vxl_renderer *r, GLuint prog, uint32_t filter, int store);

#endif
