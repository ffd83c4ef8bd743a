// slices.vert - one proxy polygon of the slicing modes (csrc/slices.c), drawn
// as a triangle fan: its corners in voxel space come as uniforms, so no
// vertex buffer is needed for a handful of points per slice.
uniform vec3 u_poly[12];
uniform mat4 u_mvp; // voxel -> clip
out vec3 v_pos;     // voxel space

void main()
{
    v_pos = u_poly[gl_VertexID];
    gl_Position = u_mvp * vec4(v_pos, 1.0);
}
