// common.glsl - volume sampling shared by the ray caster, the probe and the
// gradient filters. Positions are in voxel space: voxel centres at integers,
// the box is [-0.5, dims-0.5].
uniform sampler3D u_volume; // normalised value in [0,1], trilinear, clamp to edge
uniform vec3 u_dims;

vec3 voxel_to_tex(vec3 p) { return (p + 0.5) / u_dims; }

// textureLod, not texture: compute shaders have no derivatives, and ray loops
// are non-uniform control flow in fragment shaders.
#ifndef PAGED
float sample_value(vec3 p) { return textureLod(u_volume, voxel_to_tex(p), 0.0).r; }
#else
// Bricked storage: u_volume is the pool of bricks (each with a one-voxel
// ghost border), u_page the page table, one texel per brick: xyz = pool
// position of the brick's voxel 0, w < 0 resident, w >= 0 the value of a
// brick that is not in the pool (constant, or invisible under the
// classification). Every tap is translated on its own, so any filter
// footprint reads the right bricks; the ghost border keeps the trilinear
// footprint of a position inside its brick.
// u_lod_scale > 1: a coarser level (LOD fallback) of u_page_dims voxels,
// each the mean of u_lod_scale^3 full-resolution ones.
uniform sampler3D u_page;
uniform vec3 u_pool_dims;
uniform vec3 u_page_dims;
uniform float u_page_brick;
uniform float u_lod_scale;

float sample_value(vec3 p)
{
    if (u_lod_scale > 1.0) p = (p + 0.5) / u_lod_scale - 0.5; // coarse voxel k covers fine k*s .. k*s+s-1
    // clamping to the voxel centres reproduces clamp-to-edge of one texture
    vec3 q = clamp(p, vec3(0.0), u_page_dims - 1.0);
    ivec3 b = ivec3(floor((q + 0.5) / u_page_brick));
    vec4 e = texelFetch(u_page, b, 0);
    if (e.w >= 0.0) return e.w;
    return textureLod(u_volume, (e.xyz + q - vec3(b) * u_page_brick + 0.5) / u_pool_dims, 0.0).r;
}

// The stored value of voxel c (inside the volume, full resolution): what
// texelFetch of one texture returns.
float paged_fetch(ivec3 c)
{
    int n = int(u_page_brick);
    ivec3 b = c / n;
    vec4 e = texelFetch(u_page, b, 0);
    if (e.w >= 0.0) return e.w;
    return texelFetch(u_volume, ivec3(e.xyz) + c - b * n, 0).r;
}
#endif
