// cut_peel.vert - one corner of a cutter triangle (csrc/cut/cutaway.c):
// world position to clip space with the frame's camera, its planar view
// depth, and its triangle's unit normal (gradient space) and cutter index,
// the same on all three corners.
layout(location = 0) in vec3 a_pos;            // world
layout(location = 1) in vec4 a_normal_cutter;  // xyz: normal, w: cutter index
uniform mat4 u_view_proj; // world -> clip
uniform mat4 u_view;      // world -> view
out float v_depth;
flat out vec4 v_normal_cutter;

void main()
{
    vec4 w = vec4(a_pos, 1.0);
    gl_Position = u_view_proj * w;
    v_depth = -(u_view * w).z; // affine in world space: perspective-correct interpolation is exact
    v_normal_cutter = a_normal_cutter;
}
