// gradient_blur.comp - first pass of precomputed gradients: a separable
// [1,2,1]^3 / 64 blur of the volume at grid points (clamped at the border).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
uniform sampler3D u_src;
layout(r32f, binding = 0) writeonly uniform image3D u_dst;

void main()
{
    ivec3 size = textureSize(u_src, 0);
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, size))) return;
    float s = 0.0;
    for (int z = -1; z <= 1; z++)
        for (int y = -1; y <= 1; y++)
            for (int x = -1; x <= 1; x++) {
                ivec3 q = clamp(c + ivec3(x, y, z), ivec3(0), size - 1);
                vec3 w = 2.0 - abs(vec3(x, y, z));
                s += w.x * w.y * w.z * texelFetch(u_src, q, 0).r;
            }
    imageStore(u_dst, c, vec4(s / 64.0));
}
