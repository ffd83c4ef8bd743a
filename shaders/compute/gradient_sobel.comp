// gradient_sobel.comp - second and third passes of precomputed gradients: the
// 26-neighbour Sobel (lib/stencils.glsl) of the blurred volume at grid points.
// MAX_PASS only finds the global maximum magnitude; the store pass writes the
// raw gradient divided by that maximum (not a unit normal: normalising before
// storage costs ~9 degrees, see shared/reference/measured-facts.md).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
uniform sampler3D u_src;
#ifdef MAX_PASS
layout(std430, binding = VXL_SSBO_GRADIENT_MAX) buffer MaxMag { uint max_bits; };
#else
uniform float u_inv_max;
layout(GRADIENT_FORMAT, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_dst;
#endif

#define STENCIL_POINT ivec3
#include "lib/stencils.glsl"

float stencil_tap(ivec3 c, ivec3 o) { return texelFetch(u_src, clamp(c + o, ivec3(0), textureSize(u_src, 0) - 1), 0).r; }

void main()
{
    ivec3 size = textureSize(u_src, 0);
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, size))) return;
    vec3 g = sobel26_sum(c);
    g /= 32.0;
#ifdef MAX_PASS
    // Non-negative floats order like their bit patterns, so atomicMax works.
    atomicMax(max_bits, floatBitsToUint(length(g)));
#else
    imageStore(u_dst, c, vec4(g * u_inv_max, 0.0));
#endif
}
