// illumination.comp - the illumination volumes of the shadowed and scatter
// shading models (csrc/illumination.c), at a reduced resolution:
// u_cells cells over the volume box, cell c centred at voxel position
// (c + 0.5) * u_cell - 0.5. One pass per program (PASS):
//  0  extinction: per cell, the mean optical depth per voxel of path,
//     -ln(1 - a), of the classified opacity a, read through the ray caster's
//     own sampling (lib/common.glsl) and classification (lib/classify.glsl,
//     with the gradient-magnitude opacity of GOPACITY 1 and 2),
//     so every storage mode serves without code of its own. Once per
//     classification; every light and the occlusion read it.
//  1  sweep: a light's transmittance, one slice per dispatch (Behrens &
//     Ratering 1998; Ropinski et al. 2010): a cell's is the previous slice's,
//     read where the ray to the light crosses it, times exp(-optical depth of
//     the segment between). A directional light sweeps along the dominant
//     axis of its travel; a point light radially, along one axis away from
//     its plane (both ways when it lies inside the box), each cell with its
//     own direction. A light's size widens the read of the previous slice by
//     the disc it covers seen from the cell (soft shadows).
//  2  occlusion: per cell, the mean transmittance over 14 directions along
//     rays of u_radius voxels (local ambient occlusion, Hernell et al. 2010).
//  3  scene shadows: a light's block, swept, times the
//     visibility of each cell's centre through the scene's occluders
//     (lib/shadow_maps.glsl), in place. The product is the cell's direct
//     transmittance: the volume's and the meshes' attenuate the same path.
//  4  environment: per cell, the World's irradiance E = sum over the
//     ENV_CELLS direction cells of radiance_k / ENV_CELLS times the
//     transmittance along direction k to the box (from half a cell out, so a
//     surface does not occlude itself), RGB into its own texture.
// Passes 1-3 write u_dst at z offset u_block * u_cells.z: the lights and the
// occlusion share one texture (lib/illumination.glsl reads it).
#include "lib/common.glsl"
#if PASS == 0
#if defined(GOPACITY) && GOPACITY != 0
// Levoy's gradient-magnitude opacity makes the volume's opacity too: the
// central difference's gradient, as cheap as a gradient gets
#define FILTER_CENTRAL 1
#include "lib/gradients.glsl"
#endif
#include "lib/classify.glsl"
#ifdef LABEL_SHADOWS
// Hidden labels cast no shadow: the label at a sample as the ray caster
// finds it (lib/labels.glsl's label_at, whatever the mode), and what the
// mode's march needs declared for its other functions, unused here.
#define LABELS 2
const int u_max_steps = 1;
vec4 g_label_material = vec4(-1.0);
#include "lib/labels.glsl"
#endif
#endif

#if PASS == 1
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in; // one slice
#else
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
#endif
uniform ivec3 u_cells;
uniform vec3 u_cell;          // voxels per cell along each axis
uniform int u_block;          // which block of u_dst the pass writes

vec3 cell_centre(ivec3 c) { return (vec3(c) + 0.5) * u_cell - 0.5; }

