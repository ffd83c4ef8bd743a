// raycast.frag - front-to-back ray casting with premultiplied compositing.
// Variants by define: FILTER_* (lib/gradients.glsl), SHADING, REUSE_GRADIENTS,
// CLASSIFY_PRE / CLASSIFY_PREINT (lib/classify.glsl; post-classification otherwise),
// GOPACITY 1 (boundary) / 2 (iso-surface): Levoy's gradient-magnitude opacity,
// DATA_COLOUR: a colour volume's colour replaces the table's (lib/colour.glsl),
// SHADING_MODEL 1 (shadowed) / 2 (scatter): lib/shading.glsl's shade_lit,
// CHANNEL_GROUPS: a multi-channel volume's channels in one march (lib/channels.glsl).
#include "lib/gradients.glsl"
#include "lib/classify.glsl"
#include "lib/colour.glsl" // DATA_COLOUR: a colour volume's own colour
#include "lib/shading.glsl"
#include "lib/cut.glsl" // cutaways: CUT_CONVEX, CUT_CUTTERS
#include "lib/matcap.glsl"
#include "lib/ray_box.glsl"

#ifndef GOPACITY
#define GOPACITY 0
#endif

uniform mat4 u_ray_near;     // vec4(ndc.xy, 0, 1) -> homogeneous voxel point at ndc z = -1
uniform mat4 u_ray_far;      // the same at ndc z = +1 (both folded in double: see frame.h)
uniform mat4 u_mv;           // voxel -> view space
uniform vec2 u_viewport;     // pixels
uniform float u_step;        // voxels
uniform int u_max_steps;     // hard bound on samples per ray
uniform uint u_jitter_seed;
uniform int u_jitter;
uniform float u_early_termination;
uniform float u_depth_threshold;
uniform int u_has_scene_depth;
uniform sampler2D u_scene_depth; // view-space planar distance, +inf = none
uniform int u_skip;               // empty-space skipping on
uniform int u_brick_size;         // voxels per brick edge
uniform usampler3D u_brick_distance; // 0 occupied; k: bricks within k-1 are empty

// Work counters for vxl_renderer_get_stats: one atomic per ray, not per sample.
layout(std430, binding = VXL_SSBO_STATS) buffer Stats { uint st_samples_lo; uint st_samples_hi; uint st_max_ray; uint st_rays; };

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;

// Integer hash (PCG-style): deterministic per pixel and seed, no texture.
float jitter_hash(uvec2 px, uint seed)
{
    uint v = px.x * 1973u + px.y * 9277u + seed * 26699u + 1u;
    v = v * 747796405u + 2891336453u;
    v = ((v >> ((v >> 28u) + 4u)) ^ v) * 277803737u;
    v = (v >> 22u) ^ v;
    return float(v) * (1.0 / 4294967296.0);
}

void emit_nothing()
{
    o_color = vec4(0.0);
    o_depth = uintBitsToFloat(0x7f800000u); // +inf
}

// What march knows of a ray for add_sample: view-space position pos0 + t *
// dpos, planar distance z0 + t * dz, the lighting (shade()).
struct RaySetup {
    float z0, dz;
    vec3 pos0, dpos;
    bool one_directional;
#ifdef SHADING
    RayLighting lighting;
#endif
};

#ifdef SHADING
// The lit colour of a surface or sample with colour rgb and normal g at ray
// parameter t (voxel position p): the MatCap, the shading model (shadows,
// occlusion: lib/shading.glsl's shade_lit) or local Phong. One place for
// add_sample, the ISO mode (lib/modes.glsl) and label surfaces (lib/labels.glsl).
vec3 shade_at(vec3 rgb, vec3 g, float t, vec3 p, RaySetup r)
{
#ifdef MATCAP
    return shade_matcap(rgb, g, r.lighting.v); // lib/matcap.glsl
#elif SHADING_MODEL > 0
    return shade_lit(rgb, g, r.pos0 + t * r.dpos, p, r.lighting, r.one_directional);
#else
    return shade(rgb, g, r.pos0 + t * r.dpos, r.lighting, r.one_directional);
#endif
}
#endif

