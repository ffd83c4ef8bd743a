// shading.glsl - Phong shading with gradient normals, in view space.
uniform mat3 u_normal_matrix; // voxel-space gradient -> view-space normal
uniform vec4 u_material;      // ambient, diffuse, specular, shininess
#ifdef LABELS
// the material of the label whose sample is being lit, set by
// lib/labels.glsl before shading it; x < 0: the frame's (u_material).
vec4 g_label_material = vec4(-1.0);
#define SHADE_MATERIAL (g_label_material.x >= 0.0 ? g_label_material : u_material)
#else
#define SHADE_MATERIAL u_material
#endif
uniform int u_light_count;
uniform vec4 u_light_pos[8];  // view space; w = 0 direction towards light (unit, frame.c), 1 point
uniform vec3 u_light_color[8];// colour * intensity
#ifdef ENVIRONMENT
// The World's light (voxlight.h's vxl_environment) in place of the ambient
// term: its mean radiance here (Phong), its irradiance volume in shade_lit.
uniform vec3 u_env_mean;
#endif

// Most frames have one directional light (frame.c's headlight when none is
// given); raycast.frag's march has a copy of the sample loop for that case
// (one_directional, a constant at each call) that lights it outside any loop:
// on llvmpipe a loop over the lights inside the sample loop runs its body at
// least once and costs more than the lighting itself. What of that light is
// constant along a ray is worked out once per ray: the unit vector v towards
// the eye, the light's l and the half vector h.
struct RayLighting {
    vec3 v;
    vec3 l0, h0;
};

RayLighting ray_lighting(vec3 v)
{
    vec3 l = normalize(u_light_pos[0].xyz);
    return RayLighting(v, l, normalize(l + v));
}

// Diffuse and specular light from light i on unit normal n, given the
// light's l and half vector h there.
vec3 light_term(int i, vec3 rgb, vec3 n, vec3 l, vec3 h)
{
    float ndl = dot(n, l);
    float spec = pow(max(dot(n, h), 0.0), SHADE_MATERIAL.w);
    return ndl > 0.0 ? u_light_color[i] * (SHADE_MATERIAL.y * ndl * rgb + SHADE_MATERIAL.z * spec) : vec3(0.0);
}

vec3 point_light_term(int i, vec3 rgb, vec3 n, vec3 pos, vec3 v)
{
    vec3 l = normalize(u_light_pos[i].xyz - pos);
    return light_term(i, rgb, n, l, normalize(l + v));
}

// rgb: classified colour; g: voxel-space gradient; pos: view-space position;
// r: the ray's lighting; one_directional: u_light_count is 1 and light 0
// is directional. A vanishing gradient has no direction, so the sample is
// left unlit (emission only) instead of producing NaN.
vec3 shade(vec3 rgb, vec3 g, vec3 pos, RayLighting r, bool one_directional)
{
    vec3 n = u_normal_matrix * g;
    float len = length(n);
    if (!(len > 1e-20)) return rgb;
    n /= len;
    if (dot(n, r.v) < 0.0) n = -n; // two-sided: a boundary faces the viewer
#ifdef ENVIRONMENT
    vec3 acc = SHADE_MATERIAL.y * rgb * u_env_mean;
#else
    vec3 acc = SHADE_MATERIAL.x * rgb;
#endif
    if (one_directional) {
        acc += light_term(0, rgb, n, r.l0, r.h0);
    } else {
        for (int i = 0; i < u_light_count; i++) {
            if (u_light_pos[i].w == 0.0) {
                vec3 l = normalize(u_light_pos[i].xyz);
                acc += light_term(i, rgb, n, l, normalize(l + r.v));
            } else {
                acc += point_light_term(i, rgb, n, pos, r.v);
            }
        }
    }
    return clamp_colour(acc);
}

// Shading models beyond Phong, one per program: SHADING_MODEL 1
// shadowed, 2 scatter, with the formulas of voxlight.h's VXL_SHADING_*.
// Without the define (PHONG) none of this is compiled: shade() above stays
// today's, bit for bit.
#ifndef SHADING_MODEL
#define SHADING_MODEL 0
#endif
#if SHADING_MODEL > 0
#include "lib/illumination.glsl"
uniform vec3 u_spot_dir[8];     // view space, the direction each spot points along
uniform vec4 u_spot_shape[8];   // cos(half the cone) (< -1: no cone), Blender's spot_blend
uniform float u_ao_strength;    // s
uniform float u_anisotropy;     // Henyey-Greenstein g
uniform float u_scatter_ref;    // gradient magnitude where scattering gives way to surface shading

