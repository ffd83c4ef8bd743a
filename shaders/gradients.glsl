// gradients.glsl - the gradient filters, one chosen per program by a define:
// FILTER_CENTRAL, FILTER_FORWARD3, FILTER_SOBEL8, FILTER_SOBEL14,
// FILTER_SOBEL26, FILTER_PRECOMPUTED, FILTER_CUBIC. Every filter returns the gradient in
// voxel space (normalised value per voxel) and is exact on a linear ramp.
#include "common.glsl"

uniform float u_sample_distance; // tap offset d, in voxels

#ifdef FILTER_PRECOMPUTED
uniform sampler3D u_gradient; // raw gradient / global max, interpolated then used
uniform float u_gradient_scale; // that global max: magnitudes in value per voxel like every filter
#ifdef PAGED
// Bricked storage: u_gradient is a pool of its own, u_gpage its page table
// (w < 0 in the pool, else a brick whose whole neighbourhood is one value:
// zero gradient), see paged_gradient.comp. On a coarser level the gradient
// is the level's, per level voxel.
uniform sampler3D u_gpage;
uniform vec3 u_gpool_dims;

vec3 paged_gradient(vec3 p)
{
    vec3 t = level_position(p);
    vec4 e = page_entry(u_gpage, t);
    if (e.w >= 0.0) return vec3(0.0);
    return textureLod(u_gradient, (t + 0.5) / u_gpool_dims, 0.0).xyz / u_lod_scale;
}
#endif
#endif

#ifdef FILTER_CUBIC
uniform sampler3D u_bspline; // interpolating cubic B-spline coefficients, trilinear

// Sigg & Hadwiger (GPU Gems 2, ch. 20): a cubic B-spline over 4 samples is
// two linear fetches. For voxel coordinate x, the pair offsets (relative to
// floor(x)) and weights of the B-spline (w) and of its derivative (dw).
void bspline_pairs(float x, out vec2 h, out vec2 g, out vec2 dh, out vec2 dg)
{
    float a = x - floor(x), a2 = a * a, a3 = a2 * a, b = 1.0 - a;
    float w0 = b * b * b / 6.0, w1 = (3.0 * a3 - 6.0 * a2 + 4.0) / 6.0;
    float w2 = (-3.0 * a3 + 3.0 * a2 + 3.0 * a + 1.0) / 6.0, w3 = a3 / 6.0;
    g = vec2(w0 + w1, w2 + w3);
    h = vec2(-1.0 + w1 / g.x, 1.0 + w3 / g.y);
    // derivative weights: w0', w1' <= 0 and w2', w3' >= 0 on [0,1), so each
    // pair is a convex blend and one linear fetch still serves it
    float d0 = -0.5 * b * b, d1 = 0.5 * (3.0 * a2 - 4.0 * a);
    float d2 = 0.5 * (-3.0 * a2 + 2.0 * a + 1.0), d3 = 0.5 * a2;
    dg = vec2(d0 + d1, d2 + d3);
    dh = vec2(-1.0 + d1 / dg.x, 1.0 + d3 / dg.y);
}

#ifndef PAGED
float coeff(vec3 q) { return textureLod(u_bspline, voxel_to_tex(q), 0.0).r; }
#else
// Bricked storage: u_bspline is a pool of coefficient bricks with a one-voxel
// ghost, u_cpage its page table (w >= 0: a brick whose coefficients are all
// that value), laid out brick for brick like the data (paged_bspline.c).
// q is a level position.
uniform sampler3D u_cpage;
uniform vec3 u_cpool_dims;

float coeff(vec3 q)
{
    vec4 e = page_entry(u_cpage, q);
    return e.w >= 0.0 ? e.w : textureLod(u_bspline, (q + 0.5) / u_cpool_dims, 0.0).r;
}
#endif

// One gradient component: derivative pairs along axis `a`, value pairs on
// the other two; 8 trilinear fetches.
float bspline_partial(vec3 base, vec2 h[3], vec2 g[3], vec2 dh[3], vec2 dg[3], int a)
{
    float s = 0.0;
    for (int i = 0; i < 8; i++) {
        ivec3 k = ivec3(i & 1, (i >> 1) & 1, (i >> 2) & 1);
        vec3 q, w;
        for (int c = 0; c < 3; c++) {
            q[c] = base[c] + (c == a ? dh[c][k[c]] : h[c][k[c]]);
            w[c] = c == a ? dg[c][k[c]] : g[c][k[c]];
        }
        s += w.x * w.y * w.z * coeff(q);
    }
    return s;
}
#endif

#define TAP(o) sample_value(p + (o))

