// gradient_blur.comp - first pass of precomputed gradients: the [1,2,1]^3 / 64
// blur (lib/stencils.glsl) of the volume at grid points (clamped at the border).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
uniform sampler3D u_src;
layout(r32f, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_dst;

#define STENCIL_POINT ivec3
#include "lib/stencils.glsl"

float stencil_tap(ivec3 c, ivec3 o) { return texelFetch(u_src, clamp(c + o, ivec3(0), textureSize(u_src, 0) - 1), 0).r; }

void main()
{
    ivec3 size = textureSize(u_src, 0);
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, size))) return;
    imageStore(u_dst, c, vec4(blur121(c)));
}
