// gradients.glsl - the gradient filters, one chosen per program by a define:
// FILTER_CENTRAL, FILTER_FORWARD3, FILTER_SOBEL8, FILTER_SOBEL14,
// FILTER_SOBEL26, FILTER_PRECOMPUTED, FILTER_CUBIC, FILTER_CUBIC_SMOOTH. Every
// filter returns the gradient in voxel space (normalised value per voxel) and
// is exact on a linear ramp.
#include "lib/common.glsl"

uniform float u_sample_distance; // tap offset d, in voxels

#ifdef FILTER_PRECOMPUTED
uniform sampler3D u_gradient; // raw gradient / global max, interpolated then used
uniform float u_gradient_scale; // that global max: magnitudes in value per voxel like every filter
#ifdef PAGED
// Bricked storage: u_gradient is a pool of its own, u_gpage its page table
// (w < 0 in the pool, else a brick whose whole neighbourhood is one value:
// zero gradient), see compute/gradients.comp. On a coarser level the gradient
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

#if defined(FILTER_CUBIC) || defined(FILTER_CUBIC_SMOOTH)
// Cubic B-spline derivative over the 4x4x4 coefficients around p, read
// texel-exact (texelFetch) and weighted in float here. The two-fetch trick
// (Sigg & Hadwiger) would let the texture unit blend pairs, but GPUs blend
// with fixed-point weights (8 fractional bits is common), an error of the
// order of a small gradient; exact costs ~15% more on llvmpipe
// (docs/filters_on_scans.md).
vec4 bspline_weights(float a)
{
    float b = 1.0 - a, a2 = a * a, a3 = a2 * a;
    return vec4(b * b * b, 3.0 * a3 - 6.0 * a2 + 4.0, -3.0 * a3 + 3.0 * a2 + 3.0 * a + 1.0, a3) / 6.0;
}
vec4 bspline_dweights(float a)
{
    float b = 1.0 - a, a2 = a * a;
    return vec4(-b * b, 3.0 * a2 - 4.0 * a, -3.0 * a2 + 2.0 * a + 1.0, a2) * 0.5;
}
#endif

#ifdef FILTER_CUBIC
// Interpolating spline: coefficients from the prefilter (bspline.c,
// paged_bspline.c), float. Clamped indices reproduce clamp-to-edge.
uniform sampler3D u_bspline;
#ifndef PAGED
float spline_coeff(ivec3 c) { return texelFetch(u_bspline, clamp(c, ivec3(0), ivec3(u_dims) - 1), 0).r; }
#else
// Bricked storage: u_bspline is a pool of coefficient bricks, u_cpage its
// page table (w >= 0: a brick whose coefficients are all that value), laid
// out brick for brick like the data (paged_bspline.c); c is a level voxel.
uniform sampler3D u_cpage;

float spline_coeff(ivec3 c)
{
    c = clamp(c, ivec3(0), ivec3(u_page_dims) - 1);
    int n = int(u_page_brick);
    ivec3 b = c / n;
    vec4 e = texelFetch(u_cpage, b, 0);
    return e.w >= 0.0 ? e.w : texelFetch(u_bspline, ivec3(e.xyz) + c - b * n, 0).r;
}
#endif
#endif

#ifdef FILTER_CUBIC_SMOOTH
// Approximating spline: the voxels themselves are the coefficients (no
// prefilter), so the spline smooths (its response at grid points is
// [1 4 1]/6 per axis) instead of passing every voxel's noise on. The stored
// texels are read exactly: llvmpipe's linear filter of unorm8 textures
// returns lerps rounded to 1/255.
#ifndef PAGED
float spline_coeff(ivec3 c) { return texelFetch(u_volume, clamp(c, ivec3(0), ivec3(u_dims) - 1), 0).r; }
#else
float spline_coeff(ivec3 c) { return paged_fetch(clamp(c, ivec3(0), ivec3(u_page_dims) - 1)); }
#endif
#endif

#if defined(FILTER_CUBIC) || defined(FILTER_CUBIC_SMOOTH)
// q in (level) voxels; per row of 4 coefficients along x, the value and
// x-derivative sums, then the y and z weights.
vec3 bspline_gradient(vec3 q)
{
    vec3 fq = floor(q), a = q - fq;
    ivec3 b = ivec3(fq) - 1;
    vec4 wx = bspline_weights(a.x), wy = bspline_weights(a.y), wz = bspline_weights(a.z);
    vec4 dx = bspline_dweights(a.x), dy = bspline_dweights(a.y), dz = bspline_dweights(a.z);
    vec3 g = vec3(0.0);
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++) {
            vec4 row = vec4(spline_coeff(b + ivec3(0, j, k)), spline_coeff(b + ivec3(1, j, k)),
                            spline_coeff(b + ivec3(2, j, k)), spline_coeff(b + ivec3(3, j, k)));
            float v = dot(wx, row);
            g += vec3(dot(dx, row) * wy[j] * wz[k], v * dy[j] * wz[k], v * wy[j] * dz[k]);
        }
    return g;
}
#endif

#define TAP(o) sample_value(p + (o))

#ifdef FILTER_SOBEL26
// The Sobel's taps are trilinear samples u_sample_distance apart around p.
#define STENCIL_POINT vec3
#include "lib/stencils.glsl"

float stencil_tap(vec3 p, ivec3 o) { return TAP(u_sample_distance * vec3(o)); }
#endif

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
    // Classic weighted 26-neighbour Sobel (lib/stencils.glsl): its weights
    // sum to 32d on a ramp.
    return sobel26_sum(p) / (32.0 * d);
#elif defined(FILTER_PRECOMPUTED) && defined(PAGED)
    return paged_gradient(p) * u_gradient_scale;
#elif defined(FILTER_PRECOMPUTED)
    return textureLod(u_gradient, voxel_to_tex(p), 0.0).xyz * u_gradient_scale;
#elif defined(FILTER_CUBIC) || defined(FILTER_CUBIC_SMOOTH)
    // Analytic derivative of the cubic B-spline (interpolating or
    // approximating): 64 texel reads.
#ifdef PAGED
    return bspline_gradient(level_position(p)) / u_lod_scale; // a coarser level's spline, per level voxel
#else
    return bspline_gradient(p);
#endif
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
