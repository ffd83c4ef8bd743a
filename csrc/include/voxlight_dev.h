/*
 * voxlight_dev.h - libvoxlight's test and benchmark hooks.
 *
 * The product API is voxlight.h; this header adds what the tests, the
 * benchmarks and the accuracy studies use to look inside the renderer or to
 * produce ground truth. The library exports every function here (the ctypes
 * binding calls the probe and the phantoms too), with the same conventions
 * as voxlight.h, but a product has no reason to call them and they may
 * change between releases without an ABI version bump.
 *
 * Developer fields of voxlight.h's structs. They stay where they are, with
 * their names, so the structs keep one layout for every caller (products
 * leave them 0, the all-zero default):
 *  - vxl_renderer_options.compressed_domain: 1 = compressed storage filters
 *    in the compressed domain (every tap decodes its 8 neighbours; no decode
 *    cache), to measure deferred filtering against it; 0 = deferred
 *    filtering.
 *  - vxl_render_params.no_skip: 1 = disable every in-frame skip (empty-space
 *    skipping and early ray termination), so tests can compare a frame
 *    with and without them.
 *  - vxl_render_params.preint_size: entries per axis of the pre-integration
 *    table the PREINT classification builds; 0 = 256 (see vxl_preint_table).
 */
#ifndef VOXLIGHT_DEV_H
#define VOXLIGHT_DEV_H

#include "voxlight.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------ streamed volumes */

/* A streamed copy of a whole volume: the same info, no texels, its voxels
 * served by a brick source over a copy of whole's texels with n_levels
 * levels (0 = as many as a file of that size would get), so tests can
 * render streamed against whole. Destroy with vxl_volume_destroy. */
VXL_API int vxl_volume_stream_copy(const vxl_volume *whole, uint32_t n_levels, vxl_volume **out);

/* The texels (texture format: 8/16-bit codes or floats, x fastest) of the
 * box lo .. lo+size-1 of resolution level `level` (each 2x coarser per
 * axis): a streamed volume reads them through its source; a whole one
 * computes level k with the LOD fallback's downsampling (storage/lod.c) and
 * cuts the box out. Tests compare the two. */
VXL_API int vxl_volume_read_level(const vxl_volume *vol, uint32_t level, const uint32_t lo[3],
                                  const uint32_t size[3], void *out);

/* The brick min-max index (2 floats per brick, x fastest, over the brick and
 * a one-voxel apron). Streamed: the source's own, *brick set to its brick.
 * Whole: vxl_bricks_minmax_cpu with bricks of *brick voxels (the skipping
 * grid's CPU copy). dims gets the bricks per axis; out (may be NULL) the
 * first max_floats floats. */
VXL_API int vxl_volume_brick_index(const vxl_volume *vol, uint32_t *brick, uint32_t dims[3], float *out,
                                   size_t max_floats);

/* ---------------------------------------------------------------- notes */

/* Appends one note to the volume's notes as a reader would (vxl_volume_info
 * .notes: "; "-separated, cut with "..." when full), so tests can check
 * what reaches the user without a reader that decides something. */
VXL_API int vxl_volume_add_note(vxl_volume *vol, const char *note);

/* ------------------------------------------------------- label uploads */

/* how many label volumes and label tables the renderer has
 * uploaded since it was created (either pointer may be NULL), so tests can
 * check that recolouring or hiding a label re-uploads only the table. */
VXL_API int vxl_renderer_label_uploads(vxl_renderer *r, uint64_t *volume_uploads, uint64_t *table_uploads);

/* ------------------------------------------------------- gradient probe */

/* Evaluates the gradient filter selected in p (filter, sample_distance,
 * gradient_store, reuse_gradients) at n points given in voxel space
 * (points: n*3 floats), with the same GLSL the ray caster runs. out: n*3
 * floats, the gradient in voxel space (units of normalised value per voxel;
 * the precomputed filter's magnitude is relative). With reuse_gradients the
 * points are treated as consecutive samples of one ray. */
VXL_API int vxl_probe_gradients(vxl_renderer *r, const vxl_render_params *p, const float *points,
                                uint32_t n, float *out);

