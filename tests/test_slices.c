/* test_slices.c - the slicing comparison modes (csrc/render/slices.c):
 * both render what the ray caster renders, up to their sampling; an unknown
 * technique is refused; the 2D stacks pop where the stack switches (45
 * degrees) and the view-aligned slices do not; finer view-aligned slices
 * converge towards the double-precision reference.
 *
 * Why the bounds hold: every mode samples the same trilinear field with the
 * same classification, gradient and shading, and corrects opacity for its
 * own path per sample, so the images differ only by where the samples lie
 * (planes instead of ray steps). At step 1 that is a sampling difference of
 * the order of the ray caster's own step error (test_accuracy), which the
 * bounds below leave room for; a wrong opacity correction, ordering, normal
 * or shading costs far more (no correction for the path: 15-25 dB lost, coverage
 * down 6-7%). */
#include <stdio.h>
#include <string.h>

#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h" /* phantoms and the reference */

static vxl_renderer *R;

#define W 64
#define H 64
#define NPIX (W * H)

static vxl_volume *load_phantom(uint32_t kind, uint32_t side, vxl_phantom_desc *pd)
{
    *pd = (vxl_phantom_desc){.struct_size = sizeof *pd, .kind = kind, .dims = {side, side, side}, .seed = 3};
    vxl_volume *v = NULL;
    if (vxl_phantom_create(pd, &v) != VXL_OK) return NULL;
    if (vxl_renderer_set_volume(R, v) != VXL_OK) {
        vxl_volume_destroy(v);
        return NULL;
    }
    return v;
}

/* mean |a - b| over the pixels where both depths are finite; *n_out: how many */
static double depth_error(const float *a, const float *b, int *n_out)
{
    double s = 0;
    int n = 0;
    for (int i = 0; i < NPIX; i++)
        if (isfinite(a[i]) && isfinite(b[i])) s += fabs(a[i] - b[i]), n++;
    *n_out = n;
    return n ? s / n : 0;
}

