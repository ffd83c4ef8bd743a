// overlays.glsl - overlays (docs/overlays.md; the GL side is
// csrc/overlay/overlays.c). OVERLAYS (1..3) more volumes are sampled in the
// base volume's ray march: overlay_march replaces march. The ray walks the
// union of all boxes (overlay_span) in the base volume's voxel steps, at
// t_start + i * step whether or not it skips; at each step every volume
// whose box holds the sample is sampled (overlay k at u_ov_from_vox[k] *
// base voxel position), classified by its own table, window and opacity
// scale, step-corrected and lit by shade_at with its own gradient, then the
// step's samples combine by blend (voxlight.h): OVER ones (the base volume
// among them) as one medium, MAX ones take the step where their opacity is
// larger, ADD ones add emission. The program lists overlays OVER first,
// then MAX, then ADD (overlays.c), the order they combine in. A leap skips
// only where every volume is empty: the nearest exit of all their empty
// regions, each found in its own voxels with the shared ray parameter t.
#include "lib/ray_box.glsl"
#ifdef OVERLAYS

uniform sampler3D u_ov_volume[OVERLAYS];    // normalised texels, linear, clamp to edge
uniform sampler1D u_ov_tf[OVERLAYS];        // straight RGBA, opacity per voxel of the base's path
uniform usampler3D u_ov_distance[OVERLAYS]; // 0 occupied; k: bricks within k-1 are empty
uniform mat4 u_ov_from_vox[OVERLAYS];       // base voxel -> overlay voxel
uniform mat3 u_ov_grad_to_vox[OVERLAYS];    // overlay-voxel gradient -> base-voxel gradient
uniform vec3 u_ov_dims[OVERLAYS];
uniform vec4 u_ov_class[OVERLAYS];          // window offset, window scale, table size, opacity scale
uniform int u_ov_blend[OVERLAYS];           // VXL_BLEND_*: 0 over, 1 add, 2 max
uniform int u_ov_interp[OVERLAYS];          // VXL_INTERP_*: 0 nearest, 1 linear, 2 cubic B-spline
uniform int u_ov_shading[OVERLAYS];         // 1: lit; 0: emission only
uniform int u_ov_brick_size[OVERLAYS];      // voxels per brick edge of the distance map

// The part [ta, tb] of the ray o + t * d (t in [0, t_far]) inside the box
// [lo, hi]; false when it misses (lib/ray_box.glsl's slab test).
bool ov_box_span(vec3 o, vec3 d, vec3 lo, vec3 hi, float t_far, out float ta, out float tb)
{
    ta = 0.0;
    tb = t_far;
    return box_clip(o, d, lo, hi, ta, tb) && ta < tb;
}

vec3 ov_origin(int k, vec3 o) { return (u_ov_from_vox[k] * vec4(o, 1.0)).xyz; }
vec3 ov_direction(int k, vec3 dir) { return mat3(u_ov_from_vox[k]) * dir; }

// The ray's span over the union of the base box and every overlay's box.
bool overlay_span(vec3 o, vec3 dir, float t_far, out float t0, out float t1)
{
    t0 = uintBitsToFloat(0x7f800000u);
    t1 = 0.0;
    float a, b;
    if (ov_box_span(o, dir, vec3(-0.5), u_dims - 0.5, t_far, a, b)) {
        t0 = a;
        t1 = b;
    }
    for (int k = 0; k < OVERLAYS; k++)
        if (ov_box_span(ov_origin(k, o), ov_direction(k, dir), vec3(-0.5), u_ov_dims[k] - 0.5, t_far, a, b)) {
            t0 = min(t0, a);
            t1 = max(t1, b);
        }
    return t0 < t1;
}

bool ov_inside(vec3 q, vec3 dims) { return all(greaterThanEqual(q, vec3(-0.5))) && all(lessThanEqual(q, dims - 0.5)); }

// Overlay k's value at its voxel position q: the nearest texel, the
// trilinear interpolant, or the approximating cubic B-spline from 8
// trilinear fetches (each axis's 4 weights folded into 2 fetches between
// texels: Sigg and Hadwiger, GPU Gems 2, ch. 20).
float ov_value(int k, vec3 q)
{
    vec3 dims = u_ov_dims[k];
    if (u_ov_interp[k] == 0)
        return texelFetch(u_ov_volume[k], clamp(ivec3(floor(q + 0.5)), ivec3(0), ivec3(dims) - 1), 0).r;
    if (u_ov_interp[k] == 1) return textureLod(u_ov_volume[k], (q + 0.5) / dims, 0.0).r;
    vec3 b = floor(q), f = q - b, g = 1.0 - f, f2 = f * f;
    vec3 w0 = g * g * g / 6.0, w1 = (3.0 * f2 * f - 6.0 * f2 + 4.0) / 6.0;
    vec3 w2 = (-3.0 * f2 * f + 3.0 * f2 + 3.0 * f + 1.0) / 6.0, w3 = f2 * f / 6.0;
    vec3 s0 = w0 + w1, s1 = w2 + w3;
    vec3 h0 = (b - 1.0 + w1 / s0 + 0.5) / dims, h1 = (b + 1.0 + w3 / s1 + 0.5) / dims;
    float v = 0.0;
    for (int c = 0; c < 8; c++) {
        bvec3 hi = bvec3((c & 1) != 0, (c & 2) != 0, (c & 4) != 0);
        vec3 w = mix(s0, s1, vec3(hi));
        v += w.x * w.y * w.z * textureLod(u_ov_volume[k], mix(h0, h1, vec3(hi)), 0.0).r;
    }
    return v;
}

