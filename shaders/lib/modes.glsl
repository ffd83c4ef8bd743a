// modes.glsl - the render modes beside DVR (voxlight.h's
// VXL_MODE_*), one per program by MODE: 1 MIP, 2 MinIP, 3 average (the
// projections), 4 ISO (the first crossing of the iso value). Included by
// render/raycast.frag after its march (it uses RaySetup, jitter_hash and
// the frame's uniforms); with MODE 0 nothing here is compiled, so DVR's
// program is today's.
//
// Brick skipping: a projection or surface depends on values, not on the
// table's opacity, so the occupancy distance map of DVR cannot be used
// (a transparent brick may hold the maximum). Instead, with u_mode_skip, the
// per-brick min-max grid (the skipping grid's, apron included, so it bounds
// every trilinear sample inside the brick) lets MIP leap over a brick whose
// max cannot beat the running maximum, MinIP over one whose min cannot beat
// the running minimum or whose max lies below MinIP's floor, and ISO over one whose range excludes the iso value.
// AVERAGE needs every sample. The sample positions are t_start + i * step
// whether or not bricks are skipped, so skipping changes no result.
#include "lib/ray_box.glsl"
#ifndef MODE
#define MODE 0
#endif

#if MODE != 0
uniform int u_mode_skip;             // min-max brick skipping on
uniform sampler3D u_brick_minmax;    // RG: normalised min, max per brick of u_brick_size voxels
uniform float u_iso;                 // ISO: the iso value, normalised
uniform float u_minip_floor;         // MinIP: samples below it are not candidates (normalised; -1e30 off)

// The brick of voxel position p and its min-max.
vec2 brick_range(vec3 p, out ivec3 b)
{
    b = ivec3(floor((p + 0.5) / float(u_brick_size)));
    return texelFetch(u_brick_minmax, clamp(b, ivec3(0), textureSize(u_brick_minmax, 0) - 1), 0).rg;
}

// The index of the last sample inside brick b (at least i): the sample
// loop's i++ lands on the first one past it.
int brick_last_sample(ivec3 b, vec3 o, vec3 dir, float t_start, int i)
{
    return last_sample_before(brick_cube_exit(b, 1u, float(u_brick_size), o, dir), t_start, u_step, u_max_steps, i);
}
#endif

#if MODE == 1 || MODE == 2 || MODE == 3
// The projection of the samples t_start + i * step in [t0, t1): their max,
// min or mean, classified as one layer (colour and opacity of the table at
// that value, no opacity correction); depth where the projected sample lies
// (MIP, MinIP; the first at ties) or where the ray enters (average), when
// the opacity reaches u_depth_threshold.
vec4 project_march(vec3 o, vec3 dir, float t0, float t1, RaySetup r, out float depth, out uint taken)
{
    float jitter = u_jitter != 0 ? jitter_hash(uvec2(gl_FragCoord.xy), u_jitter_seed) : 0.0;
    float t_start = t0 + jitter * u_step;
    depth = uintBitsToFloat(0x7f800000u);
    taken = 0u;
#if MODE == 3
    float sum = 0.0, t_first = t0; // where the kept volume begins: a cutter may remove the front
#ifdef DATA_COLOUR
    vec3 colour_sum = vec3(0.0); // a colour volume's average projects its mean colour
#endif
#else
    float best = 0.0, t_best = t0;
    bool found = false; // best holds a candidate sample
#endif
    for (int i = 0; i < u_max_steps; i++) {
        float t = t_start + float(i) * u_step;
        if (t >= t1) break;
        CUT_SKIP_REMOVED(i, t, t_start) // lib/cut.glsl: a cutter's removed interval
        vec3 p = o + t * dir;
#if MODE == 1
        if (u_mode_skip != 0 && found) {
            ivec3 b;
            vec2 mm = brick_range(p, b);
            if (mm.y <= best) {
                i = brick_last_sample(b, o, dir, t_start, i);
                continue;
            }
        }
#elif MODE == 2
        if (u_mode_skip != 0) {
            ivec3 b;
            vec2 mm = brick_range(p, b);
            // a brick wholly below the floor holds no candidate either
            if ((found && mm.x >= best) || mm.y < u_minip_floor) {
                i = brick_last_sample(b, o, dir, t_start, i);
                continue;
            }
        }
#endif
        float v = sample_value(p);
        taken++;
#if MODE == 3
        if (taken == 1u && i > 0) t_first = t; // only a cutter's leap makes the first sample's index > 0
        sum += v;
#ifdef DATA_COLOUR
        colour_sum += data_colour(p);
#endif
#else
#if MODE == 1
        bool better = !found || v > best;
#else
        bool better = v >= u_minip_floor && (!found || v < best);
#endif
        if (better) {
            best = v;
            t_best = t;
            found = true;
        }
#endif
    }
#if MODE == 3
    if (taken == 0u) return vec4(0.0);
#else
    if (!found) return vec4(0.0);
#endif
#if MODE == 3
    float v = sum / float(taken);
    float t_depth = t_first;
#else
    float v = best;
    float t_depth = t_best;
#endif
    vec4 c = classify(v);
#ifdef DATA_COLOUR
#if MODE == 3
    c.rgb = colour_sum / float(taken);
#else
    c.rgb = data_colour(o + t_depth * dir); // the colour where the projected sample lies
#endif
#endif
    if (c.a >= u_depth_threshold) depth = -(r.z0 + r.dz * t_depth);
    return vec4(c.rgb * c.a, c.a);
}
#endif