TEST(each_technique_renders_close_to_the_ray_caster)
{
    static float ray[NPIX * 4], img[NPIX * 4], skipped[NPIX * 4], ray_d[NPIX], img_d[NPIX];
    const uint32_t kinds[2] = {VXL_PHANTOM_SPHERE, VXL_PHANTOM_MARSCHNER_LOBB};
    for (int k = 0; k < 2; k++) {
        vxl_phantom_desc pd;
        vxl_volume *v = load_phantom(kinds[k], 48, &pd);
        REQUIRE(v);
        for (int shaded = 0; shaded < 2; shaded++) {
            vxl_render_params p = phantom_scene(W, H, VXL_FILTER_SOBEL8, VXL_CLASSIFY_POST);
            p.jitter_off = 1; /* slices have no jitter */
            p.shading_off = !shaded;
            static float ref[NPIX * 4];
            REQUIRE(vxl_reference_render(&pd, v, &p, ref, NULL) == VXL_OK);
            for (int si = 0; si < 2; si++) { /* step 2: a missing opacity correction would show */
                p.step = si ? 2.0f : 1.0f;
                REQUIRE(vxl_render(R, &p, ray, ray_d) == VXL_OK);
                double q_ray = image_psnr(ray, ref, NPIX * 4);
                CHECK(alpha_sum(ray, NPIX) > NPIX * 0.1); /* the phantom fills a good part of the frame */
                for (uint32_t t = VXL_TECHNIQUE_SLICES2D; t <= VXL_TECHNIQUE_SLICES3D; t++) {
                    p.technique = t;
                    REQUIRE(vxl_render(R, &p, img, img_d) == VXL_OK);
                    p.technique = VXL_TECHNIQUE_RAYCAST;
                    CHECK(image_is_sane(img, img_d, NPIX));
                    double q_ref = image_psnr(img, ref, NPIX * 4);
                    double q = image_psnr(img, ray, NPIX * 4), cover = alpha_sum(img, NPIX) / alpha_sum(ray, NPIX);
                    int nd;
                    double dz = depth_error(img_d, ray_d, &nd);
                    fprintf(stderr,
                            "    %-14s %-8s %-8s step %.0f: vs reference %.1f dB (ray caster %.1f); vs ray caster %.1f dB, "
                            "coverage %.3f, depth %.3f (%d px)\n",
                            vxl_phantom_name(kinds[k]), vxl_technique_name(t), shaded ? "shaded" : "unshaded", p.step, q_ref,
                            q_ray, q, cover, dz, nd);
                    CHECKF(q_ref >= q_ray - 3, "%s %s step %.0f: %.1f dB from the reference, the ray caster %.1f",
                           vxl_phantom_name(kinds[k]), vxl_technique_name(t), p.step, q_ref, q_ray);
                    CHECKF(fabs(cover - 1) < 0.04, "%s: coverage %.3f of the ray caster's", vxl_technique_name(t), cover);
                    /* the depth where opacity passes the threshold, within a step
                     * of the ray caster's (a plane is at most ~sqrt(3) from a step) */
                    CHECKF(nd > NPIX / 10 && dz < p.step, "%s: depth off by %.3f over %d px", vxl_technique_name(t), dz, nd);
                /* skipping empty bricks changes nothing (the no-skip run also
                 * ends rays late: 1e-3 of 1 - 0.999 per channel at most) */
                p.technique = t;
                p.early_termination = 0.999f;
                REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
                p.no_skip = 1;
                REQUIRE(vxl_render(R, &p, skipped, NULL) == VXL_OK);
                p.no_skip = 0;
                p.early_termination = 0;
                p.technique = VXL_TECHNIQUE_RAYCAST;
                CHECKF(image_psnr(img, skipped, NPIX * 4) >= 60, "%s: skipping changed the image (%.1f dB)",
                       vxl_technique_name(t), image_psnr(img, skipped, NPIX * 4));
                }
            }
        }
        vxl_volume_destroy(v);
    }
}

/* An orthographic camera (the eye at infinity: one viewing direction) and a
 * host scene's depth (samples behind it dropped) work as in the ray caster. */
