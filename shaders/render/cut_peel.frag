// cut_peel.frag - appends this fragment's crossing to its pixel's list in
// the layers buffer (lib/cut.glsl has the format): no colour, no depth
// test, every face of every cutter. Past CUT_LAYERS only the count grows,
// so the ray caster knows the pixel is over-full.
#include "lib/cut.glsl"
in float v_depth;
flat in vec4 v_normal_cutter;

void main()
{
    int pix = int(gl_FragCoord.y) * u_cut_width + int(gl_FragCoord.x);
    uint k = atomicAdd(cut_words[pix], 1u);
    if (k < uint(CUT_LAYERS)) {
        int at = u_cut_pixels + 2 * (pix * CUT_LAYERS + int(k));
        cut_words[at] = floatBitsToUint(v_depth);
        cut_words[at + 1] = cut_pack(v_normal_cutter.xyz, uint(v_normal_cutter.w + 0.5));
    }
}
