// brick_minmax.comp - min and max of the normalised value per brick of
// BRICK^3 voxels, over the brick plus a one-voxel apron: every voxel that a
// trilinear sample inside the brick's box can touch. Computed once per volume.
// Its one CPU copy is vxl_bricks_minmax_cpu (csrc/storage/paging.c, for
// bricked storage); skipping.c snaps integer texels to code / (2^bits - 1)
// as that copy computes it, and tests/test_kernels.c checks the two grids
// are the same floats.
// With GRADIENT_BOUND: instead, a bound on the gradient magnitude of any
// difference filter (central, forward3, Sobel) at a sample in the brick:
// the trilinear interpolant is Lipschitz along each axis with the largest
// difference of adjacent voxels along it (over the cells the taps reach,
// u_apron voxels around the brick), and every such filter's component is a
// difference quotient along one axis. Used by iso-surface skipping.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
uniform sampler3D u_volume;
uniform int u_brick;
layout(rg32f, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_minmax;

#ifdef GRADIENT_BOUND
uniform int u_apron;
void main()
{
    ivec3 b = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(b, imageSize(u_minmax)))) return;
    ivec3 size = textureSize(u_volume, 0);
    // clamp-to-edge sampling repeats the border voxel: differences there are 0
    ivec3 lo = max(b * u_brick - u_apron, ivec3(0)), hi = min(b * u_brick + u_brick - 1 + u_apron, size - 1);
    vec3 l = vec3(0.0);
    for (int z = lo.z; z <= hi.z; z++)
        for (int y = lo.y; y <= hi.y; y++)
            for (int x = lo.x; x <= hi.x; x++) {
                float v = texelFetch(u_volume, ivec3(x, y, z), 0).r;
                if (x < hi.x) l.x = max(l.x, abs(texelFetch(u_volume, ivec3(x + 1, y, z), 0).r - v));
                if (y < hi.y) l.y = max(l.y, abs(texelFetch(u_volume, ivec3(x, y + 1, z), 0).r - v));
                if (z < hi.z) l.z = max(l.z, abs(texelFetch(u_volume, ivec3(x, y, z + 1), 0).r - v));
            }
    imageStore(u_minmax, b, vec4(length(l), 0.0, 0.0, 0.0));
}
#else
void main()
{
    ivec3 b = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(b, imageSize(u_minmax)))) return;
    ivec3 size = textureSize(u_volume, 0);
    ivec3 lo = max(b * u_brick - 1, ivec3(0)), hi = min(b * u_brick + u_brick, size - 1);
    float mn = 1e30, mx = -1e30;
    for (int z = lo.z; z <= hi.z; z++)
        for (int y = lo.y; y <= hi.y; y++)
            for (int x = lo.x; x <= hi.x; x++) {
                float v = texelFetch(u_volume, ivec3(x, y, z), 0).r;
                mn = min(mn, v);
                mx = max(mx, v);
            }
    imageStore(u_minmax, b, vec4(mn, mx, 0.0, 0.0));
}
#endif