// What add_sample carries from sample to sample.
struct Compositing {
    vec4 acc; // premultiplied
    float depth;
#ifdef REUSE_GRADIENTS
    // "previous sample" is the previous sample along the ray: a transparent
    // or skipped one has no gradient, so the state restarts after it
    GradientState gs;
    int last_shaded;
#endif
};

// The work on sample i, at t, position p, value v, that adds something: c is
// its straight colour and per-voxel opacity (the premultiplied segment for
// CLASSIFY_PREINT, the final opacity for GOPACITY 2, whose gradient is g).
// Opacity correction, gradient, shading, compositing into s; false once the
// ray is opaque enough to stop.
bool add_sample(inout Compositing s, RaySetup r, int i, float t, vec3 p, float v, vec4 c, vec3 g)
{
#if GOPACITY == 2
    float a = c.a;
    vec3 rgb = c.rgb;
#elif defined(CLASSIFY_PREINT)
    float a = c.a;
    vec3 rgb = c.rgb / a;
#else
    float a = correct_opacity(c.a, u_step);
    vec3 rgb = c.rgb;
#endif
#if GOPACITY == 1
    g = gradient_at(p, v);
    a = gradient_opacity(a, v, length(g)); // region boundaries: scaled by |grad|
    if (a <= 0.0) return true;
#endif
#ifdef SHADING
#if GOPACITY == 0
    g = gradient_at(p, v);
#endif
#ifdef REUSE_GRADIENTS
    if (s.last_shaded != i - 1) s.gs = gradient_state_init();
    s.last_shaded = i;
    g = reuse_gradient(s.gs, g);
#endif
    CUT_CAP(g, t); // the first sample behind a cut takes the cut's normal (lib/cut.glsl)
    rgb = shade_at(rgb, g, t, p, r);
#endif
    s.acc += (1.0 - s.acc.a) * a * vec4(rgb, 1.0);
    if (isinf(s.depth) && s.acc.a >= u_depth_threshold) s.depth = -(r.z0 + r.dz * t);
    return s.acc.a < u_early_termination;
}

// With a gradient per visible sample, march's inner loop stops at each
// visible sample and the outer one does its work (see there); without, that
// work is too cheap to wait for and the inner loop does it on the way.
#if defined(SHADING) || GOPACITY == 1
#define DEFER_VISIBLE 1
#endif

#ifdef LABELS
#include "lib/labels.glsl" // label maps: label_mask, label_march
#endif
#ifdef OVERLAYS
#include "lib/overlays.glsl" // overlays: overlay_span, overlay_march
#endif

