// paged_gradient.comp - the precomputed gradient filter's texture for bricked
// storage: the same [1,2,1]^3 blur then 26-neighbour Sobel as
// gradient_blur.comp and gradient_sobel.comp, computed per derived brick in a
// pool of its own. BLUR_PASS blurs each derived brick plus a two-voxel
// border (ghost + the Sobel's reach) from the data pool through the page
// table; the store pass runs the Sobel inside each blurred slot (the largest
// magnitude, which scales it, comes from the CPU: bspline_bricks.c).
// Positions outside the volume repeat its edge, as clamped fetches of one
// texture do, so every texel equals the dense texture's.
#define PAGED 1
#include "common.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = 2) readonly buffer Derived { ivec4 derived_brick[]; }; // brick coords per slot
uniform int u_brick;      // P
uniform int u_count;      // derived bricks
uniform int u_first;      // first slot of this dispatch (dispatches are chunked)
uniform ivec3 u_slots;    // slots per axis of the pool written (or read, for the Sobel)
uniform int u_blur_first; // the blurred slots hold bricks u_blur_first.. (a chunk)

ivec3 slot_origin(int k, int edge) { return ivec3(k % u_slots.x, (k / u_slots.x) % u_slots.y, k / (u_slots.x * u_slots.y)) * edge; }

#ifdef BLUR_PASS
layout(r32f, binding = 0) writeonly uniform image3D u_dst;

float voxel(ivec3 c) { return paged_fetch(clamp(c, ivec3(0), ivec3(u_dims) - 1)); }

void main()
{
    int edge = u_brick + 4;
    ivec3 t = ivec3(gl_GlobalInvocationID);
    int k = u_first + t.z / edge;
    ivec3 l = ivec3(t.xy, t.z % edge);
    if (k >= u_count || any(greaterThanEqual(l, ivec3(edge)))) return;
    // the volume voxel this texel stands for (border of 2: ghost + Sobel reach)
    ivec3 c = clamp(derived_brick[k].xyz * u_brick + l - 2, ivec3(0), ivec3(u_dims) - 1);
    float s = 0.0;
    for (int z = -1; z <= 1; z++)
        for (int y = -1; y <= 1; y++)
            for (int x = -1; x <= 1; x++) {
                vec3 w = 2.0 - abs(vec3(x, y, z));
                s += w.x * w.y * w.z * voxel(c + ivec3(x, y, z));
            }
    imageStore(u_dst, slot_origin(k - u_blur_first, edge) + l, vec4(s / 64.0));
}
#else
uniform sampler3D u_blur;  // blurred slots of edge P+4
uniform ivec3 u_blur_slots;
uniform float u_inv_max;  // 1 / the whole volume's largest |gradient|, found on the CPU
layout(GRADIENT_FORMAT, binding = 0) writeonly uniform image3D u_dst;

void main()
{
    int edge = u_brick + 2;
    ivec3 t = ivec3(gl_GlobalInvocationID);
    int k = u_first + t.z / edge;
    ivec3 l = ivec3(t.xy, t.z % edge);
    if (k >= u_count || any(greaterThanEqual(l, ivec3(edge)))) return;
    int kb = k - u_blur_first;
    ivec3 bo = ivec3(kb % u_blur_slots.x, (kb / u_blur_slots.x) % u_blur_slots.y, kb / (u_blur_slots.x * u_blur_slots.y)) * (u_brick + 4);
    // the volume voxel of this texel, and where its neighbours' blurred values lie
    ivec3 c = derived_brick[k].xyz * u_brick + l - 1;
    vec3 g = vec3(0.0);
    for (int z = -1; z <= 1; z++)
        for (int y = -1; y <= 1; y++)
            for (int x = -1; x <= 1; x++) {
                vec3 o = vec3(x, y, z);
                vec3 h = 2.0 - abs(o);
                // clamp in volume coordinates (as the dense Sobel does), then into the slot
                ivec3 q = clamp(clamp(c, ivec3(0), ivec3(u_dims) - 1) + ivec3(x, y, z), ivec3(0), ivec3(u_dims) - 1);
                g += o * vec3(h.y * h.z, h.x * h.z, h.x * h.y) * texelFetch(u_blur, bo + q - derived_brick[k].xyz * u_brick + 2, 0).r;
            }
    g /= 32.0;
    imageStore(u_dst, slot_origin(k, edge) + l, vec4(g * u_inv_max, 0.0));
}
#endif
