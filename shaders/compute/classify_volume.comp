// classify_volume.comp - pre-classification: every voxel through the transfer
// function and window, stored premultiplied (so interpolation does not bleed
// colour from transparent neighbours). Re-run when the classification changes.
#include "lib/common.glsl"
#include "lib/classify.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(rgba8, binding = VXL_IMAGE_OUT) writeonly uniform image3D u_dst;

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, imageSize(u_dst)))) return;
    vec4 k = classify(texelFetch(u_volume, c, 0).r);
    imageStore(u_dst, c, vec4(k.rgb * k.a, k.a));
}
