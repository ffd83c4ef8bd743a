/* gpu.h - the GL services every GL-side stage receives instead of the
 * renderer: the function table, the error slot, the program cache and its
 * helpers (gl_util.c), the shader folder, the storage buffers, what the
 * backend reported, and the memory budget with its holders (holdings.h).
 * Storage, skipping, classification and the derived volumes each hold a
 * pointer to the renderer's one vxl_gpu; none of them sees the renderer.
 * Everything here is used on the renderer's GL thread only. */
#ifndef VXL_GPU_H
#define VXL_GPU_H

#include <stdint.h>

#include "budget.h"
#include "error.h"
#include "gl_bindings.h"
#include "gl_funcs.h"
#include "voxlight.h"

#define VXL_MAX_PROGRAMS 1024 /* every raycast variant (7*4*3*3, dense and paged) plus compute programs */

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
#define VXL_PROG_SLICES 13 /* the slicing comparison modes (render/slices.c); flags as RAYCAST */
#define VXL_PROG_ILLUMINATION 14 /* light/illumination.c: flags & 3 the pass, plus the sample flags */
#define VXL_PROG_CUT_PEEL 24 /* cut/cutaway.c: cutter meshes peeled into per-pixel crossings */
/* kinds take 5 bits of the program cache's key (gl_util.c): at most 31 */
#define VXL_PROG_SHADOW_MAP 20 /* light/shadow_maps.c: occluders rasterised from a light (depth only) */
#define VXL_PROG_SCENE_TRANSMITTANCE 21 /* light/transmittance.c: scene points' transmittance to a light */
#define VXL_PROG_PATH 25 /* render/path.c: the PATH shading model's tracer (render/path.frag); flags as RAYCAST */
#define VXL_PROG_SLICE_PLANE 16 /* render/slice_plane.c: flags & 3 the interpolation, plus the sample flags */

/* Program flags the storage sets on shaders that sample the volume. */
#define VXL_FLAG_PAGED 64u /* program flag: sample through the page table */
#define VXL_FLAG_COMPRESSED_DOMAIN 128u /* with PAGED: the pool holds codes, every tap decodes its 8 neighbours */
/* with PAGED: the streamed storage's page table, whose entries may stand in for a coarser level's brick
 * (PAGED_MIXED, storage_streamed.c) */
#define VXL_FLAG_PAGED_MIXED (1u << 20)
/* Ray caster program flags (gl_util.c turns them into defines). */
#define VXL_FLAG_MODE_SHIFT 10u        /* bits 10-12: VXL_MODE_* (MODE) */
#define VXL_FLAG_MATCAP (1u << 13)     /* MATCAP: shading reads the MatCap */
#define VXL_FLAG_CUT_CONVEX (1u << 14) /* CUT_CONVEX: clip planes and the crop box narrow the ray */
#define VXL_FLAG_CUT_CUTTERS (1u << 15) /* CUT_CUTTERS: cutter meshes remove depth intervals */
/* Ray caster program flag (labels/labels.c): bits 16-17 hold the label mode + 1 (LABELS); 0 none. */
#define VXL_FLAG_LABELS_SHIFT 16u
/* Ray caster program flag (overlay/overlays.c): bits 18-19 hold the number of overlays (OVERLAYS); 0 none. */
#define VXL_FLAG_OVERLAYS_SHIFT 18u
/* With the LABELS bits: label boundaries as the voxels' faces (LABEL_VOXELS), not smooth. */
#define VXL_FLAG_LABEL_VOXELS (1u << 21)
/* Ray caster and slicing program flag (colour/colour.c): the samples' colour comes from a colour volume's
 * own colour texture (DATA_COLOUR), opacity still from the transfer function. */
#define VXL_FLAG_DATA_COLOUR (1u << 22)

/* The World's light: the ray caster's shading adds it (ENVIRONMENT), and
 * the illumination program with it is the environment pass (PASS 4). */
