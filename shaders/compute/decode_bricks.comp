// decode_bricks.comp - deferred filtering of compressed storage, step one:
// decodes the bricks a frame needs (value = palette[code] per voxel, ghost
// border included) from the code pool into the linear cache, an ordinary
// data pool that the ray caster then filters with hardware trilinear.
// CACHE_FORMAT: the cache's image format (r8, r16, r32f).
#include "lib/palette.glsl"
#include "lib/slots.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = VXL_SSBO_BRICK_LIST) readonly buffer Decode { int source_slot[]; }; // per cache slot: its code slot = palette row
layout(CACHE_FORMAT, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_cache;
uniform usampler3D u_codes;
uniform int u_edge;   // voxels per stored brick edge, ghost included
uniform int u_count;  // cache slots to fill
uniform int u_first;  // first slot of this dispatch (dispatches are chunked)
uniform ivec3 u_cache_slots, u_code_slots;

void main()
{
    ivec3 t = ivec3(gl_GlobalInvocationID);
    int k = u_first + t.z / u_edge;
    ivec3 l = ivec3(t.xy, t.z % u_edge);
    if (k >= u_count || any(greaterThanEqual(l, ivec3(u_edge)))) return;
    int s = source_slot[k];
    uint code = texelFetch(u_codes, slot_corner(s, u_code_slots, u_edge) + l, 0).r;
    imageStore(u_cache, slot_corner(k, u_cache_slots, u_edge) + l, vec4(palette_value(s, code)));
}
