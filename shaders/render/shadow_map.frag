// shadow_map.frag - nothing but the depth the rasteriser writes
// (csrc/light/shadow_maps.c): the framebuffer has no colour attachment.
void main() {}
