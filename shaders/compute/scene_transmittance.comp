// scene_transmittance.comp - the volume's shadow on the scene
// (csrc/light/transmittance.c): per pixel, the scene point at the given
// depth through the frame's camera, and the transmittance of its path to
// light u_light through the volume: the light's illumination volume, which
// holds every cell's transmittance to the light (mesh shadows included),
// read where the path enters the volume's box (at the point when inside).
uniform vec3 u_dims;
#include "lib/illumination.glsl"
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(r32f, binding = VXL_IMAGE_OUT) writeonly uniform image2D u_out;
uniform sampler2D u_scene_depth; // view-space planar distance, +inf: no geometry
uniform mat4 u_inv_proj;         // clip -> view
uniform mat4 u_view_to_voxel;
uniform vec2 u_viewport;
uniform int u_light;

// The transmittance to the light from voxel position p.
float transmittance_from(vec3 p)
{
    vec4 l = u_light_voxel[u_light];
    vec3 d = l.w == 0.0 ? l.xyz : l.xyz - p; // towards the light; a point light ends at t = 1
    float t0 = 0.0, t1 = l.w == 0.0 ? 1e30 : 1.0;
    for (int a = 0; a < 3; a++) {
        float lo = -0.5, hi = u_dims[a] - 0.5;
        if (abs(d[a]) < 1e-20) {
            if (p[a] < lo || p[a] > hi) return 1.0; // parallel to the slab, outside it
            continue;
        }
        float ta = (lo - p[a]) / d[a], tb = (hi - p[a]) / d[a];
        t0 = max(t0, min(ta, tb));
        t1 = min(t1, max(ta, tb));
    }
    if (t0 > t1) return 1.0; // the path misses the box
    return light_transmittance(u_light, p + d * t0);
}

void main()
{
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= int(u_viewport.x) || px.y >= int(u_viewport.y)) return;
    float depth = texelFetch(u_scene_depth, px, 0).r;
    float t = 1.0;
    if (depth > 0.0 && depth < 3.0e38) { // +inf, NaN and nothing in front of the eye: no scene point
        vec2 ndc = (vec2(px) + 0.5) / u_viewport * 2.0 - 1.0;
        vec4 a = u_inv_proj * vec4(ndc, -1.0, 1.0), b = u_inv_proj * vec4(ndc, 1.0, 1.0);
        vec3 near = a.xyz / a.w, far = b.xyz / b.w;
        // the point on the pixel's ray at view z = -depth (any projection)
        vec3 v = mix(near, far, (-depth - near.z) / (far.z - near.z));
        t = transmittance_from((u_view_to_voxel * vec4(v, 1.0)).xyz);
    }
    imageStore(u_out, px, vec4(t));
}
