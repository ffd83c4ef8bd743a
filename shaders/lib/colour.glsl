// colour.glsl - a colour volume's own colour (DATA_COLOUR; colour/colour.c):
// an RGB8 texture on the scalar volume's grid, dense whatever the scalar's
// storage, read at the sample's voxel position with the same trilinear
// filter. It replaces the transfer function's colour; opacity stays the
// table's opacity of the scalar (the opacity source), so skipping, early
// termination, shadows and every derived volume are unchanged.
#ifdef DATA_COLOUR
uniform sampler3D u_colour;

vec3 data_colour(vec3 p) { return textureLod(u_colour, (p + 0.5) / u_dims, 0.0).rgb; }

// Classified sample c (straight colour) at voxel position p with its colour
// taken from the data.
vec4 with_data_colour(vec4 c, vec3 p) { return vec4(data_colour(p), c.a); }
#endif
