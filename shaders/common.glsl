// common.glsl - volume sampling shared by the ray caster, the probe and the
// gradient filters. Positions are in voxel space: voxel centres at integers,
// the box is [-0.5, dims-0.5].
uniform sampler3D u_volume; // normalised value in [0,1], trilinear, clamp to edge
uniform vec3 u_dims;

vec3 voxel_to_tex(vec3 p) { return (p + 0.5) / u_dims; }

// textureLod, not texture: compute shaders have no derivatives, and ray loops
// are non-uniform control flow in fragment shaders.
float sample_value(vec3 p) { return textureLod(u_volume, voxel_to_tex(p), 0.0).r; }