#if PASS == 0
layout(r32f, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_dst;
uniform ivec3 u_sub;          // samples per cell along each axis

#ifdef CUT_KEEPS
// What the clip planes and the crop box remove casts no shadow: the numbers
// lib/cut.glsl's cut_convex narrows the rays by (csrc/light/illumination.c
// sets them as csrc/cut/cutaway.c does), asked of one point.
uniform int u_cut_plane_count;
uniform vec4 u_cut_planes[6];     // voxel space: dot(xyz, p) + w = signed world distance, kept >= 0
uniform float u_cut_thickness[6]; // > 0: kept only up to it (a slab)
uniform int u_cut_has_crop;
uniform mat4 u_cut_crop;          // voxel -> box space, kept inside [-1, 1]^3

bool cut_keeps(vec3 p)
{
    for (int i = 0; i < u_cut_plane_count; i++) {
        float d = dot(u_cut_planes[i].xyz, p) + u_cut_planes[i].w;
        if (d < 0.0 || (u_cut_thickness[i] > 0.0 && d > u_cut_thickness[i])) return false;
    }
    return u_cut_has_crop == 0 || all(lessThanEqual(abs((u_cut_crop * vec4(p, 1.0)).xyz), vec3(1.0)));
}
#endif

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, u_cells))) return;
    float depth = 0.0;
    for (int z = 0; z < u_sub.z; z++)
        for (int y = 0; y < u_sub.y; y++)
            for (int x = 0; x < u_sub.x; x++) {
                vec3 p = (vec3(c) + (vec3(x, y, z) + 0.5) / vec3(u_sub)) * u_cell - 0.5;
#ifdef CUT_KEEPS
                if (!cut_keeps(p)) continue; // no optical depth
#endif
                float v = sample_value(p);
#if GOPACITY == 2
                float a = gradient_opacity(classify(u_gopacity_param.x).a, v, length(gradient_at(p, v)));
#else
                float a = classify(v).a;
#if GOPACITY == 1
                a = gradient_opacity(a, v, length(gradient_at(p, v)));
#endif
#endif
#ifdef LABEL_SHADOWS
                LabelRay lr = label_ray(p, vec3(0.0, 0.0, 1.0), 0.0, 1.0);
                LabelHit h = label_at(lr, label_q(p));
                // only inside shown labels; what is shown keeps the transfer function's
                // opacity in every mode (a surface label's own alpha, taken per voxel of
                // path, darkened the label's own surface: it is drawn once per crossing)
                if (h.id == LABEL_NONE) a = 0.0;
#endif
                // a = 1 is opaque: 1e-4 left after one voxel is dark enough
                depth -= log(max(1.0 - a, 1e-4));
            }
    imageStore(u_dst, c, vec4(depth / float(u_sub.x * u_sub.y * u_sub.z)));
}
#elif PASS == 3
layout(r16f, binding = VXL_IMAGE_OUT) uniform image3D u_dst; // read and written: each cell its own texel
#else
#if PASS == 4
layout(rgba16f, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_dst;
#else
layout(r16f, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_dst;
#endif
uniform sampler3D u_extinction; // pass 0's result, trilinear
uniform float u_ext_step;       // voxels: its smallest cell, the step its integrals take

// Optical depth per voxel at voxel position p (clamped to the box's cells).
float extinction(vec3 p) { return textureLod(u_extinction, voxel_to_tex(p), 0.0).r; }

void store(ivec3 c, float t) { imageStore(u_dst, c + ivec3(0, 0, u_block * u_cells.z), vec4(t)); }

// Where the ray from p along unit d leaves the volume box (0 if outside).
float box_exit(vec3 p, vec3 d)
{
    vec3 far = mix(vec3(-0.5), u_dims - 0.5, step(0.0, d));
    vec3 t = vec3(1e30);
    for (int a = 0; a < 3; a++)
        if (abs(d[a]) > 1e-12) t[a] = (far[a] - p[a]) / d[a];
    return max(0.0, min(t.x, min(t.y, t.z)));
}
#endif

#if PASS == 1
uniform sampler3D u_previous; // u_dst itself: the previous slices, written by earlier dispatches
uniform int u_axis;           // the sweep's axis
uniform int u_slice;          // the slice this dispatch writes
uniform int u_first;          // 1 on the slice nearest the light: nothing lies before it
uniform float u_from;         // voxel coordinate along the axis where the sweep starts (box face or the light's plane)
uniform vec4 u_light;         // voxel space: w = 0 the unit direction the light travels, 1 its position
uniform float u_spread;       // directional: tan(half its angular diameter); point: its radius in voxels

// The previous slice's transmittance at voxel position q (on that slice's
// centre plane): bilinear between cell centres, and 1 (nothing in the way)
// beyond the box, blended over the border cell as a border colour would be.
float previous(vec3 q)
{
    vec3 x = (q + 0.5) / u_cell;
    vec3 n = vec3(u_cells);
    vec3 outside = clamp(0.5 - x, 0.0, 1.0) + clamp(x - (n - 0.5), 0.0, 1.0);
    outside[u_axis] = 0.0;
    float inside = (1.0 - outside.x) * (1.0 - outside.y) * (1.0 - outside.z);
    x = clamp(x, vec3(0.5), n - 0.5);
    x.z += float(u_block) * n.z;
    vec3 size = vec3(textureSize(u_previous, 0));
    float t = textureLod(u_previous, x / size, 0.0).r;
    return inside * t + (1.0 - inside);
}

void main()
{
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    int a1 = (u_axis + 1) % 3, a2 = (u_axis + 2) % 3;
    if (s.x >= u_cells[a1] || s.y >= u_cells[a2]) return;
    ivec3 c;
    c[u_axis] = u_slice;
    c[a1] = s.x;
    c[a2] = s.y;
    vec3 p = cell_centre(c);
    // the light's travel to this cell: one direction (directional), or
    // radially from the light (point; the sweep moves away from its plane)
    vec3 d = u_light.xyz;
    float spread = u_spread, dist = 1e30;
    if (u_light.w != 0.0) {
        vec3 from_light = p - u_light.xyz;
        dist = length(from_light);
        if (!(dist > 1e-6)) { store(c, 1.0); return; }
        d = from_light / dist;
        spread = u_spread / dist;
    }
    // back along d to the previous slice's centre plane, or to where the sweep starts
    float along = u_first != 0 ? abs(p[u_axis] - u_from) : u_cell[u_axis];
    // (a cell in a point light's own plane reaches it within that plane)
    float seg = abs(d[u_axis]) > 1e-6 ? min(along / abs(d[u_axis]), dist) : dist;
    vec3 q = p - d * seg;
    float t_prev = 1.0;
    if (u_first == 0) {
        t_prev = previous(q);
        float r = seg * spread; // the light's disc, seen from p, one slice back
        if (r > 0.05 * min(u_cell[a1], u_cell[a2])) {
            vec3 e1 = vec3(0.0), e2 = vec3(0.0);
            e1[a1] = r;
            e2[a2] = r;
            t_prev = (2.0 * t_prev + previous(q + e1) + previous(q - e1) + previous(q + e2) + previous(q - e2)) / 6.0;
        }
    }
    // the segment's optical depth, midpoint rule, a sample per extinction
    // cell or so (oblique segments near a point light's plane are long)
    int n = int(clamp(ceil(seg / u_ext_step), 1.0, 16.0));
    float depth = 0.0;
    for (int k = 0; k < n; k++) depth += extinction(mix(p, q, (float(k) + 0.5) / float(n)));
    store(c, t_prev * exp(-depth * seg / float(n)));
}
#endif

#if PASS == 2
uniform float u_radius; // voxels

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, u_cells))) return;
    vec3 p = cell_centre(c);
    int n = int(clamp(ceil(2.0 * u_radius / u_ext_step), 2.0, 8.0));
    float h = u_radius / float(n);
    float sum = 0.0;
    for (int i = 0; i < 14; i++) {
        // the 6 faces and 8 corners of a cube
        vec3 d = i < 6 ? vec3(i == 0 ? 1 : i == 1 ? -1 : 0, i == 2 ? 1 : i == 3 ? -1 : 0, i == 4 ? 1 : i == 5 ? -1 : 0)
                       : normalize(vec3((i & 1) != 0 ? 1.0 : -1.0, (i & 2) != 0 ? 1.0 : -1.0, (i & 4) != 0 ? 1.0 : -1.0));
        float len = min(u_radius, box_exit(p, d)); // nothing occludes beyond the box
        float depth = 0.0;
        for (int k = 0; k < n; k++) {
            float t = (float(k) + 0.5) * h;
            if (t < len) depth += h * extinction(p + d * t);
        }
        sum += exp(-depth);
    }
    store(c, sum / 14.0);
}
#endif