// centre: the value at p, which the ray caster has already fetched.
vec3 gradient_at(vec3 p, float centre)
{
    float d = u_sample_distance;
#if defined(FILTER_CENTRAL)
    return vec3(TAP(vec3(d, 0, 0)) - TAP(vec3(-d, 0, 0)),
                TAP(vec3(0, d, 0)) - TAP(vec3(0, -d, 0)),
                TAP(vec3(0, 0, d)) - TAP(vec3(0, 0, -d))) / (2.0 * d);
#elif defined(FILTER_FORWARD3)
    // 3 taps against the centre sample: cheapest, biased by d/2 along each axis.
    return (vec3(TAP(vec3(d, 0, 0)), TAP(vec3(0, d, 0)), TAP(vec3(0, 0, d))) - centre) / d;
#elif defined(FILTER_SOBEL8)
    // Trilinear fetches at the 8 corners (+-d,+-d,+-d); at d = 0.5 this is
    // exactly the [-1,0,1]x[1,2,1]x[1,2,1] Sobel kernel at grid points.
    vec3 g = vec3(0.0);
    for (int i = 0; i < 8; i++) {
        vec3 s = vec3((i & 1) != 0 ? 1.0 : -1.0, (i & 2) != 0 ? 1.0 : -1.0, (i & 4) != 0 ? 1.0 : -1.0);
        g += s * TAP(d * s);
    }
    return g / (8.0 * d);
#elif defined(FILTER_SOBEL14)
    // Faces and corners together (MRIcroGL's Sobel14); each face tap sums to
    // 2d*grad and the corners to 8d*grad on a ramp.
    vec3 g = vec3(TAP(vec3(d, 0, 0)) - TAP(vec3(-d, 0, 0)),
                  TAP(vec3(0, d, 0)) - TAP(vec3(0, -d, 0)),
                  TAP(vec3(0, 0, d)) - TAP(vec3(0, 0, -d)));
    for (int i = 0; i < 8; i++) {
        vec3 s = vec3((i & 1) != 0 ? 1.0 : -1.0, (i & 2) != 0 ? 1.0 : -1.0, (i & 4) != 0 ? 1.0 : -1.0);
        g += s * TAP(d * s);
    }
    return g / (10.0 * d);
#elif defined(FILTER_SOBEL26)
    // Classic weighted 26-neighbour Sobel: weight o.x*h(o.y)*h(o.z) for the x
    // component with h(0) = 2, h(+-1) = 1; the weights sum to 32d on a ramp.
    vec3 g = vec3(0.0);
    for (int z = -1; z <= 1; z++)
        for (int y = -1; y <= 1; y++)
            for (int x = -1; x <= 1; x++) {
                if (x == 0 && y == 0 && z == 0) continue;
                vec3 o = vec3(x, y, z);
                vec3 h = 2.0 - abs(o);
                g += o * vec3(h.y * h.z, h.x * h.z, h.x * h.y) * TAP(d * o);
            }
    return g / (32.0 * d);
#elif defined(FILTER_PRECOMPUTED) && defined(PAGED)
    return paged_gradient(p) * u_gradient_scale;
#elif defined(FILTER_PRECOMPUTED)
    return textureLod(u_gradient, voxel_to_tex(p), 0.0).xyz * u_gradient_scale;
#elif defined(FILTER_CUBIC)
    // Analytic derivative of the interpolating cubic B-spline: 24 fetches.
#ifdef PAGED
    vec3 q = level_position(p); // a coarser level's spline, per level voxel
    float per_voxel = 1.0 / u_lod_scale;
#else
    vec3 q = p;
    float per_voxel = 1.0;
#endif
    vec3 base = floor(q);
    vec2 h[3], g[3], dh[3], dg[3];
    for (int c = 0; c < 3; c++) bspline_pairs(q[c], h[c], g[c], dh[c], dg[c]);
    return vec3(bspline_partial(base, h, g, dh, dg, 0), bspline_partial(base, h, g, dh, dg, 1),
                bspline_partial(base, h, g, dh, dg, 2)) * per_voxel;
#else
#error "no FILTER_* define"
#endif
}

// reuseGradients (MRIcroGL): when the gradient magnitude drops below the
// previous sample's, keep the previous direction. The magnitude always
// follows the current sample, as in MRIcroGL, so a long decline keeps one
// direction while a rise takes the new one.
struct GradientState {
    vec3 dir;
    float mag; // < 0: no previous sample
};

GradientState gradient_state_init() { return GradientState(vec3(0.0), -1.0); }

vec3 reuse_gradient(inout GradientState s, vec3 g)
{
    float m = length(g);
    vec3 d = (m < s.mag) ? s.dir : g;
    s.dir = d;
    s.mag = m;
    return d;
}
