/* illumination.h - the illumination volumes of the shadowed and scatter
 * shading models: per light, the transmittance from every cell of
 * a reduced grid over the volume to the light, and the ambient occlusion,
 * read by the ray caster with one fetch per light per shaded sample
 * (shaders/lib/illumination.glsl). Built on the GL side by
 * shaders/compute/illumination.comp from an extinction volume (optical depth
 * per cell, through the ray caster's own sampling and classification), and
 * rebuilt only when what each depends on changes: the extinction on the
 * classification and the pool; a light's volume on that, the grid and the
 * light's voxel-space direction or position and size; the occlusion on that
 * and its radius. The camera is in none of the keys. The extinction keeps
 * its grid while the lights' grid is as coarse or coarser (it is read
 * through its sampler in voxel coordinates), so a light dragged at a
 * coarser size, and refined when it settles, costs no extinction pass.
 * Such a frame is a preview: the coarse cells point-sample a sharper field
 * than their own extinction would give (two-blobs, 96^3, sun and occlusion:
 * RMSE 0.0097 against the reference for 24 cells after 96, 0.0063 fresh;
 * 0.0056 against 0.0045 for 48 after 96), and the settled frame is exact
 * to its own size again.
 *
 * Approximation: the extinction is always post-classified (the table looked
 * up at the interpolated value). Pre-integrated frames integrate that same
 * extinction along their segments, so their shadows are consistent; a
 * pre-classified frame interpolates classified voxels instead, which the
 * reference's shadow rays follow too. Measured on the two-blobs phantom
 * (48^3, illumination size 48, one sun): the shadows add 0.0027 RMSE against
 * the reference to post-classified frames and 0.0031 to pre-classified
 * ones, so the difference is small next to the grid's own error, and not
 * worth a pre-classified extinction pass per storage mode. */
#ifndef VXL_ILLUMINATION_H
#define VXL_ILLUMINATION_H

#include <stdint.h>

#include "frame.h"
#include "gpu.h"
#include "shadow_maps.h"
#include "storage.h"
#include "voxlight.h"

typedef struct vxl_illumination_state {
    vxl_gpu *gpu;               /* the GL services */
    vxl_storage_state *storage; /* the volume the extinction is sampled from */
    GLuint extinction_tex;      /* R32F, extinction_cells: mean optical depth per voxel of path */
    GLuint tex;                 /* R16F, cells stacked `blocks` times along z: light i, then occlusion */
    uint32_t extinction_cells[3]; /* at least as fine as cells: kept when only the lights' grid shrinks */
    uint32_t cells[3];
    uint32_t blocks;
    uint32_t size;              /* cells along the longest side */
    uint64_t bytes;
    uint64_t extinction_key, occlusion_key;
    /* The World's light (environment_map.h): its map reduced to direction
     * cells (keyed by the frame's env.key), and the irradiance volume E(x)
     * on env_cells (half the lights' grid per axis), RGBA16F, keyed by the
     * extinction, the grid, the map and its voxel-space directions. Freed by
     * a frame without one. */
    GLuint env_tex;
    uint32_t env_cells[3];
    uint64_t env_key, env_map_key;
    float env_radiance[VXL_ENV_CELLS][3];
    float env_mean[3];          /* the cells' mean: the map's mean radiance (Phong's term) */
    uint64_t light_key[VXL_MAX_LIGHTS];
    int in_use;                 /* the last prepared frame reads it */
    uint32_t rebuilt;           /* volumes the last prepare rebuilt (lights + occlusion + environment) */
    uint32_t builds;            /* every volume built since the renderer opened (tests) */
    /* the scene's occluders seen from each light; a light's
     * volume is multiplied by their visibility and keyed by its maps. */
    vxl_shadow_maps_state shadows;
    /* vxl_scene_transmittance's images (transmittance.c): the scene depth
     * in (R32F) and the transmittance out (R32F), of image_w x image_h. */
    GLuint scene_depth_tex, transmittance_tex;
    uint32_t image_w, image_h;
    uint64_t image_bytes;
    /* Hidden labels cast no shadow: the extinction pass reads the label
     * volume through the labels' own binding (labels/ is a peer of light/,
     * so the renderer hands it over here). NULL: frames with labels shadow
     * as if every voxel were shown. */
    int (*bind_labels)(void *ctx, const vxl_frame *f, GLuint prog);
    void *labels_ctx;
} vxl_illumination_state;

/* Wires s to the GL services and the storage, and registers its bytes with the budget. */
void vxl_illumination_init(vxl_illumination_state *s, vxl_gpu *g, vxl_storage_state *st);

/* Builds what frame f's shading model reads (nothing for Phong or unshaded
 * frames but the environment's reduction) and binds it on
 * VXL_ILLUMINATION_UNIT (and the environment's on VXL_ENVIRONMENT_UNIT). With occluders in f
 *, each light's volume is cut by its shadow maps. Needs the storage prepared
 * for f and the transfer function on VXL_TF_UNIT; uses programs of its own,
 * so call it before the ray caster's program is bound. */
int vxl_illumination_prepare(vxl_illumination_state *s, const vxl_frame *f);
/* The ray caster's illumination uniforms, on prog (in use). */
void vxl_illumination_bind(vxl_illumination_state *s, GLuint prog, const vxl_frame *f);
/* The illumination fields of the frame's stats. */
void vxl_illumination_report(const vxl_illumination_state *s, vxl_render_stats *out);
void vxl_illumination_release(vxl_illumination_state *s);

#endif