// Blender's spot mask for light i, with l the unit vector from the sample
// towards the light: smoothstep over the blend, a hard edge at 0.
float spot_mask(int i, vec3 l)
{
    float c = u_spot_shape[i].x;
    if (c < -1.0) return 1.0;
    float cos_a = dot(-l, u_spot_dir[i]);
    float blend = (1.0 - c) * u_spot_shape[i].y;
    if (!(blend > 0.0)) return cos_a > c ? 1.0 : 0.0;
    return smoothstep(0.0, 1.0, (cos_a - c) / blend);
}

#if SHADING_MODEL == 2
// 4 pi times the Henyey-Greenstein phase function of cos t, t the angle
// between the light's travel (-l) and the direction to the eye (v): 1 for g = 0.
float phase_4pi(vec3 l, vec3 v)
{
    float g = u_anisotropy, c = dot(-l, v);
    return (1.0 - g * g) / pow(max(1.0 + g * g - 2.0 * g * c, 1e-6), 1.5);
}
#endif

// The light of light i (unit l towards it, h the half vector) on a sample
// of colour rgb with unit normal n (has_normal false: no surface, w = 0),
// surface weight w, before its transmittance.
vec3 lit_term(int i, vec3 rgb, vec3 n, bool has_normal, float w, vec3 l, vec3 h, vec3 v)
{
#if SHADING_MODEL == 1
    return light_term(i, rgb, n, l, h);
#else
    vec3 surface = has_normal && w > 0.0 ? w * light_term(i, rgb, n, l, h) : vec3(0.0);
    return surface + (1.0 - w) * u_light_color[i] * SHADE_MATERIAL.y * rgb * phase_4pi(l, v);
#endif
}

// shade() with shadows, occlusion and (SCATTER) the phase function: p is the
// sample's voxel position, where the illumination volumes are read. The sum
// before shade_lit's clamp: render/path.frag adds it, unclamped, at every
// collision of a path.
vec3 shade_lit_sum(vec3 rgb, vec3 g, vec3 pos, vec3 p, RayLighting r, bool one_directional)
{
    vec3 n = u_normal_matrix * g;
    float len = length(n);
    bool has_normal = len > 1e-20;
#if SHADING_MODEL == 1
    if (!has_normal) return rgb; // as shade(): no direction, emission only
    float w = 1.0;
#else
    float w = min(1.0, length(g) / u_scatter_ref);
    if (!has_normal) w = 0.0;
#endif
    if (has_normal) {
        n /= len;
        if (dot(n, r.v) < 0.0) n = -n;
    }
#ifdef ENVIRONMENT
    // isotropic: the irradiance is a mean over the sphere, the phase
    // function's 1 / 4 pi and the cells' solid angles folded in
    vec3 acc = SHADE_MATERIAL.y * rgb * environment_light(p, g);
#else
    vec3 acc = SHADE_MATERIAL.x * rgb * (1.0 - u_ao_strength * (1.0 - ambient_occlusion(p)));
#endif
    if (one_directional) {
        acc += light_transmittance(0, p) * lit_term(0, rgb, n, has_normal, w, r.l0, r.h0, r.v);
    } else {
        for (int i = 0; i < u_light_count; i++) {
            vec3 l = u_light_pos[i].w == 0.0 ? normalize(u_light_pos[i].xyz) : normalize(u_light_pos[i].xyz - pos);
            float mask = spot_mask(i, l);
            if (mask > 0.0)
                acc += mask * light_transmittance(i, p) * lit_term(i, rgb, n, has_normal, w, l, normalize(l + r.v), r.v);
        }
    }
    return acc;
}

vec3 shade_lit(vec3 rgb, vec3 g, vec3 pos, vec3 p, RayLighting r, bool one_directional)
{
    return clamp_colour(shade_lit_sum(rgb, g, pos, p, r, one_directional));
}
#endif
