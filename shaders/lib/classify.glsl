// classify.glsl - classification through a 1D RGBA transfer function. The
// window maps data onto the table: x = (value - offset) * scale.
// Post-classification (default) looks up the interpolated value; CLASSIFY_PRE
// interpolates voxels classified beforehand (compute/classify_volume.comp);
// CLASSIFY_PREINT looks up whole segments in the pre-integration table.
uniform sampler1D u_tf;     // straight RGBA; alpha is opacity per voxel of path
uniform float u_tf_size;
uniform vec2 u_window;      // (offset, scale) in normalised value units
uniform float u_opacity_scale;

float window_pos(float v) { return clamp((v - u_window.x) * u_window.y, 0.0, 1.0); }

vec4 classify(float v)
{
    float x = window_pos(v);
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

#ifdef CLASSIFY_PRE
uniform sampler3D u_classified; // premultiplied RGBA per voxel, opacity scale applied

#ifndef PAGED
vec4 classified_texels(vec3 p) { return textureLod(u_classified, voxel_to_tex(p), 0.0); }
#else
// Bricked storage: u_classified is the pool classified texel for texel (the
// same slots, ghosts included). A brick not in the pool is its one value,
// classified and rounded as the RGBA8 texels are, so bricked equals dense.
vec4 classified_texels(vec3 p)
{
    vec3 t = level_position(p);
    vec4 e = page_entry(u_page, t);
    if (e.w < 0.0) return textureLod(u_classified, (t + 0.5) / u_pool_dims, 0.0);
    vec4 k = classify(e.w);
    return round(vec4(k.rgb * k.a, k.a) * 255.0) / 255.0;
}
#endif

// Straight colour and per-voxel opacity of the interpolated classified voxels
// around voxel position p.
vec4 pre_classified(vec3 p)
{
    vec4 c = classified_texels(p);
    return vec4(c.a > 0.0 ? c.rgb / c.a : vec3(0.0), c.a);
}
#endif

#ifdef CLASSIFY_PREINT
uniform sampler2D u_preint;   // (front, back) table positions -> premultiplied segment RGBA
uniform float u_preint_size;

vec4 preint_segment(float v_front, float v_back)
{
    vec2 x = vec2(window_pos(v_front), window_pos(v_back));
    return textureLod(u_preint, (x * (u_preint_size - 1.0) + 0.5) / u_preint_size, 0.0);
}
#endif

#ifndef GOPACITY
#define GOPACITY 0
#endif

// Levoy's opacity functions: opacity from the gradient magnitude (g in
// normalised value per voxel). BOUNDARY scales the table opacity; ISO
// replaces it by a surface of constant thickness around u_iso.
uniform vec2 u_gopacity_param; // boundary: (ref, exp); iso: (normalised value, thickness)

float gradient_opacity(float alpha, float v, float g)
{
#if GOPACITY == 1
    return alpha * pow(clamp(g / u_gopacity_param.x, 0.0, 1.0), u_gopacity_param.y);
#endif
    float d = abs(u_gopacity_param.x - v), r = u_gopacity_param.y;
    if (g > 0.0) return d <= r * g ? alpha * (1.0 - d / (r * g)) : 0.0;
    return d == 0.0 ? alpha : 0.0;
}