// One ray from t0 to t1 (o + t * dir in voxels): premultiplied colour, the
// depth where it reached u_depth_threshold, the samples taken.
vec4 march(vec3 o, vec3 dir, float t0, float t1, RaySetup r, out float depth, out uint taken)
{
    float jitter = u_jitter != 0 ? jitter_hash(uvec2(gl_FragCoord.xy), u_jitter_seed) : 0.0;
    // Sample positions are t_start + i * step for integer i, whether or not
    // empty space is skipped, so skipping changes no sample that counts.
    float t_start = t0 + jitter * u_step;
    Compositing s;
    s.acc = vec4(0.0);
    s.depth = uintBitsToFloat(0x7f800000u);
#ifdef REUSE_GRADIENTS
    s.gs = gradient_state_init();
    s.last_shaded = -2;
#endif
#ifdef CLASSIFY_PREINT
    // the first segment is a point: constant value over its step
    float v_prev = sample_value(o + t_start * dir);
#endif
    taken = 0u;
#if defined(LABELS) && LABELS > 1
    LabelRay lr = label_ray(o, dir, t_start, u_step); // the label bricks along the ray
    uint no_label = LABEL_NONE;
#endif
    // Two loops: the inner one walks over the samples that add nothing
    // (skipped or transparent), the outer one does the work of a sample that
    // adds something. On 8-wide SIMD (llvmpipe) every lane runs a branch that
    // any lane takes, so with one loop every lane paid for a gradient and
    // shading at every step where a neighbour needed them; here a lane that
    // found its next visible sample waits for the others to find theirs.
    int i = 0;
    for (;; i++) {
        bool visible = false;
        float t = 0.0, v = 0.0;
        vec3 p = vec3(0.0), g = vec3(0.0);
        vec4 c = vec4(0.0);
        for (; i < u_max_steps; i++) {
            t = t_start + float(i) * u_step;
            if (t >= t1) break;
#ifdef CUT_CUTTERS
            int cut_next = cut_leap(i, t, t_start, u_step, u_max_steps); // removed by a cutter
            if (cut_next >= 0) {
#ifdef CLASSIFY_PREINT
                v_prev = sample_value(o + (t_start + float(cut_next) * u_step) * dir); // a segment starts as a point
#endif
                i = cut_next - 1;
                continue;
            }
#endif
            p = o + t * dir;
            int leap = -1;
            if (u_skip != 0) {
                ivec3 b = ivec3(floor((p + 0.5) / float(u_brick_size)));
                uint k = texelFetch(u_brick_distance, clamp(b, ivec3(0), textureSize(u_brick_distance, 0) - 1), 0).r;
                if (k > 0u) {
                    // Leap to where the ray leaves the cube of 2k-1 empty bricks
                    // around this one (Chebyshev distance map); the loop's i++
                    // lands on the first sample past it.
                    leap = last_sample_before(brick_cube_exit(b, k, float(u_brick_size), o, dir), t_start, u_step,
                                              u_max_steps, i);
#ifndef CLASSIFY_PREINT
                    i = leap;
                    continue;
#endif
                }
            }
#if defined(LABELS) && LABELS > 1 && !defined(CLASSIFY_PREINT)
            int label_next = label_leap(lr, i, t, label_q(p), no_label); // no visible label here
            if (label_next >= 0) {
                i = label_next - 1;
                continue;
            }
#endif
            taken++;
            v = sample_value(p);
#if GOPACITY == 2
            // iso-surface of constant thickness: the colour and opacity of the
            // iso value, fading out over iso_thickness voxels of the gradient
            c = classify(u_gopacity_param.x);
            g = gradient_at(p, v);
            c.a = correct_opacity(gradient_opacity(c.a, v, length(g)), u_step);
#elif defined(CLASSIFY_PREINT)
            // A segment ending in an empty brick is still integrated: its front
            // may lie in an occupied one. After a leap the next segment starts
            // from the last sample inside the empty region.
            c = preint_segment(v_prev, v);
            if (leap >= 0 && leap > i) {
                i = leap;
                v_prev = sample_value(o + (t_start + float(i) * u_step) * dir);
            } else {
                v_prev = v;
            }
#elif defined(CLASSIFY_PRE)
            c = pre_classified(p);
#else
            c = classify(v);
#endif
#ifdef DATA_COLOUR
#ifdef CLASSIFY_PREINT
            if (c.a > 0.0) c.rgb = data_colour(p) * c.a; // the segment is premultiplied
#else
            if (c.a > 0.0) c = with_data_colour(c, p);
#endif
#endif
#if defined(LABELS) && LABELS > 1
            if (c.a > 0.0) c = label_mask(lr, p, c); // only inside visible labels
#endif
            if (c.a <= 0.0) continue;
#ifdef DEFER_VISIBLE
            visible = true;
            break;
#else
            if (!add_sample(s, r, i, t, p, v, c, g)) break;
#endif
        }
        if (!visible || !add_sample(s, r, i, t, p, v, c, g)) break;
    }
    depth = s.depth;
    return s.acc;
}

