// shading.glsl - Phong shading with gradient normals, in view space.
uniform mat3 u_normal_matrix; // voxel-space gradient -> view-space normal
uniform vec4 u_material;      // ambient, diffuse, specular, shininess
uniform int u_light_count;
uniform vec4 u_light_pos[8];  // view space; w = 0 direction towards light, 1 point
uniform vec3 u_light_color[8];// colour * intensity

// rgb: classified colour; g: voxel-space gradient; pos: view-space position;
// v: unit vector towards the eye. A vanishing gradient has no direction, so
// the sample is left unlit (emission only) instead of producing NaN.
vec3 shade(vec3 rgb, vec3 g, vec3 pos, vec3 v)
{
    vec3 n = u_normal_matrix * g;
    float len = length(n);
    if (!(len > 1e-20)) return rgb;
    n /= len;
    if (dot(n, v) < 0.0) n = -n; // two-sided: a boundary faces the viewer
    vec3 acc = u_material.x * rgb;
    for (int i = 0; i < u_light_count; i++) {
        vec3 l = u_light_pos[i].w == 0.0 ? normalize(u_light_pos[i].xyz)
                                         : normalize(u_light_pos[i].xyz - pos);
        float ndl = dot(n, l);
        if (ndl <= 0.0) continue;
        vec3 h = normalize(l + v);
        float spec = pow(max(dot(n, h), 0.0), u_material.w);
        acc += u_light_color[i] * (u_material.y * ndl * rgb + u_material.z * spec);
    }
    return clamp(acc, 0.0, 1.0);
}
