// path.frag - the PATH shading model (voxlight.h's VXL_SHADING_PATH):
// progressive Monte Carlo volume path tracing of docs/physical_model.md's
// medium. Per pixel, samples u_path_first .. + u_path_samples - 1, each a
// random walk from the eye:
//  - free flights by delta tracking in voxel space against the majorant per
//    skipping brick (render/path.c; a brick of majorant 0 is crossed at
//    once), with the extinction -ln(1 - a) per voxel of path of the table's
//    opacity a, the medium the ray caster composites;
//  - at each collision after the first, SCATTER's lighting there
//    (lib/shading.glsl's shade_lit_sum: the lamps times their transmittance
//    from the illumination volumes, which carry the scene's mesh shadows, the
//    ambient term or the World's irradiance, the surface term where the
//    gradient is strong), unclamped, times the path's throughput: next-event
//    estimation through the same volumes `scatter` reads;
//  - the first collision's lighting is not sampled but integrated along the
//    eye ray by the deterministic march that also gives alpha (the same sum,
//    T a S per step, that `scatter` composites, unclamped): it is most of the
//    light in all but thick, bright media, and a free flight that may or may
//    not collide was most of a sample's noise (on the Blender tests' ball,
//    RMSE 0.083 a sample against Cycles; docs/lighting.md). The random walk
//    still starts with a free flight from the eye, to carry the bounces;
//  - then, up to u_path_bounces collisions, a new direction: the surface
//    lobe with probability w (cosine-weighted about the normal, throughput
//    times min(diffuse, 1) * colour: a material's diffuse above 1 brightens
//    its direct light but may not multiply light bounce after bounce) or
//    the Henyey-Greenstein lobe (throughput times the colour, the
//    single-scattering albedo), so the throughput never exceeds 1.
// A path that leaves the volume adds nothing more: the lamps and the World
// were counted at every collision already. Alpha and depth come from the
// same deterministic march of the same opacity, so they are free of noise
// and the same in every call.
// Random numbers: each sample's first 16 dimensions (4 per collision: the
// first free flight, the lobe, the direction's two) are a rank-1 lattice
// over the sample index (a Kronecker sequence with the fractional parts of
// the square roots of the first primes, exact in 32-bit integers), shifted
// per pixel, seed and dimension by a hash (Cranley-Patterson rotation), so
// a pixel's samples are stratified in each; the rest (further free flights,
// the null-collision tests) are hashed white noise. Everything is a function
// of (seed, pixel, sample index): the same call gives the same image.
#include "lib/gradients.glsl"
#include "lib/classify.glsl"
#include "lib/colour.glsl" // DATA_COLOUR: a colour volume's own colour
#include "lib/shading.glsl"
#include "lib/ray_box.glsl"
#include "lib/cut.glsl" // CUT_CONVEX: clip planes and the crop box (cut_convex)

uniform mat4 u_ray_near;  // as raycast.frag's
uniform mat4 u_ray_far;
uniform mat4 u_mv;        // voxel -> view space
uniform vec2 u_viewport;
uniform float u_step;     // the alpha march's step, voxels
uniform int u_max_steps;
uniform float u_early_termination;
uniform float u_depth_threshold;
uniform int u_has_scene_depth;
uniform sampler2D u_scene_depth;
uniform sampler3D u_majorant;   // extinction bound per voxel of path, per brick
uniform int u_path_brick;       // voxels per brick edge
uniform uint u_path_first;      // this call's first sample index
uniform uint u_path_samples;    // samples this call
uniform uint u_path_seed;
uniform int u_path_bounces;     // collisions per path
uniform float u_path_max_sigma; // extinction of opacity 1 (majorant.h's cap)

layout(std430, binding = VXL_SSBO_STATS) buffer Stats { uint st_samples_lo; uint st_samples_hi; uint st_max_ray; uint st_rays; };

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;

const float PATH_INF = uintBitsToFloat(0x7f800000u);

// ---- random numbers -------------------------------------------------------

