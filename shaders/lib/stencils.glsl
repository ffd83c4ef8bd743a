// stencils.glsl - the two 3x3x3 stencils of the gradient filters, written
// once: the [1,2,1]^3 blur and the 26-neighbour Sobel ([-1,0,1] along a
// component's axis, [1,2,1] across it). Users: the precomputed filter's
// passes (compute/gradients.comp, one texture and bricked)
// and the on-the-fly FILTER_SOBEL26 (lib/gradients.glsl). The CPU's copy of
// both, for the bricked maximum, is csrc/gradients/bspline_bricks.c (tests/test_kernels.c).
//
// The includer says what a stencil is applied at and how a tap is read:
// #define STENCIL_POINT as the type of that point (ivec3 for a voxel, vec3 for
// a position, or a struct of its own), then defines
//     float stencil_tap(STENCIL_POINT at, ivec3 o)
// the value at neighbour o (each component -1, 0 or 1) of `at`, border
// handling included. A program uses one kind of point, so one tap.
#ifndef STENCIL_POINT
#error "define STENCIL_POINT before including lib/stencils.glsl"
#endif

float stencil_tap(STENCIL_POINT at, ivec3 o);

// [1,2,1] per axis: 8 at the centre, 1 at the corners; 64 in all.
float blur121_weight(vec3 o)
{
    vec3 w = 2.0 - abs(o);
    return w.x * w.y * w.z;
}

// The Sobel weight of neighbour o for the three components: o.x h(o.y) h(o.z)
// for x, with h(0) = 2, h(+-1) = 1 (and so on): 32 per unit of slope.
vec3 sobel26_weight(vec3 o)
{
    vec3 h = 2.0 - abs(o);
    return o * vec3(h.y * h.z, h.x * h.z, h.x * h.y);
}

// The blurred value at `at`.
float blur121(STENCIL_POINT at)
{
    float s = 0.0;
    for (int z = -1; z <= 1; z++)
        for (int y = -1; y <= 1; y++)
            for (int x = -1; x <= 1; x++) s += blur121_weight(vec3(x, y, z)) * stencil_tap(at, ivec3(x, y, z));
    return s / 64.0;
}

// The weighted sum of the Sobel at `at`: 32 times the gradient per tap
// spacing (the caller divides, by 32 or 32 times its spacing). The centre
// weighs 0 and is not read.
vec3 sobel26_sum(STENCIL_POINT at)
{
    vec3 g = vec3(0.0);
    for (int z = -1; z <= 1; z++)
        for (int y = -1; y <= 1; y++)
            for (int x = -1; x <= 1; x++) {
                if (x == 0 && y == 0 && z == 0) continue;
                g += sobel26_weight(vec3(x, y, z)) * stencil_tap(at, ivec3(x, y, z));
            }
    return g;
}