#if MODE == 4
#define ISO_BISECTIONS 12

// The first crossing of u_iso between two samples, refined by bisection on
// sample_value (the reconstruction every mode samples: the texture's
// trilinear interpolant, whatever the gradient filter) and a last secant
// step inside the final bracket; shaded as a surface with the table's colour
// at the iso value, opacity 1, depth at the hit. The refinement's taps, like
// gradient taps, are not samples of the march (the stats' sample bound).
vec4 iso_march(vec3 o, vec3 dir, float t0, float t1, RaySetup r, out float depth, out uint taken)
{
    float jitter = u_jitter != 0 ? jitter_hash(uvec2(gl_FragCoord.xy), u_jitter_seed) : 0.0;
    float t_start = t0 + jitter * u_step;
    depth = uintBitsToFloat(0x7f800000u);
    taken = 0u;
    bool have_prev = false, prev_above = false;
    int last_i = -1; // the sample before i, unless a cutter removed what lies between
    bool hit = false;
    float t_prev = t0, t_hit = t0;
    for (int i = 0; i < u_max_steps; i++) {
        float t = t_start + float(i) * u_step;
        if (t >= t1) break;
        CUT_SKIP_REMOVED(i, t, t_start) // lib/cut.glsl: a cutter's removed interval
        if (i != last_i + 1) have_prev = false; // no crossing across a removed interval
        last_i = i;
        vec3 p = o + t * dir;
        if (u_mode_skip != 0) {
            ivec3 b;
            vec2 mm = brick_range(p, b);
            bool above = mm.x >= u_iso;
            // the whole brick lies on one side: no crossing inside it, nor
            // with the previous sample when that was on the same side
            if ((above || mm.y < u_iso) && (!have_prev || above == prev_above)) {
                i = brick_last_sample(b, o, dir, t_start, i);
                last_i = i;
                t_prev = t_start + float(i) * u_step;
                have_prev = true;
                prev_above = above;
                continue;
            }
        }
        taken++;
        bool above = sample_value(p) >= u_iso;
        if (have_prev && above != prev_above) {
            float a = t_prev, b = t;
            for (int k = 0; k < ISO_BISECTIONS; k++) {
                float m = 0.5 * (a + b);
                if ((sample_value(o + m * dir) >= u_iso) == prev_above) a = m;
                else b = m;
            }
            float va = sample_value(o + a * dir), vb = sample_value(o + b * dir);
            float w = vb != va ? clamp((u_iso - va) / (vb - va), 0.0, 1.0) : 0.5;
            t_hit = mix(a, b, w);
            hit = true;
            break;
        }
        have_prev = true;
        prev_above = above;
        t_prev = t;
    }
    if (!hit) return vec4(0.0);
    vec3 rgb = classify(u_iso).rgb;
#ifdef DATA_COLOUR
    rgb = data_colour(o + t_hit * dir); // a colour volume's colour at the hit
#endif
#ifdef SHADING
    vec3 p = o + t_hit * dir;
    vec3 g = gradient_at(p, u_iso);
    rgb = shade_at(rgb, g, t_hit, p, r);
#endif
    depth = -(r.z0 + r.dz * t_hit);
    return vec4(rgb, 1.0);
}
#endif

#if MODE != 0
// The mode's march, called by raycast.frag's main() in place of march().
vec4 mode_march(vec3 o, vec3 dir, float t0, float t1, RaySetup r, out float depth, out uint taken)
{
#if MODE == 4
    return iso_march(o, dir, t0, t1, r, depth, taken);
#else
    return project_march(o, dir, t0, t1, r, depth, taken);
#endif
}
#endif