TEST(orthographic_camera_and_scene_depth)
{
    static float ray[NPIX * 4], img[NPIX * 4], ray_d[NPIX], img_d[NPIX], scene[NPIX];
    vxl_phantom_desc pd;
    vxl_volume *v = load_phantom(VXL_PHANTOM_SPHERE, 48, &pd);
    REQUIRE(v);
    vxl_render_params p = phantom_scene(W, H, VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
    p.jitter_off = 1;
    REQUIRE(vxl_default_camera(R, &p, p.view, p.proj) == VXL_OK);
    /* the default view with an orthographic projection of the same frame:
     * the perspective's half height at the volume's distance, its clip range */
    double half = -p.view[14] / p.proj[5], near = p.proj[14] / (p.proj[10] - 1), far = p.proj[14] / (p.proj[10] + 1);
    memset(p.proj, 0, sizeof p.proj);
    p.proj[0] = p.proj[5] = (float)(1 / half);
    p.proj[10] = (float)(-2 / (far - near));
    p.proj[14] = (float)(-(far + near) / (far - near));
    p.proj[15] = 1;
    p.has_camera = 1;
    double open_alpha = 0;
    for (int with_scene = 0; with_scene < 2; with_scene++) {
        p.technique = VXL_TECHNIQUE_RAYCAST;
        p.scene_depth = NULL;
        REQUIRE(vxl_render(R, &p, ray, ray_d) == VXL_OK);
        if (with_scene) {
            /* a wall through the middle of the ball: half its depth range */
            double lo = INFINITY, hi = 0;
            for (int i = 0; i < NPIX; i++)
                if (isfinite(ray_d[i])) lo = fmin(lo, ray_d[i]), hi = fmax(hi, ray_d[i]);
            for (int i = 0; i < NPIX; i++) scene[i] = (float)(lo + 0.5 * (hi - lo));
            p.scene_depth = scene;
            REQUIRE(vxl_render(R, &p, ray, ray_d) == VXL_OK);
            /* the wall hides a good part of the ball, so a mode ignoring it would show */
            CHECKF(alpha_sum(ray, NPIX) < 0.9 * open_alpha, "the wall hides too little: %.1f of %.1f",
                   alpha_sum(ray, NPIX), open_alpha);
        } else {
            open_alpha = alpha_sum(ray, NPIX);
        }
        for (uint32_t t = VXL_TECHNIQUE_SLICES2D; t <= VXL_TECHNIQUE_SLICES3D; t++) {
            p.technique = t;
            REQUIRE(vxl_render(R, &p, img, img_d) == VXL_OK);
            double q = image_psnr(img, ray, NPIX * 4), cover = alpha_sum(img, NPIX) / alpha_sum(ray, NPIX);
            fprintf(stderr, "    orthographic%s, %s: %.1f dB vs the ray caster, coverage %.3f\n",
                    with_scene ? " + scene depth" : "", vxl_technique_name(t), q, cover);
            CHECK(alpha_sum(ray, NPIX) > NPIX * 0.05);
            CHECKF(q >= 40 && fabs(cover - 1) < 0.04, "%s%s: %.1f dB, coverage %.3f", vxl_technique_name(t),
                   with_scene ? " with scene depth" : "", q, cover);
        }
    }
    vxl_volume_destroy(v);
}

TEST(unknown_techniques_and_unsupported_modes_are_refused)
{
    static float img[NPIX * 4];
    vxl_phantom_desc pd;
    vxl_volume *v = load_phantom(VXL_PHANTOM_SPHERE, 32, &pd);
    REQUIRE(v);
    vxl_render_params p = phantom_scene(W, H, VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
    p.technique = VXL_TECHNIQUE_COUNT;
    CHECK(vxl_render(R, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(vxl_last_error(), "technique") != NULL, "message: %s", vxl_last_error());
    p.technique = 0xFFFFFFFFu;
    CHECK(vxl_render(R, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    p.technique = VXL_TECHNIQUE_SLICES3D;
    p.classify = VXL_CLASSIFY_PREINT;
    CHECK(vxl_render(R, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(vxl_last_error(), "slices3d") && strstr(vxl_last_error(), "preint"), "message: %s",
           vxl_last_error());
    p.classify = VXL_CLASSIFY_POST;
    p.shading_model = VXL_SHADING_SHADOWED;
    CHECK(vxl_render(R, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(vxl_last_error(), "slices3d") && strstr(vxl_last_error(), "shadowed"), "message: %s",
           vxl_last_error());
    p.shading_model = VXL_SHADING_PHONG;
    /* the renderer still works afterwards */
    p.classify = VXL_CLASSIFY_PRE;
    CHECK(vxl_render(R, &p, img, NULL) == VXL_OK);
    CHECK(alpha_sum(img, NPIX) > NPIX * 0.05);
    CHECK(vxl_technique_name(VXL_TECHNIQUE_SLICES2D) && !strcmp(vxl_technique_name(VXL_TECHNIQUE_SLICES2D), "slices2d"));
    CHECK(vxl_technique_name(VXL_TECHNIQUE_COUNT) == NULL);
    vxl_volume_destroy(v);
}

/* The lecture's popping: a 2D stack switches axis where two components of
 * the viewing direction are equal, and the samples jump from one set of
 * planes to the other. Across the switch (44.5 -> 45.5 degrees azimuth on a
 * cube) the image changes much more than over one degree that does not
 * switch (43.5 -> 44.5); view-aligned slices change smoothly. */
TEST(object_aligned_stacks_pop_at_45_degrees)
{
    static float a[NPIX * 4], b[NPIX * 4], c[NPIX * 4];
    vxl_phantom_desc pd;
    vxl_volume *v = load_phantom(VXL_PHANTOM_MARSCHNER_LOBB, 48, &pd);
    REQUIRE(v);
    for (uint32_t t = VXL_TECHNIQUE_SLICES2D; t <= VXL_TECHNIQUE_SLICES3D; t++) {
        vxl_render_params p = phantom_scene(W, H, VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
        p.technique = t;
        p.elevation_deg = 10;
        p.step = 1;
        p.azimuth_deg = 44.7f;
        REQUIRE(vxl_render(R, &p, a, NULL) == VXL_OK);
        p.azimuth_deg = 44.9f;
        REQUIRE(vxl_render(R, &p, b, NULL) == VXL_OK);
        p.azimuth_deg = 45.1f;
        REQUIRE(vxl_render(R, &p, c, NULL) == VXL_OK);
        double smooth = image_rmse(a, b, NPIX * 4), across = image_rmse(b, c, NPIX * 4);
        fprintf(stderr, "    %s: image change over 0.2 degrees %.4f, across 45 degrees %.4f (x%.2f)\n",
                vxl_technique_name(t), smooth, across, across / smooth);
        if (t == VXL_TECHNIQUE_SLICES2D)
            CHECKF(across > 1.8 * smooth, "slices2d: no popping at 45 degrees (%.4f vs %.4f)", across, smooth);
        else
            CHECKF(across < 1.3 * smooth, "slices3d: popping at 45 degrees (%.4f vs %.4f)", across, smooth);
    }
    vxl_volume_destroy(v);
}

/* View-aligned slices are a sampling of the same integral: finer spacing
 * converges towards the reference as the ray caster's finer steps do. */
TEST(finer_view_aligned_slices_converge_to_the_reference)
{
    enum { RW = 40, RH = 40 };
    static float ref[RW * RH * 4], img[RW * RH * 4], ray[RW * RH * 4];
    vxl_phantom_desc pd;
    vxl_volume *v = load_phantom(VXL_PHANTOM_SPHERE, 48, &pd);
    REQUIRE(v);
    vxl_render_params p = phantom_scene(RW, RH, VXL_FILTER_CUBIC, VXL_CLASSIFY_POST);
    p.jitter_off = 1;
    REQUIRE(vxl_reference_render(&pd, v, &p, ref, NULL) == VXL_OK);
    const float steps[4] = {2.0f, 1.0f, 0.5f, 0.25f};
    double first = 0, last = 0;
    for (int i = 0; i < 4; i++) {
        p.step = steps[i];
        p.technique = VXL_TECHNIQUE_RAYCAST;
        REQUIRE(vxl_render(R, &p, ray, NULL) == VXL_OK);
        p.technique = VXL_TECHNIQUE_SLICES3D;
        REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
        double q = image_psnr(img, ref, RW * RH * 4), qr = image_psnr(ray, ref, RW * RH * 4);
        fprintf(stderr, "    sphere, cubic, spacing %.2f: slices3d %.2f dB, raycast %.2f dB against the reference\n",
                steps[i], q, qr);
        CHECKF(i == 0 || q > last - 0.5, "spacing %.2f got worse (%.2f after %.2f dB)", steps[i], q, last);
        if (i == 0) first = q;
        last = q;
    }
    vxl_volume_destroy(v);
    CHECKF(last > first + 3 && last > 35, "no convergence: %.2f dB at spacing 2, %.2f at 0.25 (want > 35)", first,
           last);
}

int main(void)
{
    if (!(R = make_renderer(software_backend()))) return printf("0 passed, 1 failed (no renderer)\n"), 1;
    RUN(each_technique_renders_close_to_the_ray_caster);
    RUN(orthographic_camera_and_scene_depth);
    RUN(unknown_techniques_and_unsupported_modes_are_refused);
    RUN(object_aligned_stacks_pop_at_45_degrees);
    RUN(finer_view_aligned_slices_converge_to_the_reference);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