uint path_hash(uint x) // a 32-bit integer mix with low bias
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

#define PATH_LATTICE_DIMS 16
// frac(sqrt(p)) * 2^32 for the first 16 primes: rationally independent steps
const uint PATH_LATTICE[PATH_LATTICE_DIMS] = uint[](
    1779033703u, 3144134277u, 1013904242u, 2773480762u, 1359893119u, 2600822924u, 528734635u, 1541459225u,
    3418070365u, 1654270250u, 2438529370u, 355462360u, 1731405415u, 2394180231u, 3675008525u, 1203062813u);

struct PathRng {
    uint pixel;  // the hash of the pixel and the seed
    uint index;  // the sample index
    uint white;  // counter of the hashed stream
};

float path_unit(uint x) { return float(x >> 8) * (1.0 / 16777216.0); } // [0, 1)

// Lattice dimension d (< PATH_LATTICE_DIMS) of the current sample.
float path_dim(PathRng r, int d)
{
    uint shift = path_hash(r.pixel ^ path_hash(uint(d) + 0x9e3779b9u));
    return path_unit(shift + r.index * PATH_LATTICE[d]);
}

float path_white(inout PathRng r)
{
    r.white++;
    return path_unit(path_hash(r.pixel ^ path_hash(r.index * 0x2c1b3c6du + path_hash(r.white + 0x68e31da4u))));
}

// Dimension d of collision k, lattice while it lasts.
float path_stratified(inout PathRng r, int k, int d)
{
    int dim = 4 * k + d;
    return dim < PATH_LATTICE_DIMS ? path_dim(r, dim) : path_white(r);
}

// ---- the medium -------------------------------------------------------------

// The alpha march's samples, for the frame's statistics (within its bound,
// as the ray caster's); the tracker's lookups are bounded by its own guards.
uint g_lookups = 0u;

float extinction(float a) { return a >= 1.0 ? u_path_max_sigma : min(-log(1.0 - a), u_path_max_sigma); }

// Delta tracking of o + t d (voxel space, d unit) from t to t1: true and the
// collision's t and value where it collides with the medium (probability
// density T(t) sigma(t)), false where it leaves [t, t1]. u0: the first free
// flight's random number.
bool track(vec3 o, vec3 d, float t, float t1, float u0, inout PathRng rng, out float tc, out float vc)
{
    tc = t1;
    vc = 0.0;
    float bs = float(u_path_brick);
    ivec3 top = textureSize(u_majorant, 0) - 1;
    float u = u0;
    bool fresh = false;
    // bounds: bricks a ray can cross, and tentative collisions (a grid of
    // 512^3 voxels at the cap's majorant asks for ~15000 along a diagonal)
    int events = 0;
    for (int guard = 0; guard < 4096 && t < t1; guard++) {
        ivec3 b = clamp(ivec3(floor((o + (t + 1e-4) * d + 0.5) / bs)), ivec3(0), top);
        float t_exit = min(max(brick_cube_exit(b, 1u, bs, o, d), t + 1e-4), t1);
        float smaj = texelFetch(u_majorant, b, 0).r;
        if (smaj > 0.0) {
            for (; events < 65536; events++) {
                if (fresh) u = path_white(rng);
                fresh = true;
                t -= log(1.0 - u) / smaj;
                if (t >= t_exit) break;
                vec3 q = o + t * d;
                float v = sample_value(q);
                if (path_white(rng) * smaj < extinction(classify(v).a)) {
                    tc = t;
                    vc = v;
                    return true;
                }
            }
        }
        t = t_exit;
    }
    return false;
}

// The part of o + t d in [t0, t1] that the clip planes and the crop box
// keep: a convex region, so one interval for every segment of a path, the
// primary ray and each bounce alike (what is cut away is no medium; no
// caps: a medium has no surface normal there). False when nothing is left.
bool path_keep(vec3 o, vec3 d, inout float t0, inout float t1)
{
#ifdef CUT_CONVEX
    vec3 cap = vec3(0.0);
    return cut_convex(o, d, t0, t1, cap) && t0 < t1;
#else
    return t0 < t1;
#endif
}

