// probe.comp - evaluates the selected gradient filter at given points with
// the very code the ray caster runs (lib/gradients.glsl), so tests and the
// benchmark measure the real shader, not a C copy.
#include "lib/gradients.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = VXL_SSBO_PROBE_POINTS) readonly buffer Points { float pts[]; };
layout(std430, binding = VXL_SSBO_PROBE_RESULTS) writeonly buffer Result { float res[]; };
uniform uint u_count;
uniform int u_sequential; // 1: points are consecutive samples of one ray (reuseGradients)

vec3 point(uint i) { return vec3(pts[3u * i], pts[3u * i + 1u], pts[3u * i + 2u]); }
void store(uint i, vec3 g) { res[3u * i] = g.x; res[3u * i + 1u] = g.y; res[3u * i + 2u] = g.z; }

void main()
{
    uint id = gl_GlobalInvocationID.x;
    if (u_sequential != 0) {
        if (id != 0u) return;
        GradientState gs = gradient_state_init();
        for (uint i = 0u; i < u_count; i++) {
            vec3 p = point(i);
            store(i, reuse_gradient(gs, gradient_at(p, sample_value(p))));
        }
        return;
    }
    if (id >= u_count) return;
    vec3 p = point(id);
    store(id, gradient_at(p, sample_value(p)));
}
