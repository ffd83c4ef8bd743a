// illumination.glsl - what the ray caster reads of the illumination volumes
// (compute/illumination.comp, csrc/illumination.c): one texture, the
// transmittance of light i in block i and the ambient occlusion in block
// u_illum_ao_block, each block u_illum_cells cells over the volume box and
// stacked along z. One trilinear fetch per light per shaded sample.
uniform sampler3D u_illumination;
uniform vec3 u_illum_cells;
uniform float u_illum_blocks;   // blocks stacked along z
uniform int u_illum_ao_block;   // < 0: no occlusion (AO = 1)
uniform vec4 u_light_voxel[8];  // voxel space: w = 0 unit direction towards the light, 1 its position
uniform float u_illum_bias;     // voxels: reads move this far towards the light, off the sample's own cell

// Block `block` at voxel position p; z clamped inside the block so the
// trilinear fetch never blends in the next one.
float illumination_at(int block, vec3 p)
{
    vec3 x = (p + 0.5) / u_dims * u_illum_cells;
    x.z = clamp(x.z, 0.5, u_illum_cells.z - 0.5) + float(block) * u_illum_cells.z;
    return textureLod(u_illumination, x / vec3(u_illum_cells.xy, u_illum_cells.z * u_illum_blocks), 0.0).r;
}

// Transmittance from voxel position p to light i.
float light_transmittance(int i, vec3 p)
{
    vec3 towards = u_light_voxel[i].w == 0.0 ? u_light_voxel[i].xyz : u_light_voxel[i].xyz - p;
    float len = length(towards);
    return illumination_at(i, len > 1e-6 ? p + towards * (u_illum_bias / len) : p);
}

float ambient_occlusion(vec3 p) { return u_illum_ao_block < 0 ? 1.0 : illumination_at(u_illum_ao_block, p); }

#ifdef ENVIRONMENT
// The World's irradiance at voxel position p (compute/illumination.comp's
// pass 4): its own texture on cells twice the lights' size, one trilinear
// fetch.
uniform sampler3D u_environment;
uniform float u_env_bias; // voxels: half its cell
// g is the voxel-space gradient: the read moves half a cell against it
// (towards lower values, out of the usual bright-is-dense material), as a
// light's read moves towards the light, so a surface's own cell, half
// inside it, does not darken it.
vec3 environment_light(vec3 p, vec3 g)
{
    float len = length(g);
    vec3 q = len > 1e-20 ? p - g * (u_env_bias / len) : p;
    return textureLod(u_environment, (q + 0.5) / u_dims, 0.0).rgb;
}
#endif
