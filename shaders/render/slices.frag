// slices.frag - one fragment of a slice (csrc/slices.c): the ray caster's
// sample (lib/ files: sampling, classification, gradient filter, shading)
// at the slice point, composited front to back into the colour and depth
// attachments, read and written as images (one fragment per pixel per
// slice; slices.c puts a barrier between slices). Variants as raycast.frag:
// FILTER_*, SHADING, CLASSIFY_PRE (pre-integration needs segments and is
// refused), GOPACITY 1 / 2. REUSE_GRADIENTS has nothing to reuse here.
#include "lib/gradients.glsl"
#include "lib/classify.glsl"
#include "lib/colour.glsl" // DATA_COLOUR: a colour volume's own colour
#include "lib/shading.glsl"

#ifndef GOPACITY
#define GOPACITY 0
#endif

layout(binding = VXL_IMAGE_SLICE_ACCUM, rgba32f) uniform coherent image2D u_accum; // premultiplied
layout(binding = VXL_IMAGE_SLICE_DEPTH, r32f) uniform coherent image2D u_depth_out;
uniform mat4 u_mv;               // voxel -> view space
uniform vec4 u_eye;              // voxel space: eye position (w = 1), or unit viewing direction (w = 0)
uniform vec3 u_slice_normal;     // voxel space, unit
uniform float u_slice_spacing;   // voxels along u_slice_normal
uniform float u_early_termination;
uniform float u_depth_threshold;
uniform int u_has_scene_depth;
uniform sampler2D u_scene_depth; // view-space planar distance, +inf = none
uniform int u_skip;               // empty-space skipping on (render.c binds the map as for the ray caster)
uniform int u_brick_size;         // voxels per brick edge
uniform usampler3D u_brick_distance; // 0 occupied: a sample in any other brick adds nothing

in vec3 v_pos;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 p = v_pos;
    if (u_skip != 0) {
        ivec3 b = ivec3(floor((p + 0.5) / float(u_brick_size)));
        if (texelFetch(u_brick_distance, clamp(b, ivec3(0), textureSize(u_brick_distance, 0) - 1), 0).r > 0u) return;
    }
    vec4 acc = imageLoad(u_accum, px);
    if (acc.a >= u_early_termination) return; // the ray caster would have stopped
    vec3 view_pos = (u_mv * vec4(p, 1.0)).xyz;
    float z = -view_pos.z; // planar distance, the depth output's convention
    if (u_has_scene_depth != 0) {
        float d = texelFetch(u_scene_depth, px, 0).r;
        if (!isnan(d) && z > d) return; // behind the host scene
    }
    // The path this sample stands for: the distance along this pixel's ray
    // to the next plane, in voxels (the ray caster's step).
    vec3 dir = u_eye.w != 0.0 ? normalize(p - u_eye.xyz) : u_eye.xyz;
    float seg = u_slice_spacing / max(abs(dot(dir, u_slice_normal)), 1e-3);
    float v = sample_value(p);
    vec3 g = vec3(0.0);
#if GOPACITY == 2
    vec4 c = classify(u_gopacity_param.x);
    g = gradient_at(p, v);
    float a = correct_opacity(gradient_opacity(c.a, v, length(g)), seg);
#else
#ifdef CLASSIFY_PRE
    vec4 c = pre_classified(p);
#else
    vec4 c = classify(v);
#endif
    if (c.a <= 0.0) return;
#endif
#ifdef DATA_COLOUR
    c = with_data_colour(c, p); // a colour volume's own colour
#endif
#if GOPACITY != 2
    float a = correct_opacity(c.a, seg);
#endif
    vec3 rgb = c.rgb;
#if GOPACITY == 1
    g = gradient_at(p, v);
    a = gradient_opacity(a, v, length(g));
#endif
    if (a <= 0.0) return;
#ifdef SHADING
#if GOPACITY == 0
    g = gradient_at(p, v);
#endif
    vec3 view_dir = u_eye.w != 0.0 ? normalize(view_pos) : vec3(0.0, 0.0, -1.0);
    bool one_directional = u_light_count == 1 && u_light_pos[0].w == 0.0;
    rgb = shade(rgb, g, view_pos, ray_lighting(-view_dir), one_directional);
#endif
    float before = acc.a;
    acc = clamp(acc + (1.0 - acc.a) * a * vec4(rgb, 1.0), 0.0, 1.0);
    imageStore(u_accum, px, acc);
    if (before < u_depth_threshold && acc.a >= u_depth_threshold) imageStore(u_depth_out, px, vec4(z));
}