// Overlay k's straight colour and per-voxel opacity for value v (classify()'s lookup).
vec4 ov_classify(int k, float v)
{
    vec4 m = u_ov_class[k];
    float x = clamp((v - m.x) * m.y, 0.0, 1.0);
    vec4 c = textureLod(u_ov_tf[k], (x * (m.z - 1.0) + 0.5) / m.z, 0.0);
    c.a = clamp(c.a * m.w, 0.0, 1.0);
    return c;
}

#ifdef SHADING
// Overlay k's central-difference gradient at q (taps u_sample_distance of
// its own voxels apart), in base voxels.
vec3 ov_gradient(int k, vec3 q)
{
    float d = u_sample_distance;
    vec3 g = vec3(ov_value(k, q + vec3(d, 0, 0)) - ov_value(k, q - vec3(d, 0, 0)),
                  ov_value(k, q + vec3(0, d, 0)) - ov_value(k, q - vec3(0, d, 0)),
                  ov_value(k, q + vec3(0, 0, d)) - ov_value(k, q - vec3(0, 0, d))) / (2.0 * d);
    return u_ov_grad_to_vox[k] * g;
}
#endif

// Where a volume whose voxel-space ray is qo + t * qd (its box's span [ta,
// tb]) stops being empty after sample t: t itself in an occupied brick; the
// exit of the cube of 2k-1 empty bricks around it (the Chebyshev distance
// map, as march leaps); the box's entry before it; never after it.
float ov_empty_until(usampler3D dist, int bs, vec3 qo, vec3 qd, float t, float ta, float tb)
{
    if (!(ta < tb) || t > tb) return uintBitsToFloat(0x7f800000u);
    if (t < ta) return ta;
    vec3 q = qo + t * qd;
    ivec3 b = ivec3(floor((q + 0.5) / float(bs)));
    uint k = texelFetch(dist, clamp(b, ivec3(0), textureSize(dist, 0) - 1), 0).r;
    if (k == 0u) return t;
    return brick_cube_exit(b, k, float(bs), qo, qd);
}

// -ln(1 - a) >= 0, the optical depth of a step of opacity a; a series where
// 1 - a would round to 1 in float, a large finite depth for a = 1.
float ov_depth(float a)
{
    return a < 1e-3 ? a + a * a * (0.5 + a / 3.0) : -log(max(1.0 - a, 1e-30));
}

