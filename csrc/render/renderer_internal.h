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
#include "gl_bindings.h"
#include "gl_thread.h"
#include "lod.h"
#include "frame.h"
#include "storage.h"
#include "voxlight.h"

#define VXL_MAX_PROGRAMS 1024 /* every raycast variant (7*4*3*3, dense and paged) plus compute programs */
#define VXL_MAX_SAMPLES_PER_RAY 16384 /* bounds every ray, whatever the step */
#define VXL_MAX_IMAGE_SIDE 16384

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

/* Each subsystem's state; each subsystem releases only its own. */

/* Precomputed gradients (precompute.c; bricked: paged_gradients.c) depend
 * only on the volume data and the storage format: rebuilt on set_volume or
 * a format change, never per frame. */
typedef struct vxl_gradient_state {
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

/* Cubic B-spline coefficients (bspline.c; bricked: paged_bspline.c, a pool
 * of coefficient bricks with its page table): depend only on the volume data. */
typedef struct vxl_bspline_state {
    GLuint tex, page_tex;
    uint32_t pool_dims[3];
    uint8_t *covered;          /* bricked: per page brick of `level`, 1 if in the coefficient pool */
    uint32_t level;
    uint64_t bytes;
} vxl_bspline_state;

/* Empty-space skipping (skipping.c): min-max per brick (data only; bricked
 * storage hands over the grid it computed on the CPU) and the distance map
 * texture (re-derived when the classification changes). */
typedef struct vxl_skipping_state {
    vxl_bricks bricks;
    GLuint brick_tex;
} vxl_skipping_state;

/* Classification caches (classification.c): the pre-classified volume
 * (RGBA8, keyed by the classification) and the pre-integration table (keyed
 * by the classification, the step and the table size). */
typedef struct vxl_classification_state {
    GLuint classified_tex, preint_tex;
    uint64_t classified_key, preint_key;
    uint64_t classified_bytes;
    uint32_t classified_dims[3];
} vxl_classification_state;

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

    vxl_storage_state storage;               /* storage.h, paged.c, storage_*.c */
    vxl_gradient_state gradients;
    vxl_bspline_state bspline;
    vxl_skipping_state skipping;
    vxl_classification_state classification;

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
 * storage), after asking the budget (budget.h) for `need` bytes: the gradients' own, transient blur included. */
int vxl_gradient_programs(vxl_renderer *r, int paged, int store, uint64_t need, GLuint progs[3]);
void vxl_gradients_release(vxl_renderer *r);
/* Releases, and forgets what was known about the volume (the largest gradient per level). */
void vxl_gradients_forget_volume(vxl_renderer *r);
int vxl_bspline_ensure(vxl_renderer *r);
void vxl_bspline_release(vxl_renderer *r);

/* classification.c */
int vxl_classification_prepare(vxl_renderer *r, const vxl_frame *f);
void vxl_classification_release(vxl_renderer *r);

/* skipping.c */
int vxl_skipping_prepare(vxl_renderer *r, const vxl_frame *f);
void vxl_skipping_release(vxl_renderer *r);
/* Takes a min-max grid the storage computed (bricked: on the CPU at
 * set_volume); an empty one leaves the grid to be built from the texture. */
void vxl_skipping_adopt(vxl_renderer *r, vxl_bricks *grid);
uint32_t vxl_skip_brick_size(void);

/* paged_gradients.c, paged_bspline.c: the derived pools of bricked storage
 * (precomputed gradients, cubic coefficients). make_room, when given, runs
 * right before a pool is (re)built: the storage decides what else goes. */
int vxl_paged_gradients_ensure(vxl_renderer *r, int store, void (*make_room)(vxl_renderer *r));
int vxl_paged_bspline_ensure(vxl_renderer *r, void (*make_room)(vxl_renderer *r));
/* Bytes the cubic / precomputed pool of `level` needs for the last frame's
 * visibility (UINT64_MAX: over the texture limit); fills want (a mask of the
 * level's page count) and *count. */
uint64_t vxl_paged_bspline_bytes(const vxl_renderer *r, uint32_t level, uint8_t *want, uint32_t *count);
uint64_t vxl_paged_gradient_bytes(const vxl_renderer *r, uint32_t level, int store, uint8_t *want, uint32_t *count);

/* render.c helpers shared with probe.c */
int vxl_bind_volume_textures(vxl_renderer *r, GLuint prog, uint32_t filter, int store);

#endif