#if PASS == 3
#include "lib/shadow_maps.glsl"
uniform mat4 u_model; // voxel -> world

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, u_cells))) return;
    float v = shadow_visibility((u_model * vec4(cell_centre(c), 1.0)).xyz);
    ivec3 t = c + ivec3(0, 0, u_block * u_cells.z);
    if (v < 1.0) imageStore(u_dst, t, imageLoad(u_dst, t) * v);
}
#endif

#if PASS == 4
uniform vec3 u_env_dir[ENV_CELLS];      // voxel space, unit: towards each cell of the sky
uniform vec3 u_env_radiance[ENV_CELLS]; // each cell's radiance / ENV_CELLS (equal solid angles)
uniform float u_env_start;              // voxels: half a cell, where each path starts

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, u_cells))) return;
    vec3 p = cell_centre(c);
    vec3 e = vec3(0.0);
    for (int k = 0; k < ENV_CELLS; k++) {
        vec3 d = u_env_dir[k];
        float len = box_exit(p, d) - u_env_start; // nothing occludes beyond the box
        float depth = 0.0;
        if (len > 0.0) {
            // midpoint rule at about two extinction cells a sample: 32 such
            // paths per cell are the pass's cost, and the irradiance is a
            // mean over them, smoother than any one light's shadow
            int n = int(clamp(ceil(len / (2.0 * u_ext_step)), 1.0, 16.0));
            float h = len / float(n);
            for (int i = 0; i < n; i++) depth += h * extinction(p + d * (u_env_start + (float(i) + 0.5) * h));
        }
        e += u_env_radiance[k] * exp(-depth);
    }
    imageStore(u_dst, c, vec4(min(e, vec3(65504.0)), 1.0)); // half float's largest, never inf
}
#endif
