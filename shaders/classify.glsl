// classify.glsl - post-classification through a 1D RGBA transfer function.
// The window maps data onto the table: x = (value - offset) * scale.
uniform sampler1D u_tf;     // straight RGBA; alpha is opacity per voxel of path
uniform float u_tf_size;
uniform vec2 u_window;      // (offset, scale) in normalised value units
uniform float u_opacity_scale;

vec4 classify(float v)
{
    float x = clamp((v - u_window.x) * u_window.y, 0.0, 1.0);
    vec4 c = textureLod(u_tf, (x * (u_tf_size - 1.0) + 0.5) / u_tf_size, 0.0);
    c.a = clamp(c.a * u_opacity_scale, 0.0, 1.0);
    return c;
}

// Opacity correction for a step of `step` voxels against the table's unit of
// one voxel: a' = 1 - (1 - a)^step. pow(0, y > 0) is defined; pow of a
// negative base is not, so a is clamped first.
float correct_opacity(float a, float step)
{
    float t = clamp(1.0 - a, 0.0, 1.0);
    return t <= 0.0 ? 1.0 : 1.0 - pow(t, step);
}
