// common.glsl - volume sampling shared by the ray caster, the probe and the
// gradient filters. Positions are in voxel space: voxel centres at integers,
// the box is [-0.5, dims-0.5].
// (Included outside every #if: files go in once per program, where first named.)
#include "lib/slots.glsl"
// VXL_COLOR_SPACE_LINEAR: scene-linear colour in and out, so light may
// make a colour brighter than 1 (display colour is clamped to [0, 1]).
uniform bool u_linear;
vec3 clamp_colour(vec3 c) { return u_linear ? max(c, 0.0) : clamp(c, 0.0, 1.0); }

#ifndef COMPRESSED_DOMAIN
uniform sampler3D u_volume; // normalised value in [0,1], trilinear, clamp to edge
#endif
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
// PAGED_MIXED (streamed storage only, storage_streamed.c): a progressive
// frame mixes levels per brick. An entry with w < -1 is a brick of the
// level not read yet, standing in for its finest resident coarser ancestor
// s = -w times coarser (bricks nest, the same size at every level): pool
// position = xyz + (q - brick corner) / s, xyz folding in the ancestor's
// slot and the fine brick's place in it (exact in the RGBA32F table). The
// footprint stays inside the ancestor's brick and ghost. w == -1 is a
// resident brick, read exactly as without PAGED_MIXED.
uniform sampler3D u_page;
uniform vec3 u_pool_dims;
uniform vec3 u_page_dims;
uniform float u_page_brick;
uniform float u_lod_scale;

#ifdef COMPRESSED_DOMAIN
// Compressed storage filtered in the compressed domain (for measuring
// deferred filtering against it): u_volume is the code pool (8-bit codes,
// a brick's slot = its palette row), and a value is palette[code], which is
// not linear in the codes, so every tap decodes its 8 neighbours and
// weights them by hand.
#include "lib/palette.glsl"
uniform usampler3D u_volume;
uniform ivec3 u_code_slots;

int palette_row(vec3 origin)
{
    return slot_index(ivec3(origin) / (int(u_page_brick) + 2), u_code_slots); // origin = slot corner + ghost
}

float decode_texel(ivec3 t, int row) { return palette_value(row, texelFetch(u_volume, t, 0).r); }
#endif

// Full-resolution position -> position on the level in the pool (coarse
// voxel k covers fine k*s .. k*s+s-1).
vec3 level_position(vec3 p) { return u_lod_scale > 1.0 ? (p + 0.5) / u_lod_scale - 0.5 : p; }

// The entry of `table` (the page table, or that of a pool derived from the
// data: gradients, spline coefficients, all laid out brick for brick) for
// level position q, and q moved to its texel position in that pool (texel
// centres at integers). page_entry_at takes the level's size: a
// multi-channel volume's pools (lib/channels.glsl) stay at full resolution
// while the scalar's may fall back to a coarser level. Clamping q to the voxel centres first reproduces
// clamp-to-edge sampling of one texture.
vec4 page_entry_at(sampler3D table, vec3 page_dims, inout vec3 q)
{
    q = clamp(q, vec3(0.0), page_dims - 1.0);
    ivec3 b = ivec3(floor((q + 0.5) / u_page_brick));
    vec4 e = texelFetch(table, b, 0);
#ifdef PAGED_MIXED
    q = e.w < -1.0 ? e.xyz + (q - vec3(b) * u_page_brick) / -e.w : e.xyz + q - vec3(b) * u_page_brick;
#else
    q = e.xyz + q - vec3(b) * u_page_brick;
#endif
    return e;
}
vec4 page_entry(sampler3D table, inout vec3 q) { return page_entry_at(table, u_page_dims, q); }

float sample_value(vec3 p)
{
    vec3 t = level_position(p);
    vec4 e = page_entry(u_page, t);
    if (e.w >= 0.0) return e.w;
#ifndef COMPRESSED_DOMAIN
    return textureLod(u_volume, (t + 0.5) / u_pool_dims, 0.0).r;
#else
    ivec3 i = ivec3(floor(t));
    vec3 w = t - vec3(i);
    int row = palette_row(e.xyz);
    float c000 = decode_texel(i, row), c100 = decode_texel(i + ivec3(1, 0, 0), row);
    float c010 = decode_texel(i + ivec3(0, 1, 0), row), c110 = decode_texel(i + ivec3(1, 1, 0), row);
    float c001 = decode_texel(i + ivec3(0, 0, 1), row), c101 = decode_texel(i + ivec3(1, 0, 1), row);
    float c011 = decode_texel(i + ivec3(0, 1, 1), row), c111 = decode_texel(i + ivec3(1, 1, 1), row);
    return mix(mix(mix(c000, c100, w.x), mix(c010, c110, w.x), w.y), mix(mix(c001, c101, w.x), mix(c011, c111, w.x), w.y),
               w.z);
#endif
}

// The stored value of voxel c of the level in the pool (inside it): what
// texelFetch of one texture returns.
float paged_fetch(ivec3 c)
{
    int n = int(u_page_brick);
    ivec3 b = c / n;
    vec4 e = texelFetch(u_page, b, 0);
    if (e.w >= 0.0) return e.w;
#ifdef PAGED_MIXED
    // a stand-in ancestor: its field at voxel c's centre (trilinear), so
    // stencils over a coarse region see a smooth field, not steps of s voxels
    if (e.w < -1.0) return textureLod(u_volume, (e.xyz + vec3(c - b * n) / -e.w + 0.5) / u_pool_dims, 0.0).r;
#endif
#ifndef COMPRESSED_DOMAIN
    return texelFetch(u_volume, ivec3(e.xyz) + c - b * n, 0).r;
#else
    return decode_texel(ivec3(e.xyz) + c - b * n, palette_row(e.xyz));
#endif
}
#endif
