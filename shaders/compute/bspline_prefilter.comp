// bspline_prefilter.comp - turns the volume into interpolating cubic
// B-spline coefficients (Unser's recursive filter, pole sqrt(3) - 2), one
// axis per dispatch and one line per invocation, in place. COPY_PASS first
// copies the normalised volume into the float coefficient image. Bricked
// storage runs the same recursion on the CPU, brick by brick from the CPU
// bricks (csrc/gradients/bspline_bricks.c), checked against this by tests/test_kernels.c.
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32f, binding = VXL_IMAGE_OUT) uniform coherent image3D u_coeffs;
#ifdef COPY_PASS
uniform sampler3D u_volume;
#else
uniform int u_axis; // 0, 1, 2: the axis the lines run along
#endif

#ifndef COPY_PASS
const float POLE = -0.26794919243112270; // sqrt(3) - 2
const float GAIN = 6.0;                  // (1 - z)(1 - 1/z)

ivec3 at(ivec2 uv, int k)
{
    return u_axis == 0 ? ivec3(k, uv) : u_axis == 1 ? ivec3(uv.x, k, uv.y) : ivec3(uv, k);
}
#endif

void main()
{
    ivec3 size = imageSize(u_coeffs);
#ifdef COPY_PASS
    for (int x = 0; x < size.x; x++) {
        ivec3 c = ivec3(x, gl_GlobalInvocationID.xy);
        if (c.y < size.y && c.z < size.z) imageStore(u_coeffs, c, texelFetch(u_volume, c, 0));
    }
#else
    ivec2 other = u_axis == 0 ? size.yz : u_axis == 1 ? size.xz : size.xy;
    int n = u_axis == 0 ? size.x : u_axis == 1 ? size.y : size.z;
    ivec2 uv = ivec2(gl_GlobalInvocationID.xy);
    if (uv.x >= other.x || uv.y >= other.y || n < 2) return;
    // causal initialisation: mirror boundary, truncated where z^k < 1e-7
    int horizon = min(n, 13);
    float zk = 1.0, sum = 0.0;
    for (int k = 0; k < horizon; k++) {
        sum += zk * GAIN * imageLoad(u_coeffs, at(uv, k)).r;
        zk *= POLE;
    }
    float prev = sum;
    imageStore(u_coeffs, at(uv, 0), vec4(prev));
    for (int k = 1; k < n; k++) {
        prev = GAIN * imageLoad(u_coeffs, at(uv, k)).r + POLE * prev;
        imageStore(u_coeffs, at(uv, k), vec4(prev));
    }
    // anticausal initialisation and pass
    float last = POLE / (POLE * POLE - 1.0) * (prev + POLE * imageLoad(u_coeffs, at(uv, n - 2)).r);
    imageStore(u_coeffs, at(uv, n - 1), vec4(last));
    for (int k = n - 2; k >= 0; k--) {
        last = POLE * (last - imageLoad(u_coeffs, at(uv, k)).r);
        imageStore(u_coeffs, at(uv, k), vec4(last));
    }
#endif
}