vec4 overlay_march(vec3 o, vec3 dir, float t0, float t1, RaySetup r, out float depth, out uint taken)
{
    float jitter = u_jitter != 0 ? jitter_hash(uvec2(gl_FragCoord.xy), u_jitter_seed) : 0.0;
    float t_start = t0 + jitter * u_step;
    const float t_huge = 1e30;
    float ba, bb;
    if (!ov_box_span(o, dir, vec3(-0.5), u_dims - 0.5, t_huge, ba, bb)) { ba = 1.0; bb = 0.0; }
    vec3 qo[OVERLAYS], qd[OVERLAYS];
    float ta[OVERLAYS], tb[OVERLAYS];
    for (int k = 0; k < OVERLAYS; k++) {
        qo[k] = ov_origin(k, o);
        qd[k] = ov_direction(k, dir);
        if (!ov_box_span(qo[k], qd[k], vec3(-0.5), u_ov_dims[k] - 0.5, t_huge, ta[k], tb[k])) {
            ta[k] = 1.0;
            tb[k] = 0.0;
        }
    }
    vec4 acc = vec4(0.0);
    depth = uintBitsToFloat(0x7f800000u);
    taken = 0u;
#if defined(LABELS) && LABELS > 1
    LabelRay lr = label_ray(o, dir, t_start, u_step); // the labels mask the base volume
#endif
    // Two loops, as march: the inner one walks the samples where no volume
    // is visible (skipped, or transparent in every volume), reading and
    // classifying only; the outer one shades and combines a sample where
    // one is. On 8-wide SIMD (llvmpipe) a lane that found its visible sample
    // waits for the others instead of making them all pay for gradients.
    int i = 0;
    for (;; i++) {
        bool visible = false;
        float t = 0.0, vb = 0.0;
        vec3 p = vec3(0.0);
        vec4 cb = vec4(0.0);         // the base volume's classified sample
        vec4 ck[OVERLAYS];           // each overlay's
        vec3 qk[OVERLAYS];           // and where it was read, in its voxels
        for (; i < u_max_steps; i++) {
            t = t_start + float(i) * u_step;
            if (t >= t1) break;
            CUT_SKIP_REMOVED(i, t, t_start) // cutters remove intervals from every volume
            if (u_skip != 0) {
                float t_exit = ov_empty_until(u_brick_distance, u_brick_size, o, dir, t, ba, bb);
                for (int k = 0; k < OVERLAYS; k++)
                    t_exit = min(t_exit, ov_empty_until(u_ov_distance[k], u_ov_brick_size[k], qo[k], qd[k], t, ta[k], tb[k]));
                if (t_exit > t) { // every volume is empty here: on to the first sample at or past the nearest exit
                    int next = int(min(ceil((t_exit - t_start) / u_step - 1e-3), float(u_max_steps)));
                    i = max(i, next - 1);
                    continue;
                }
            }
            taken++;
            p = o + t * dir;
            cb = vec4(0.0);
            if (ov_inside(p, u_dims)) { // the base volume, nothing outside its box
                vb = sample_value(p);
#ifdef CLASSIFY_PRE
                cb = pre_classified(p);
#else
                cb = classify(vb);
#endif
#ifdef DATA_COLOUR
                if (cb.a > 0.0) cb = with_data_colour(cb, p); // a colour volume's own colour
#endif
#if defined(LABELS) && LABELS > 1
                if (cb.a > 0.0) cb = label_mask(lr, p, cb); // only inside visible labels
#endif
            }
            bool any = cb.a > 0.0;
            for (int k = 0; k < OVERLAYS; k++) {
                qk[k] = qo[k] + t * qd[k];
                ck[k] = ov_inside(qk[k], u_ov_dims[k]) ? ov_classify(k, ov_value(k, qk[k])) : vec4(0.0);
                any = any || ck[k].a > 0.0;
            }
            if (any) {
                visible = true;
                break;
            }
        }
        if (!visible) break;
        // OVER: one medium. Opacities combine as 1 - prod(1 - a_i) (written
        // a + a_i (1 - a) so a single volume keeps its a exactly), colours by
        // their share of the optical depth ln(1 - a_i).
        float a_over = 0.0, od = 0.0;
        vec3 od_rgb = vec3(0.0);
        if (cb.a > 0.0) {
            float a = correct_opacity(cb.a, u_step);
            vec3 rgb = cb.rgb;
#ifdef SHADING
            vec3 g = gradient_at(p, vb);
            CUT_CAP(g, t);
            rgb = shade_at(rgb, g, t, p, r);
#endif
            a_over = a;
            od = ov_depth(a);
            od_rgb = od * rgb;
        }
#if defined(LABELS) && LABELS > 1
        g_label_material = vec4(-1.0); // the overlays are lit with the frame's material, not the base's label's
#endif
        float a_step = 0.0;
        vec3 rgb_step = vec3(0.0), emission = vec3(0.0);
        bool over_done = false;
        for (int k = 0; k < OVERLAYS; k++) {
            if (!over_done && u_ov_blend[k] != 0) { // the OVER ones are all in (listed first)
                a_step = a_over;
                rgb_step = od > 0.0 ? od_rgb / od : vec3(0.0);
                over_done = true;
            }
            vec4 c = ck[k];
            if (c.a <= 0.0) continue;
            float a = correct_opacity(c.a, u_step);
            vec3 rgb = c.rgb;
#ifdef SHADING
            if (u_ov_shading[k] != 0) {
                vec3 g = ov_gradient(k, qk[k]);
                CUT_CAP(g, t);
                rgb = shade_at(rgb, g, t, p, r);
            }
#endif
            if (u_ov_blend[k] == 0) {
                a_over += a * (1.0 - a_over);
                float d = ov_depth(a);
                od += d;
                od_rgb += d * rgb;
            } else if (u_ov_blend[k] == 2) {
                if (a > a_step) {
                    a_step = a;
                    rgb_step = rgb;
                }
            } else {
                emission += a * rgb;
            }
        }
        if (!over_done) {
            a_step = a_over;
            rgb_step = od > 0.0 ? od_rgb / od : vec3(0.0);
        }
        if (a_step <= 0.0 && all(equal(emission, vec3(0.0)))) continue;
        acc += (1.0 - acc.a) * vec4(a_step * rgb_step + emission, a_step);
        if (isinf(depth) && acc.a >= u_depth_threshold) depth = -(r.z0 + r.dz * t);
        if (acc.a >= u_early_termination) break;
    }
    return acc;
}

#endif
