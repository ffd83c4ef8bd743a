// matcap.glsl - MatCap shading (voxlight.h's vxl_matcap): the
// classified colour times the picture of a lit sphere at the view-space
// normal, texel (0.5 + 0.5 n.x, 0.5 + 0.5 n.y), instead of the material and
// lights. Needs lib/shading.glsl's u_normal_matrix. Compiled with MATCAP only.
#ifdef MATCAP
uniform sampler2D u_matcap; // linear RGB, row 0 = bottom (csrc/render/matcap.c)

// rgb: classified colour; g: voxel-space gradient; v: unit vector towards
// the eye. As shade(): a vanishing gradient leaves the sample unlit, and
// the normal is turned towards the viewer (a boundary is two-sided).
vec3 shade_matcap(vec3 rgb, vec3 g, vec3 v)
{
    vec3 n = u_normal_matrix * g;
    float len = length(n);
    if (!(len > 1e-20)) return rgb;
    n /= len;
    if (dot(n, v) < 0.0) n = -n;
    return clamp(rgb * textureLod(u_matcap, 0.5 + 0.5 * n.xy, 0.0).rgb, 0.0, 1.0);
}
#endif
