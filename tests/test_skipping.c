/* test_skipping.c - skipping what a scene doesn't need must not change the
 * image: every phantom and filter rendered with all in-frame skips on
 * (bricks, screen bound, early termination) against all of them off.
 * Brick leaping and the screen bound are exact by construction; early
 * termination drops at most 1 - threshold of each pixel, so the test runs it
 * at 0.999 (<= 1e-3 per channel, >= 60 dB) and checks the default 0.99
 * against its own bound. */
#include <stdio.h>

#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h" /* the test hooks */

static vxl_renderer *R;

#define W 64
#define H 64

TEST(skipping_never_changes_the_image)
{
    static float on[W * H * 4], off[W * H * 4];
    const uint32_t kinds[5] = {VXL_PHANTOM_MARSCHNER_LOBB, VXL_PHANTOM_SPHERE, VXL_PHANTOM_NOISY_BLOB,
                               VXL_PHANTOM_SPARSE_BALLS, VXL_PHANTOM_DENSE_BALLS};
    for (int k = 0; k < 5; k++) {
        vxl_phantom_desc pd = {.struct_size = sizeof pd, .kind = kinds[k], .dims = {48, 48, 48}, .seed = 3};
        vxl_volume *v = NULL;
        REQUIRE(vxl_phantom_create(&pd, &v) == VXL_OK);
        REQUIRE(vxl_renderer_set_volume(R, v) == VXL_OK);
        vxl_volume_destroy(v);
        /* every filter in post-classification, every other mode with one
         * filter, and every filter with Levoy's iso-surface opacity, whose
         * occupancy follows the iso value instead of the table */
        const uint32_t n_plain = VXL_FILTER_COUNT + VXL_CLASSIFY_COUNT - 1;
        for (uint32_t run = 0; run < n_plain + VXL_FILTER_COUNT; run++) {
            int iso = run >= n_plain;
            uint32_t f = iso ? run - n_plain : run < VXL_FILTER_COUNT ? run : VXL_FILTER_CENTRAL;
            uint32_t mode = iso || run < VXL_FILTER_COUNT ? VXL_CLASSIFY_POST : run - VXL_FILTER_COUNT + 1;
            vxl_render_params p = phantom_scene(W, H, f, mode);
            if (iso) {
                p.gradient_opacity = VXL_GOPACITY_ISO;
                p.iso_value = 0.6f;
                p.iso_thickness = 1.5f;
            }
            static float dflt[W * H * 4];
            REQUIRE(vxl_render(R, &p, dflt, NULL) == VXL_OK); /* default threshold 0.99 */
            p.early_termination = 0.999f;
            REQUIRE(vxl_render(R, &p, on, NULL) == VXL_OK);
            vxl_render_stats s_on = {.struct_size = sizeof s_on}, s_off = s_on;
            vxl_renderer_get_stats(R, &s_on);
            p.no_skip = 1;
            REQUIRE(vxl_render(R, &p, off, NULL) == VXL_OK);
            vxl_renderer_get_stats(R, &s_off);
            double q = image_psnr(on, off, W * H * 4), worst = 0;
            for (int i = 0; i < W * H * 4; i++) worst = fmax(worst, fabs(dflt[i] - off[i]));
            CHECKF(worst <= 0.01 + 1e-5, "%s/%s: default termination off by %.4f", vxl_phantom_name(kinds[k]),
                   vxl_filter_name(f), worst);
            fprintf(stderr, "    %-15s %-11s mode %u%s PSNR %6.1f dB, samples %8llu vs %8llu (%.0f%%)\n",
                    vxl_phantom_name(kinds[k]), vxl_filter_name(f), mode, iso ? " iso" : "", q, (unsigned long long)s_on.samples, (unsigned long long)s_off.samples,
                    100.0 * s_on.samples / (s_off.samples ? s_off.samples : 1));
            CHECKF(q >= 60, "%s/%s/mode %u%s: %.1f dB", vxl_phantom_name(kinds[k]), vxl_filter_name(f), mode,
                   iso ? " iso" : "", q);
            /* cubic and precomputed have no gradient bound from adjacent
             * differences: in iso mode only the termination saves */
            if (iso && (f == VXL_FILTER_CUBIC || f == VXL_FILTER_PRECOMPUTED)) CHECK(s_on.samples <= s_off.samples);
            else CHECK(s_on.samples < s_off.samples);
            /* the iso occupancy must leap bricks where a gradient bound exists
             * (the sparse phantom: most bricks hold no part of the surface) */
            if (iso && kinds[k] == VXL_PHANTOM_SPARSE_BALLS && f != VXL_FILTER_CUBIC && f != VXL_FILTER_PRECOMPUTED)
                CHECKF(s_on.samples * 2 < s_off.samples, "%s iso: skipping kept %llu of %llu samples",
                       vxl_filter_name(f), (unsigned long long)s_on.samples, (unsigned long long)s_off.samples);
        }
    }
}

int main(void)
{
    R = make_renderer(software_backend());
    if (!R) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    RUN(skipping_never_changes_the_image);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
