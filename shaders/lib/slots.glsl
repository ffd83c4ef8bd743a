// slots.glsl - where slot k of a pool lies. Every pool (the data's bricks,
// the derived volumes' bricks, the compressed codes, the decode cache)
// stores cubes of `edge` texels in slots counted x fastest, as the C side
// lays them out (vxl_pool_layout): slot k at column k % slots.x, row
// (k / slots.x) % slots.y, layer k / (slots.x * slots.y).
ivec3 slot_corner(int k, ivec3 slots, int edge)
{
    return ivec3(k % slots.x, (k / slots.x) % slots.y, k / (slots.x * slots.y)) * edge;
}

// The slot number of slot position s (a slot corner / edge).
int slot_index(ivec3 s, ivec3 slots) { return s.x + slots.x * (s.y + slots.y * s.z); }
