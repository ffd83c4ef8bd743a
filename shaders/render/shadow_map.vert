// shadow_map.vert - the scene's occluder triangles
// (csrc/light/shadow_maps.c) as one light's view sees them: world positions
// to that view's clip space. Depth only (shadow_map.frag).
layout(location = 0) in vec3 a_position; // world
uniform mat4 u_light_matrix;             // world -> the view's clip space

void main() { gl_Position = u_light_matrix * vec4(a_position, 1.0); }
