// shadow_maps.glsl - one light's visibility through the scene's occluders
// (csrc/light/shadow_maps.c): its shadow maps, one layer per view
// (one view, or six for a cube about a point light), depth compared to the
// point's own with a bias towards the light and filtered over a footprint
// (percentage-closer filtering on the bilinear compare the sampler makes).
uniform sampler2DArrayShadow u_shadow_maps;
uniform mat4 u_shadow_matrix[6]; // world -> each view's clip space
uniform int u_shadow_views;
uniform float u_shadow_first_layer;
uniform vec4 u_shadow_light;     // world: w = 0 unit direction towards the light, 1 its position
uniform float u_shadow_bias;     // world units the compared point moves towards the light
uniform float u_shadow_pcf;      // the filter's half width, texels

// 1 where nothing lies between world point w and the light, 0 where an
// occluder does, in between over the filter's footprint at shadow edges.
float shadow_visibility(vec3 w)
{
    vec3 towards = u_shadow_light.w == 0.0 ? u_shadow_light.xyz : u_shadow_light.xyz - w;
    float len = length(towards);
    vec3 wb = len > 1e-12 ? w + towards * (min(u_shadow_bias, 0.5 * len) / len) : w;
    for (int v = 0; v < u_shadow_views; v++) {
        vec4 c = u_shadow_matrix[v] * vec4(w, 1.0);
        if (!(c.w > 0.0)) continue;
        vec2 ndc = c.xy / c.w;
        if (any(greaterThan(abs(ndc), vec2(1.0)))) continue; // another view of the cube
        vec4 cb = u_shadow_matrix[v] * vec4(wb, 1.0);
        float ref = clamp((cb.z / max(cb.w, 1e-30)) * 0.5 + 0.5, 0.0, 1.0);
        vec2 uv = ndc * 0.5 + 0.5;
        vec2 texel = 1.0 / vec2(textureSize(u_shadow_maps, 0).xy);
        float layer = u_shadow_first_layer + float(v);
        // a 4x4 grid over the footprint, each tap a bilinear compare
        float sum = 0.0;
        for (int y = 0; y < 4; y++)
            for (int x = 0; x < 4; x++) {
                vec2 o = (vec2(x, y) - 1.5) / 1.5 * u_shadow_pcf * texel;
                sum += texture(u_shadow_maps, vec4(uv + o, layer, ref));
            }
        return sum / 16.0;
    }
    return 1.0; // outside every view: nothing was rasterised towards the light there
}
