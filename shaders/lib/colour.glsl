// colour.glsl - a colour volume's own colour (DATA_COLOUR; colour/colour.c):
// an RGB8 texture on the scalar volume's grid, dense whatever the scalar's
// storage, read at the sample's voxel position with the same trilinear
// filter. It replaces the transfer function's colour; opacity stays the
// table's opacity of the scalar (the opacity source), so skipping, early
// termination, shadows and every derived volume are unchanged.
#ifdef DATA_COLOUR
uniform sampler3D u_colour;

vec3 srgb_to_linear(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

vec3 data_colour(vec3 p)
{
    vec3 c = textureLod(u_colour, (p + 0.5) / u_dims, 0.0).rgb;
    return u_linear ? srgb_to_linear(c) : c; // the data's RGB is display-referred
}

// Classified sample c (straight colour) at voxel position p with its colour
// taken from the data.
vec4 with_data_colour(vec4 c, vec3 p) { return vec4(data_colour(p), c.a); }
#endif
