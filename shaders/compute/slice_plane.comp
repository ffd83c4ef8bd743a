// slice_plane.comp - vxl_render_slice (render/slice_plane.c): the volume
// resampled on a plane, one invocation per output pixel, through the same
// sampling code as the ray caster (lib/common.glsl: one texture, or the page
// table of bricked, sparse and compressed storage), so every storage mode
// gives the same image. Voxels are read texel-exact (texelFetch) and weighted
// in float here, never by the texture unit, whose fixed-point weights
// (8 fractional bits on many GPUs, and llvmpipe's unorm8 lerps rounded to
// 1/255) would cost the linear slice its accuracy. INTERP: 0 nearest,
// 1 linear, 2 cubic (compiled with FILTER_CUBIC: the interpolating B-spline's
// coefficients, as the cubic gradient filter reads them). DATA_COLOUR: a
// colour volume's own colour replaces the table's (lib/colour.glsl).
#include "lib/gradients.glsl"
#include "lib/colour.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = VXL_IMAGE_OUT) writeonly uniform image2D u_out;
uniform mat4 u_plane_to_voxel; // slice square [-1, 1]^2 at z = 0 -> voxel space (affine)
uniform sampler1D u_tf;        // straight RGBA table, read texel-exact
uniform int u_tf_size;
uniform vec2 u_window;         // (offset, scale) in normalised value units

#ifndef PAGED
float voxel(ivec3 c) { return texelFetch(u_volume, clamp(c, ivec3(0), ivec3(u_dims) - 1), 0).r; }
vec3 level_pos(vec3 p) { return p; }
#else
// A coarser level (sparse storage's LOD fallback) is read as the level's own voxels.
float voxel(ivec3 c) { return paged_fetch(clamp(c, ivec3(0), ivec3(u_page_dims) - 1)); }
vec3 level_pos(vec3 p) { return level_position(p); }
#endif

float trilinear(vec3 q)
{
    vec3 f = floor(q), w = q - f;
    ivec3 i = ivec3(f);
    float c000 = voxel(i), c100 = voxel(i + ivec3(1, 0, 0));
    float c010 = voxel(i + ivec3(0, 1, 0)), c110 = voxel(i + ivec3(1, 1, 0));
    float c001 = voxel(i + ivec3(0, 0, 1)), c101 = voxel(i + ivec3(1, 0, 1));
    float c011 = voxel(i + ivec3(0, 1, 1)), c111 = voxel(i + ivec3(1, 1, 1));
    return mix(mix(mix(c000, c100, w.x), mix(c010, c110, w.x), w.y), mix(mix(c001, c101, w.x), mix(c011, c111, w.x), w.y),
               w.z);
}

#if INTERP == 2
// The spline's value over the 4x4x4 coefficients around q (gradients.glsl's
// bspline_gradient without the derivative weights).
float bspline_value(vec3 q)
{
    vec3 fq = floor(q), a = q - fq;
    ivec3 b = ivec3(fq) - 1;
    vec4 wx = bspline_weights(a.x), wy = bspline_weights(a.y), wz = bspline_weights(a.z);
    float v = 0.0;
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++) {
            vec4 row = vec4(spline_coeff(b + ivec3(0, j, k)), spline_coeff(b + ivec3(1, j, k)),
                            spline_coeff(b + ivec3(2, j, k)), spline_coeff(b + ivec3(3, j, k)));
            v += dot(wx, row) * wy[j] * wz[k];
        }
    return v;
}
#endif

float value_at(vec3 p)
{
    vec3 q = level_pos(p);
#if INTERP == 0
    return voxel(ivec3(floor(q + 0.5)));
#elif INTERP == 1
    return trilinear(q);
#else
    return bspline_value(q);
#endif
}

// The table's colour at window position x, interpolated between its two
// nearest entries in float (a texture unit's weights are coarser).
vec3 colour_of(float v)
{
    float x = clamp((v - u_window.x) * u_window.y, 0.0, 1.0) * float(u_tf_size - 1);
    int i = min(int(floor(x)), u_tf_size - 2);
    float t = x - float(i);
    return mix(texelFetch(u_tf, i, 0).rgb, texelFetch(u_tf, i + 1, 0).rgb, t);
}

void main()
{
    ivec2 px = ivec2(gl_GlobalInvocationID.xy), size = imageSize(u_out);
    if (px.x >= size.x || px.y >= size.y) return;
    vec2 uv = (vec2(px) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec3 p = (u_plane_to_voxel * vec4(uv, 0.0, 1.0)).xyz;
    bool inside = all(greaterThanEqual(p, vec3(-0.5))) && all(lessThanEqual(p, u_dims - 0.5));
#ifdef DATA_COLOUR
    // the nearest voxel's colour, or the colour texture's trilinear one (its
    // 8-bit texels need no finer weights); cubic takes the trilinear colour
#if INTERP == 0
    vec3 rgb = texelFetch(u_colour, clamp(ivec3(floor(p + 0.5)), ivec3(0), ivec3(u_dims) - 1), 0).rgb;
#else
    vec3 rgb = data_colour(p);
#endif
#else
    vec3 rgb = colour_of(value_at(p));
#endif
    imageStore(u_out, px, inside ? vec4(rgb, 1.0) : vec4(0.0));
}
