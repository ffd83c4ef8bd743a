// gradient_sobel.comp - second and third passes of precomputed gradients: the
// 26-neighbour Sobel of the blurred volume at grid points. MAX_PASS only
// finds the global maximum magnitude; the store pass writes the raw gradient
// divided by that maximum (not a unit normal: normalising before storage
// costs ~9 degrees, see shared/reference/measured-facts.md).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
uniform sampler3D u_src;
#ifdef MAX_PASS
layout(std430, binding = 0) buffer MaxMag { uint max_bits; };
#else
uniform float u_inv_max;
layout(GRADIENT_FORMAT, binding = 0) writeonly uniform image3D u_dst;
#endif

void main()
{
    ivec3 size = textureSize(u_src, 0);
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, size))) return;
    vec3 g = vec3(0.0);
    for (int z = -1; z <= 1; z++)
        for (int y = -1; y <= 1; y++)
            for (int x = -1; x <= 1; x++) {
                vec3 o = vec3(x, y, z);
                vec3 h = 2.0 - abs(o);
                ivec3 q = clamp(c + ivec3(x, y, z), ivec3(0), size - 1);
                g += o * vec3(h.y * h.z, h.x * h.z, h.x * h.y) * texelFetch(u_src, q, 0).r;
            }
    g /= 32.0;
#ifdef MAX_PASS
    // Non-negative floats order like their bit patterns, so atomicMax works.
    atomicMax(max_bits, floatBitsToUint(length(g)));
#else
    imageStore(u_dst, c, vec4(g * u_inv_max, 0.0));
#endif
}