// ---- directions ---------------------------------------------------------------

// A unit vector at angle acos(c) from unit axis n, azimuth 2 pi u.
vec3 around(vec3 n, float c, float u)
{
    vec3 a = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    vec3 x = normalize(cross(a, n)), y = cross(n, x);
    float s = sqrt(max(0.0, 1.0 - c * c)), phi = 6.28318530718 * u;
    return normalize(c * n + s * (cos(phi) * x + sin(phi) * y));
}

// Cosine of the angle between the incoming travel and the scattered
// direction, drawn from Henyey-Greenstein with g (inverted CDF).
float hg_cos(float g, float u)
{
    if (abs(g) < 1e-3) return 1.0 - 2.0 * u;
    float s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    return clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

// ---- one sample -------------------------------------------------------------

// The medium's albedo at p of value v: the table's colour, or a colour
// volume's own.
vec3 albedo_at(vec3 p, float v)
{
#ifdef DATA_COLOUR
    return data_colour(p);
#else
    return classify(v).rgb;
#endif
}

// Radiance (premultiplied: 0 where the path leaves without colliding) of one
// random walk from o along d over [t0, t1], all in voxel space, without the
// light of its first collision (path_primary integrates that).
vec3 path_sample(vec3 o, vec3 d, float t0, float t1, mat3 to_voxel, bool one_directional, inout PathRng rng)
{
    vec3 radiance = vec3(0.0), throughput = vec3(1.0);
    for (int k = 0; k < u_path_bounces; k++) {
        float t, v;
        if (!track(o, d, t0, t1, path_stratified(rng, k, 0), rng, t, v)) break;
        vec3 p = o + t * d;
        vec3 rgb = albedo_at(p, v);
        vec3 g = gradient_at(p, v);
        vec3 travel = normalize(mat3(u_mv) * d); // view space
        if (k > 0) {
            RayLighting rl = ray_lighting(-travel);
            radiance += throughput * shade_lit_sum(rgb, g, (u_mv * vec4(p, 1.0)).xyz, p, rl, one_directional);
        }
        if (k + 1 == u_path_bounces) break;
        vec3 n = u_normal_matrix * g;
        float len = length(n);
        float w = len > 1e-20 ? min(1.0, length(g) / u_scatter_ref) : 0.0;
        vec3 next;
        if (path_stratified(rng, k, 1) < w) {
            n /= len;
            if (dot(n, -travel) < 0.0) n = -n; // the side the path came from, as shading turns it
            next = around(n, sqrt(path_stratified(rng, k, 2)), path_stratified(rng, k, 3));
            throughput *= min(SHADE_MATERIAL.y, 1.0) * rgb; // a surface reflects at most what it receives
        } else {
            next = around(travel, hg_cos(u_anisotropy, path_stratified(rng, k, 2)), path_stratified(rng, k, 3));
            throughput *= rgb;
        }
        if (!any(greaterThan(throughput, vec3(0.0)))) break;
        d = normalize(to_voxel * next);
        o = p;
        t0 = 0.0;
        t1 = PATH_INF;
        if (!box_clip(o, d, vec3(-0.5), u_dims - 0.5, t0, t1) || !path_keep(o, d, t0, t1)) break;
    }
    return radiance;
}

// The ray's opacity and depth as the emission-absorption march composites
// them (raycast.frag without jitter), over bricks of majorant 0 at once, and
// the light of the first collision along it: the sum over steps of the
// transmittance before the step, the step's opacity and SCATTER's lighting
// there (unclamped), which is what the first collision's next-event
// estimate averages to, up to the step.
float path_primary(vec3 o, vec3 d, float t0, float t1, float z0, float dz, bool one_directional, out float depth,
                   out vec3 direct)
{
    float T = 1.0;
    depth = PATH_INF;
    direct = vec3(0.0);
    RayLighting rl = ray_lighting(-normalize(mat3(u_mv) * d));
    float bs = float(u_path_brick);
    ivec3 top = textureSize(u_majorant, 0) - 1;
    for (int i = 0; i < u_max_steps; i++) {
        float t = t0 + float(i) * u_step;
        if (t >= t1) break;
        vec3 p = o + t * d;
        ivec3 b = clamp(ivec3(floor((p + 0.5) / bs)), ivec3(0), top);
        if (texelFetch(u_majorant, b, 0).r == 0.0) {
            i = last_sample_before(brick_cube_exit(b, 1u, bs, o, d), t0, u_step, u_max_steps, i);
            continue;
        }
        g_lookups++;
        float v = sample_value(p);
        float a = correct_opacity(classify(v).a, u_step);
        if (a > 0.0)
            direct += T * a *
                      shade_lit_sum(albedo_at(p, v), gradient_at(p, v), (u_mv * vec4(p, 1.0)).xyz, p, rl,
                                    one_directional);
        T *= 1.0 - a;
        if (isinf(depth) && 1.0 - T >= u_depth_threshold) depth = -(z0 + dz * t);
        if (1.0 - T >= u_early_termination) break;
    }
    return 1.0 - T;
}

void emit_nothing()
{
    o_color = vec4(0.0);
    o_depth = PATH_INF;
}

void main()
{
    // the pixel's ray, as raycast.frag's main builds it
    vec2 ndc = gl_FragCoord.xy / u_viewport * 2.0 - 1.0;
    vec4 hn = u_ray_near * vec4(ndc, 0.0, 1.0);
    vec4 hf = u_ray_far * vec4(ndc, 0.0, 1.0);
    vec3 o = hn.xyz / hn.w;
    vec3 dir = hf.xyz * hn.w - hn.xyz * hf.w;
    float len = length(dir);
    float t_far = hn.w * hf.w > 0.0 ? len / (hn.w * hf.w) : PATH_INF;
    if (!(len > 0.0) || isinf(len) || any(isnan(o)) || any(isinf(o)) || isnan(t_far)) { emit_nothing(); return; }
    dir /= len;
    float t0 = 0.0, t1 = t_far;
    if (!box_clip(o, dir, vec3(-0.5), u_dims - 0.5, t0, t1)) { emit_nothing(); return; }
    vec4 row2 = vec4(u_mv[0][2], u_mv[1][2], u_mv[2][2], u_mv[3][2]);
    float z0 = dot(row2, vec4(o, 1.0)), dz = dot(row2.xyz, dir);
    if (u_has_scene_depth != 0 && dz < 0.0) {
        float sd = texelFetch(u_scene_depth, ivec2(gl_FragCoord.xy), 0).r;
        if (!isnan(sd)) t1 = min(t1, (-sd - z0) / dz);
    }
    if (!path_keep(o, dir, t0, t1)) { emit_nothing(); return; }

    float depth;
    vec3 direct;
    bool one_directional = u_light_count == 1 && u_light_pos[0].w == 0.0;
    float alpha = path_primary(o, dir, t0, t1, z0, dz, one_directional, depth, direct);
    vec3 sum = vec3(0.0);
    if (u_path_bounces > 1) {
        mat3 to_voxel = inverse(mat3(u_mv));
        uvec2 px = uvec2(gl_FragCoord.xy);
        PathRng rng;
        rng.pixel = path_hash(px.x ^ path_hash(px.y ^ path_hash(u_path_seed + 0x5bd1e995u)));
        for (uint s = 0u; s < u_path_samples; s++) {
            rng.index = u_path_first + s;
            rng.white = 0u;
            sum += path_sample(o, dir, t0, t1, to_voxel, one_directional, rng);
        }
    }
    uint old = atomicAdd(st_samples_lo, g_lookups);
    if (old + g_lookups < old) atomicAdd(st_samples_hi, 1u);
    atomicMax(st_max_ray, g_lookups);
    atomicAdd(st_rays, 1u);
    o_color = vec4(direct + sum / float(u_path_samples), alpha);
    o_depth = depth;
}
