/* shadow_maps.h - the scene's opaque meshes as seen from each light (issue
 * 18): depth maps, one per light (six, a cube, for a point light inside or
 * beside the volume), rasterised from the occluders of
 * vxl_render_params.scene_shadows by render/shadow_map.vert and .frag. The
 * illumination volumes (illumination.c) multiply each light's transmittance
 * by the visibility the maps give at each cell (lib/shadow_maps.glsl), so a
 * mesh between a light and the volume shadows the volume.
 *
 * Frusta. A directional light: an orthographic box along the light, tight
 * around the volume's world box. A point light outside the box: a
 * perspective frustum from the light around the box's corners, when they
 * fit within 60 degrees of its axis. A point light inside the box, or so
 * close that they do not: a cube of six 90-degree views about the light,
 * which covers every direction. Depth clamping keeps occluders that lie
 * between the light and the near plane (a directional light's occluders
 * are anywhere towards the light) at depth 0, so they block; occluders
 * beyond the box clamp to 1 and block nothing the box holds.
 *
 * Each light's maps are keyed by the occluders' key, the light, the map
 * size and the volume's placement and size: the camera is in none, so a
 * camera move rebuilds nothing. */
#ifndef VXL_SHADOW_MAPS_H
#define VXL_SHADOW_MAPS_H

#include <stdint.h>

#include "frame.h"
#include "gpu.h"
#include "voxlight.h"

#define VXL_SHADOW_MAX_VIEWS 6 /* a cube about a point light */

typedef struct vxl_shadow_light {
    uint32_t views;                           /* 1, or 6 (a cube) */
    uint32_t first_layer;                     /* its first layer of the map array */
    float matrix[VXL_SHADOW_MAX_VIEWS][16];   /* world -> the view's clip space */
    float texel_world;                        /* world size of a texel, at the volume's centre */
    uint64_t key;                             /* what the maps were built for; 0: none */
} vxl_shadow_light;

typedef struct vxl_shadow_maps_state {
    vxl_gpu *gpu;
    GLuint tex;                 /* GL_TEXTURE_2D_ARRAY, DEPTH_COMPONENT32F, compare to reference */
    GLuint fbo, vao, vbo, ebo;
    uint32_t size, layers;      /* of tex */
    uint64_t mesh_key;          /* the occluders in vbo / ebo; 0: none uploaded */
    uint64_t mesh_bytes, map_bytes;
    uint32_t triangle_count;
    vxl_shadow_light light[VXL_MAX_LIGHTS];
    int active;                 /* the last prepared frame has occluders */
    uint32_t rebuilt;           /* lights whose maps the last prepare rasterised */
    uint32_t builds;            /* every light's maps rasterised since the renderer opened (tests) */
} vxl_shadow_maps_state;

void vxl_shadow_maps_init(vxl_shadow_maps_state *s, vxl_gpu *g);
/* Bytes of GL memory held (maps and occluder buffers). */
uint64_t vxl_shadow_maps_bytes(const vxl_shadow_maps_state *s);
/* Rasterises the maps of every light of f whose key changed; nothing (and
 * inactive) when f has no occluders. dims: the volume's voxels. Leaves the
 * default framebuffer state to the caller: the framebuffer, viewport and
 * vertex array are changed. */
int vxl_shadow_maps_prepare(vxl_shadow_maps_state *s, const vxl_frame *f, const uint32_t dims[3]);
/* The uniforms of lib/shadow_maps.glsl for light i on prog (in use) and the
 * maps on VXL_SHADOW_MAP_UNIT; bias: world units the reference moves
 * towards the light; pcf: the filter's half width in world units. */
void vxl_shadow_maps_bind(vxl_shadow_maps_state *s, GLuint prog, const vxl_frame *f, int i, float bias, float pcf);
void vxl_shadow_maps_release(vxl_shadow_maps_state *s);

#endif
