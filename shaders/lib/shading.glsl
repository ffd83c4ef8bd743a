// shading.glsl - Phong shading with gradient normals, in view space.
uniform mat3 u_normal_matrix; // voxel-space gradient -> view-space normal
uniform vec4 u_material;      // ambient, diffuse, specular, shininess
uniform int u_light_count;
uniform vec4 u_light_pos[8];  // view space; w = 0 direction towards light (unit, frame.c), 1 point
uniform vec3 u_light_color[8];// colour * intensity

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
    float spec = pow(max(dot(n, h), 0.0), u_material.w);
    return ndl > 0.0 ? u_light_color[i] * (u_material.y * ndl * rgb + u_material.z * spec) : vec3(0.0);
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
    vec3 acc = u_material.x * rgb;
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
    return clamp(acc, 0.0, 1.0);
}
