// gradients.comp - precomputed gradients, one source for one texture and for
// bricked storage: the [1,2,1]^3 / 64 blur, then the 26-neighbour Sobel
// (lib/stencils.glsl), the raw gradient divided by the whole volume's largest
// magnitude (not a unit normal: normalising before storage costs ~9 degrees,
// see shared/reference/measured-facts.md).
//   BLUR_PASS            the blur at grid points (clamped at the border)
//   MAX_PASS             the Sobel's global maximum magnitude (one texture;
//                        bricked: found on the CPU, bspline_bricks.c)
//   neither              the Sobel of the blurred values, stored as
//                        GRADIENT_FORMAT
// One texture: each pass runs over the volume (u_src). PAGED (bricked
// storage): per derived brick in a pool of its own; the blur pass blurs each
// derived brick plus a two-voxel border (ghost + the Sobel's reach) from the
// data pool through the page table, the store pass runs the Sobel inside
// each blurred slot. Positions outside the volume repeat its edge, as
// clamped fetches of one texture do, so every texel equals the dense one's.
#ifdef PAGED
#include "lib/common.glsl"
#include "lib/slots.glsl"
#endif

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
#ifdef PAGED
layout(std430, binding = VXL_SSBO_BRICK_LIST) readonly buffer Derived { ivec4 derived_brick[]; }; // brick coords per slot
uniform int u_brick;      // P
uniform int u_count;      // derived bricks
uniform int u_first;      // first slot of this dispatch (dispatches are chunked)
uniform ivec3 u_slots;    // slots per axis of the pool written (or read, for the Sobel)
uniform int u_blur_first; // the blurred slots hold bricks u_blur_first.. (a chunk)
#else
uniform sampler3D u_src;
#endif
#ifdef BLUR_PASS
layout(r32f, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_dst;
#elif defined(MAX_PASS)
layout(std430, binding = VXL_SSBO_GRADIENT_MAX) buffer MaxMag { uint max_bits; };
#else
uniform float u_inv_max;  // 1 / the whole volume's largest |gradient|
layout(GRADIENT_FORMAT, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_dst;
#endif

// Each pass's stencil point (one include per program: shader_source.c)
#if defined(PAGED) && !defined(BLUR_PASS)
// A voxel of the volume and where the blurred slot holding its neighbourhood
// lies: blurred voxel q (volume coordinates) is texel q + shift of u_blur.
struct BlurredVoxel {
    ivec3 c;
    ivec3 shift;
};
#define STENCIL_POINT BlurredVoxel
#else
#define STENCIL_POINT ivec3
#endif
#include "lib/stencils.glsl"

#if !defined(PAGED)
float stencil_tap(ivec3 c, ivec3 o) { return texelFetch(u_src, clamp(c + o, ivec3(0), textureSize(u_src, 0) - 1), 0).r; }

void main()
{
    ivec3 size = textureSize(u_src, 0);
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, size))) return;
#ifdef BLUR_PASS
    imageStore(u_dst, c, vec4(blur121(c)));
#else
    vec3 g = sobel26_sum(c);
    g /= 32.0;
#ifdef MAX_PASS
    // Non-negative floats order like their bit patterns, so atomicMax works.
    atomicMax(max_bits, floatBitsToUint(length(g)));
#else
    imageStore(u_dst, c, vec4(g * u_inv_max, 0.0));
#endif
#endif
}
#elif defined(BLUR_PASS)
float stencil_tap(ivec3 c, ivec3 o) { return paged_fetch(clamp(c + o, ivec3(0), ivec3(u_dims) - 1)); }

void main()
{
    int edge = u_brick + 4;
    ivec3 t = ivec3(gl_GlobalInvocationID);
    int k = u_first + t.z / edge;
    ivec3 l = ivec3(t.xy, t.z % edge);
    if (k >= u_count || any(greaterThanEqual(l, ivec3(edge)))) return;
    // the volume voxel this texel stands for (border of 2: ghost + Sobel reach)
    ivec3 c = clamp(derived_brick[k].xyz * u_brick + l - 2, ivec3(0), ivec3(u_dims) - 1);
    imageStore(u_dst, slot_corner(k - u_blur_first, u_slots, edge) + l, vec4(blur121(c)));
}
#else
uniform sampler3D u_blur;  // blurred slots of edge P+4
uniform ivec3 u_blur_slots;

// clamp in volume coordinates (as the dense Sobel does), then into the slot
float stencil_tap(BlurredVoxel v, ivec3 o)
{
    ivec3 q = clamp(clamp(v.c, ivec3(0), ivec3(u_dims) - 1) + o, ivec3(0), ivec3(u_dims) - 1);
    return texelFetch(u_blur, q + v.shift, 0).r;
}

void main()
{
    int edge = u_brick + 2;
    ivec3 t = ivec3(gl_GlobalInvocationID);
    int k = u_first + t.z / edge;
    ivec3 l = ivec3(t.xy, t.z % edge);
    if (k >= u_count || any(greaterThanEqual(l, ivec3(edge)))) return;
    ivec3 bo = slot_corner(k - u_blur_first, u_blur_slots, u_brick + 4);
    // the volume voxel of this texel, and where its neighbours' blurred values lie
    ivec3 c = derived_brick[k].xyz * u_brick + l - 1;
    vec3 g = sobel26_sum(BlurredVoxel(c, bo - derived_brick[k].xyz * u_brick + 2));
    g /= 32.0;
    imageStore(u_dst, slot_corner(k, u_slots, edge) + l, vec4(g * u_inv_max, 0.0));
}
#endif