// MIP, MinIP, average and ISO (lib/modes.glsl) replace march in main().
#include "lib/modes.glsl"
#if MODE != 0
#define march mode_march
#endif
#if defined(LABELS) && LABELS == 1
#define march label_march // labels as surfaces
#endif
#ifdef OVERLAYS
#define march overlay_march // several volumes in one march
#endif
#include "lib/channels.glsl" // CHANNEL_GROUPS: every channel of a multi-channel volume in one march
#ifdef CHANNEL_GROUPS
#define march channel_march
#endif

void main()
{
    vec2 ndc = gl_FragCoord.xy / u_viewport * 2.0 - 1.0;
    vec4 hn = u_ray_near * vec4(ndc, 0.0, 1.0);
    vec4 hf = u_ray_far * vec4(ndc, 0.0, 1.0);
    vec3 o = hn.xyz / hn.w;
    // The direction from the homogeneous points without dividing by hf.w,
    // which is ~0 for a far plane at 1e9 (or infinity) in float.
    vec3 dir = hf.xyz * hn.w - hn.xyz * hf.w;
    float len = length(dir);
    float t_far = hn.w * hf.w > 0.0 ? len / (hn.w * hf.w) : uintBitsToFloat(0x7f800000u);
    if (!(len > 0.0) || isinf(len) || any(isnan(o)) || any(isinf(o)) || isnan(t_far)) { emit_nothing(); return; }
    dir /= len;

    // The part of the ray inside the volume's box (lib/ray_box.glsl).
    float t0 = 0.0, t1 = t_far;
#ifdef OVERLAYS
    if (!overlay_span(o, dir, t_far, t0, t1)) { emit_nothing(); return; } // the union of all boxes
#else
    if (!box_clip(o, dir, vec3(-0.5), u_dims - 0.5, t0, t1)) { emit_nothing(); return; }
#endif
    // View-space planar distance along the ray is affine in t.
    vec4 row2 = vec4(u_mv[0][2], u_mv[1][2], u_mv[2][2], u_mv[3][2]);
    float z0 = dot(row2, vec4(o, 1.0)), dz = dot(row2.xyz, dir);
    if (u_has_scene_depth != 0 && dz < 0.0) {
        float d = texelFetch(u_scene_depth, ivec2(gl_FragCoord.xy), 0).r;
        if (!isnan(d)) t1 = min(t1, (-d - z0) / dz);
    }
    if (!(t0 < t1)) { emit_nothing(); return; }
#ifdef CUT_ANY
    if (!cut_begin(o, dir, z0, dz, t0, t1)) { emit_nothing(); return; } // only the kept part (lib/cut.glsl)
#endif

    // View-space position is affine in t too: no matrix product per sample.
    RaySetup r;
    r.z0 = z0;
    r.dz = dz;
    r.pos0 = (u_mv * vec4(o, 1.0)).xyz;
    r.dpos = mat3(u_mv) * dir;
    r.one_directional = true;
    float depth;
    uint taken;
#ifdef SHADING
    r.lighting = ray_lighting(-normalize(r.dpos));
    // Two copies of the march, one without a loop over the lights (shade()):
    // one_directional is a constant at each call.
    vec4 acc;
    if (u_light_count == 1 && u_light_pos[0].w == 0.0) {
        acc = march(o, dir, t0, t1, r, depth, taken);
    } else {
        r.one_directional = false;
        acc = march(o, dir, t0, t1, r, depth, taken);
    }
#else
    vec4 acc = march(o, dir, t0, t1, r, depth, taken);
#endif
    uint old = atomicAdd(st_samples_lo, taken);
    if (old + taken < old) atomicAdd(st_samples_hi, 1u); // carry into the high word
    atomicMax(st_max_ray, taken);
    atomicAdd(st_rays, 1u);
    o_color = vec4(clamp_colour(acc.rgb), clamp(acc.a, 0.0, 1.0));
    o_depth = depth;
}
