/* frame_scene.c - validates vxl_render_params.scene_shadows: the
 * scene's opaque meshes that shadow the volume. Every index and vertex is
 * checked here, on the CPU, before anything reaches the GL side: a bad
 * array from a Blender scene must give an error naming the field, never a
 * read out of bounds in the rasteriser. The occluders' key is the caller's,
 * or a hash of the arrays, so the shadow maps (light/shadow_maps.c) are
 * rebuilt only when the meshes change. */
#include <math.h>
#include <string.h>

#include "frame.h"
#include "hash.h"

#define DEFAULT_SHADOW_MAP_SIZE 1024u
#define MIN_SHADOW_MAP_SIZE 16u
#define MAX_SHADOW_MAP_SIZE 8192u /* 256 MiB of depth per map layer: far beyond what a preview needs */
#define MAX_TRIANGLES (INT32_MAX / 3u) /* one glDrawElements counts 3 indices per triangle in a GLsizei */

/* The caller's struct as this library's: there is one layout so far, so a
 * struct_size other than 0 must cover it (a newer, longer one is read up to
 * what this library knows). */
static int read_struct(const vxl_scene_shadows *in, vxl_scene_shadows *out, vxl_err *e)
{
    if (in->struct_size != 0 && in->struct_size < sizeof *out)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "scene_shadows.struct_size = %u is smaller than the struct (%zu bytes)",
                        in->struct_size, sizeof *out);
    memcpy(out, in, sizeof *out);
    return VXL_OK;
}

static int check_occluders(const vxl_scene_shadows *s, vxl_err *e)
{
    if (s->occluder_vertex_count && !s->occluder_vertices)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "scene_shadows.occluder_vertices is NULL with occluder_vertex_count %u",
                        s->occluder_vertex_count);
    if (s->occluder_triangle_count && !s->occluder_indices)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "scene_shadows.occluder_indices is NULL with occluder_triangle_count %u", s->occluder_triangle_count);
    if (s->occluder_triangle_count > MAX_TRIANGLES)
        return vxl_fail(e, VXL_ERR_LIMIT, "scene_shadows.occluder_triangle_count = %u is over %u",
                        s->occluder_triangle_count, MAX_TRIANGLES);
    if (!s->occluder_triangle_count) return VXL_OK; /* vertices alone cast nothing and are not read */
    const size_t n = (size_t)s->occluder_triangle_count * 3;
    for (size_t i = 0; i < n; i++)
        if (s->occluder_indices[i] >= s->occluder_vertex_count)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                            "scene_shadows.occluder_indices[%zu] = %u is out of range (occluder_vertex_count %u)", i,
                            s->occluder_indices[i], s->occluder_vertex_count);
    const size_t m = (size_t)s->occluder_vertex_count * 3;
    for (size_t i = 0; i < m; i++)
        if (!isfinite(s->occluder_vertices[i]))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "scene_shadows.occluder_vertices[%zu] (vertex %zu) is not finite",
                            i, i / 3);
    return VXL_OK;
}

int vxl_frame_resolve_scene_shadows(vxl_frame *f, const vxl_render_params *p, vxl_err *e)
{
    if (!p->scene_shadows) return VXL_OK;
    vxl_scene_shadows s;
    int rc = read_struct(p->scene_shadows, &s, e);
    if (!rc) rc = check_occluders(&s, e);
    if (rc) return rc;
    uint32_t size = s.shadow_map_size ? s.shadow_map_size : DEFAULT_SHADOW_MAP_SIZE;
    if (size < MIN_SHADOW_MAP_SIZE || size > MAX_SHADOW_MAP_SIZE)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "scene_shadows.shadow_map_size = %u must be 0 (%u) or in [%u, %u]",
                        s.shadow_map_size, DEFAULT_SHADOW_MAP_SIZE, MIN_SHADOW_MAP_SIZE, MAX_SHADOW_MAP_SIZE);
    if (!s.occluder_triangle_count) return VXL_OK;
    f->occluder_vertices = s.occluder_vertices;
    f->occluder_indices = s.occluder_indices;
    f->occluder_vertex_count = s.occluder_vertex_count;
    f->occluder_triangle_count = s.occluder_triangle_count;
    f->shadow_map_size = size;
    uint64_t key = s.occluder_key;
    if (!key) { /* the caller keeps no version: the arrays are the version */
        key = vxl_fnv(1469598103934665603ull, &s.occluder_vertex_count, sizeof s.occluder_vertex_count);
        key = vxl_fnv(key, &s.occluder_triangle_count, sizeof s.occluder_triangle_count);
        key = vxl_fnv_words(key, s.occluder_vertices, (size_t)s.occluder_vertex_count * 3 * sizeof(float));
        key = vxl_fnv_words(key, s.occluder_indices, (size_t)s.occluder_triangle_count * 3 * sizeof(uint32_t));
        key = key ? key : 1;
    }
    f->occluder_key = key;
    return VXL_OK;
}