/* The empty-space skipping grid as the renderer holds it: per brick of
 * *brick voxels, x fastest, the normalised min and max (2 floats) over the
 * brick and a one-voxel apron (every voxel a trilinear sample in the brick
 * reaches). Built by brick_minmax.comp at the first skipping frame (one
 * volume texture), or on the CPU at set_volume (bricked storage). dims gets
 * the bricks per axis; out (may be NULL) the first max_floats of the
 * 2*dims[0]*dims[1]*dims[2] floats. VXL_ERR_STATE while there is no grid. */
VXL_API int vxl_probe_skip_grid(vxl_renderer *r, uint32_t dims[3], uint32_t *brick, float *out, size_t max_floats);

/* ------------------------------------------------- ground truth */

/* Analytic phantoms, generated at any resolution, each with an analytic
 * gradient. The volume covers [-1,1]^3 in world units (affine maps voxel
 * centres 0..n-1 onto -1..1), stored as float32. */
#define VXL_PHANTOM_MARSCHNER_LOBB 1 /* fM = 6, alpha = 0.25; iso-surface at 0.5 */
#define VXL_PHANTOM_SPHERE 2         /* ellipsoid distance field: 0.5 - signed distance */
#define VXL_PHANTOM_RAMP 3           /* linear ramp along (1, 2, 3)/|.| */
#define VXL_PHANTOM_NOISY_BLOB 4     /* smooth Gaussian blob plus Gaussian noise */
#define VXL_PHANTOM_SPARSE_BALLS 5   /* Gaussian balls on 5% of an 8^3 lattice (empty-space skipping) */
#define VXL_PHANTOM_DENSE_BALLS 6    /* its dense twin: a ball on every lattice site */
#define VXL_PHANTOM_LARGE_SPARSE 7  /* 8-bit Gaussian ellipsoids on 30% of a 12x8x2 lattice; default
                                        2500x1500x400 (over every 2048 texture limit, for bricking) */
#define VXL_PHANTOM_TWO_BLOBS 8     /* Gaussian blobs (sigma 0.2) at x = -0.45 and +0.45 (shadows) */
#define VXL_PHANTOM_COUNT 9

typedef struct vxl_phantom_desc {
    uint32_t struct_size;
    uint32_t kind;         /* VXL_PHANTOM_* */
    uint32_t dims[3];      /* 0 = 64 */
    uint32_t seed;         /* noise seed (NOISY_BLOB) */
    double noise_sigma;    /* NOISY_BLOB: standard deviation; 0 = 0.05 */
} vxl_phantom_desc;

VXL_API int vxl_phantom_create(const vxl_phantom_desc *d, vxl_volume **out);
/* The noise-free analytic field and its gradient at a voxel-space point
 * (gradient per voxel of the given grid). For NOISY_BLOB this is the blob
 * without noise: the signal a filter should recover. */
VXL_API int vxl_phantom_eval(const vxl_phantom_desc *d, const double p[3], double *value, double grad[3]);
VXL_API const char *vxl_phantom_name(uint32_t kind);
/* Up to max voxel-space points (max*3 floats) where the noise-free field is
 * within tol of iso, drawn uniformly from the central 90% of the box with a
 * fixed seed; *n receives the count found. */
VXL_API int vxl_phantom_iso_points(const vxl_phantom_desc *d, double iso, double tol, uint32_t seed, float *pts,
                                   uint32_t max, uint32_t *n);

/* The ground-truth image of a phantom: a CPU renderer in double precision
 * with the shaders' camera, transfer function, shading and compositing
 * equations, sampling the analytic field and gradient at a step of at most
 * 1/16 voxel, with no jitter. vol must be vxl_phantom_create(d)'s volume (it
 * fixes the value normalisation). Slow: meant for small images. */
VXL_API int vxl_reference_render(const vxl_phantom_desc *d, const vxl_volume *vol, const vxl_render_params *p,
                                 float *rgba, float *depth);

/* The pre-integration table the PREINT mode uses, for inspection and tests:
 * tf (tf_size straight RGBA entries, alpha per voxel), opacity_scale (0 = 1),
 * segment length step (voxels), n entries per axis. out: n*n*4 floats,
 * premultiplied RGBA, out[(back*n + front)*4 + c]. */
VXL_API int vxl_preint_table(const float *tf, uint32_t tf_size, float opacity_scale, float step, uint32_t n,
                             float *out);

#ifdef __cplusplus
}
#endif
#endif
