// palette.glsl - where palette entry `code` of compressed brick `row` lies in
// the palette texture: 16 palettes of 256 values per texel row
// (VXL_PALETTES_PER_ROW in renderer_internal.h).
uniform sampler2D u_palette;

float palette_value(int row, uint code)
{
    return texelFetch(u_palette, ivec2((row % 16) * 256 + int(code), row / 16), 0).r;
}