#define VXL_FLAG_ENVIRONMENT (1u << 23)
/* Ray caster program flag (channels/channels.c): bits 24-25 hold the number of
 * a multi-channel volume's texture groups drawn (CHANNEL_GROUPS, 1 or 2); 0 none. */
#define VXL_FLAG_CHANNELS_SHIFT 24u
/* The ray caster's flags are one key: no two may share a bit (the sum of
 * the fields equals their union; two rooms added on separate branches once
 * took the same bit). */
#define VXL_RAYCAST_FLAG_FIELDS_(op)                                                                                 \
    (VXL_FLAG_PAGED op VXL_FLAG_COMPRESSED_DOMAIN op (7u << VXL_FLAG_MODE_SHIFT) op VXL_FLAG_MATCAP op                \
     VXL_FLAG_CUT_CONVEX op VXL_FLAG_CUT_CUTTERS op (3u << VXL_FLAG_LABELS_SHIFT) op (3u << VXL_FLAG_OVERLAYS_SHIFT) op \
     VXL_FLAG_PAGED_MIXED op VXL_FLAG_LABEL_VOXELS op VXL_FLAG_DATA_COLOUR op VXL_FLAG_ENVIRONMENT op (3u << VXL_FLAG_CHANNELS_SHIFT))
_Static_assert(VXL_RAYCAST_FLAG_FIELDS_(+) == VXL_RAYCAST_FLAG_FIELDS_(|), "two program flags share a bit (gpu.h)");
/* Direction cells the World's map is reduced to (light/environment_map.h);
 * the environment pass's ENV_CELLS. */
#define VXL_ENV_CELLS 32

typedef struct vxl_program_entry {
    uint64_t key; /* kind | filter << 5 | flags << 12 (gl_util.c): every flag bit fits */
    GLuint program;
} vxl_program_entry;

/* One holder of GL memory as the budget counts it (budget.h): the subsystem
 * that holds it registers how to read its bytes (holdings.h), so the
 * accountant reads no subsystem's struct. */
typedef struct vxl_holding {
    uint64_t (*bytes)(const void *state);
    const void *state;
} vxl_holding;

typedef struct vxl_gpu {
    vxl_gl gl;
    vxl_err err;               /* last failure on this handle */
    uint64_t budget;           /* GPU storage budget, bytes */
    char *shader_dir;          /* NULL = embedded shaders */
    vxl_renderer_info info;
    vxl_program_entry programs[VXL_MAX_PROGRAMS];
    int n_programs;
    GLuint ssbo[3];            /* probe points / the gradient maximum, probe results / brick lists, stats */
    vxl_holding holdings[VXL_HOLD_COUNT];
} vxl_gpu;

/* gl_util.c */
int vxl_program_get(vxl_gpu *g, uint32_t kind, uint32_t filter, uint32_t flags, GLuint *out);
void vxl_uniform_i(vxl_gpu *g, GLuint prog, const char *name, int v);
void vxl_uniform_f(vxl_gpu *g, GLuint prog, const char *name, float v);
GLuint vxl_texture_new(vxl_gpu *g, GLenum target, GLint filter);
/* The GL internal format and pixel type of one-channel texels of `bytes`
 * per voxel (1, 2: unsigned normalised; 4: float), as every volume texture
 * (dense, pool, overlay) stores vxl_volume texels. */
static inline GLenum vxl_texel_internal_format(uint32_t bytes) { return bytes == 1 ? GL_R8 : bytes == 2 ? GL_R16 : GL_R32F; }
static inline GLenum vxl_texel_type(uint32_t bytes)
{
    return bytes == 1 ? GL_UNSIGNED_BYTE : bytes == 2 ? GL_UNSIGNED_SHORT : GL_FLOAT;
}
int vxl_gl_check(vxl_gpu *g, const char *what);
void vxl_programs_delete(vxl_gpu *g);

#endif
