/* test_classification.c - pre-, post- and pre-integrated classification:
 * the pre-integration table against brute-force integration, every mode
 * against the reference renderer, independence of the step (opacity
 * correction), and where the modes must differ. */
#include <stdio.h>

#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h" /* the test hooks */

static vxl_renderer *R;

#define W 48
#define H 48
#define NTF 256

/* A thin opacity spike: the high-frequency transfer function where
 * post-classification needs small steps and pre-integration should not. */
static void spike_tf(float *tf, double centre, double width)
{
    for (int i = 0; i < NTF; i++) {
        double x = i / (NTF - 1.0), a = exp(-0.5 * pow((x - centre) / width, 2));
        tf[4 * i + 0] = (float)(0.4 + 0.6 * x);
        tf[4 * i + 1] = (float)(0.9 - 0.5 * x);
        tf[4 * i + 2] = 0.5f;
        tf[4 * i + 3] = (float)(0.8 * a);
    }
}

static void smooth_tf(float *tf)
{
    for (int i = 0; i < NTF; i++) {
        double x = i / (NTF - 1.0);
        tf[4 * i + 0] = (float)x;
        tf[4 * i + 1] = (float)(0.5 + 0.5 * x);
        tf[4 * i + 2] = (float)(1 - x);
        tf[4 * i + 3] = (float)(0.08 * x * x);
    }
}

/* GL_LINEAR lookup of the tf at x in [0,1] */
static void tf_at(const float *tf, double x, double out[4])
{
    double u = x * (NTF - 1);
    int i0 = (int)floor(u);
    if (i0 > NTF - 1) i0 = NTF - 1;
    int i1 = i0 + 1 < NTF ? i0 + 1 : i0;
    double w = u - i0;
    for (int k = 0; k < 4; k++) out[k] = tf[4 * i0 + k] * (1 - w) + tf[4 * i1 + k] * w;
}

TEST(preint_table_matches_brute_force_integration)
{
    enum { N = 128 };
    static float tf[NTF * 4], table[N * N * 4];
    spike_tf(tf, 0.5, 0.03);
    const float steps[3] = {0.25f, 1.0f, 2.0f};
    for (int s = 0; s < 3; s++) {
        REQUIRE(vxl_preint_table(tf, NTF, 1, steps[s], N, table) == VXL_OK);
        double worst_a = 0, sum_c = 0;
        int count = 0;
        for (int b = 0; b < N; b += 7)
            for (int f = 0; f < N; f += 5) {
                /* the segment's emission-absorption integral by 20000 sub-steps */
                const int M = 20000;
                double A = 0, C[3] = {0, 0, 0}, dt = steps[s] / M;
                for (int m = 0; m < M; m++) {
                    double x = (f + (b - f) * (m + 0.5) / M) / (N - 1.0), k[4];
                    tf_at(tf, x, k);
                    double a = 1 - pow(1 - fmin(k[3], 1 - 1e-7), dt);
                    for (int c = 0; c < 3; c++) C[c] += (1 - A) * a * k[c];
                    A += (1 - A) * a;
                }
                const float *e = table + ((size_t)b * N + f) * 4;
                worst_a = fmax(worst_a, fabs(e[3] - A));
                for (int c = 0; c < 3; c++) sum_c += fabs(e[c] - C[c]);
                count += 3;
                for (int c = 0; c < 3; c++) CHECK(e[c] <= e[3] + 1e-6f); /* premultiplied */
            }
        /* the opacity is exact for a linear segment; the colour ignores
         * self-attenuation inside the segment (weighted mean colour) */
        fprintf(stderr, "    step %.2f: max |alpha error| %.2e, mean |colour error| %.2e\n", steps[s], worst_a,
                sum_c / count);
        CHECKF(worst_a < 1e-4, "step %.2f alpha error %.2e", steps[s], worst_a);
        CHECKF(sum_c / count < 1e-3, "step %.2f colour error %.2e", steps[s], sum_c / count);
    }
    /* the front = back diagonal is the exact point segment */
    REQUIRE(vxl_preint_table(tf, NTF, 1, 1.0f, N, table) == VXL_OK);
    for (int i = 0; i < N; i++) {
        double k[4];
        tf_at(tf, i / (N - 1.0), k);
        double a = 1 - pow(1 - fmin(k[3], 1 - 1e-7), 1.0);
        CHECKF(fabs(table[((size_t)i * N + i) * 4 + 3] - a) < 1e-5, "diagonal %d", i);
    }
    CHECK(vxl_preint_table(tf, NTF, 1, 0, N, table) == VXL_ERR_INVALID_ARGUMENT);
}

static vxl_phantom_desc sphere = {sizeof(vxl_phantom_desc), VXL_PHANTOM_SPHERE, {40, 40, 40}, 0, 0};

static vxl_render_params scene(const float *tf, uint32_t mode, float step)
{
    vxl_render_params p = default_params(W, H);
    p.tf_rgba = tf;
    p.tf_size = NTF;
    p.has_window = 1;
    p.window_low = 0.0f;
    p.window_high = 1.0f;
    p.azimuth_deg = 30;
    p.elevation_deg = 20;
    p.classify = mode;
    p.step = step;
    p.jitter_off = 1;
    return p;
}

static double psnr(const float *a, const float *b) { return image_psnr(a, b, W * H * 4); }

TEST(every_mode_matches_the_reference)
{
    static float tf[NTF * 4], ref[W * H * 4], img[W * H * 4];
    smooth_tf(tf);
    vxl_volume *v = NULL;
    REQUIRE(vxl_phantom_create(&sphere, &v) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(R, v) == VXL_OK);
    const char *names[3] = {"post", "pre", "preint"};
    for (uint32_t m = 0; m < VXL_CLASSIFY_COUNT; m++) {
        vxl_render_params p = scene(tf, m, 0.25f);
        p.filter = VXL_FILTER_CUBIC;
        REQUIRE(vxl_reference_render(&sphere, v, &p, ref, NULL) == VXL_OK);
        REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
        double q = psnr(img, ref);
        fprintf(stderr, "    %-6s PSNR %.1f dB against the reference\n", names[m], q);
        CHECKF(q > 40, "%s: %.1f dB", names[m], q);
        CHECK(alpha_sum(ref, W * H) > 50);
    }
    vxl_volume_destroy(v);
}

TEST(opacity_correction_makes_the_step_irrelevant)
{
    static float tf[NTF * 4], a[W * H * 4], b[W * H * 4];
    smooth_tf(tf);
    vxl_volume *v = NULL;
    REQUIRE(vxl_phantom_create(&sphere, &v) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(R, v) == VXL_OK);
    vxl_volume_destroy(v);
    for (uint32_t m = 0; m < VXL_CLASSIFY_COUNT; m++) {
        vxl_render_params p = scene(tf, m, 0.25f);
        REQUIRE(vxl_render(R, &p, a, NULL) == VXL_OK);
        p.step = 1.0f;
        REQUIRE(vxl_render(R, &p, b, NULL) == VXL_OK);
        double q = psnr(a, b);
        fprintf(stderr, "    mode %u: step 0.25 vs 1.0: %.1f dB\n", m, q);
        CHECKF(q > 38, "mode %u: %.1f dB", m, q);
        /* and without the correction it would not be: opacity per step doubles */
        p.opacity_scale = 4.0f;
        REQUIRE(vxl_render(R, &p, b, NULL) == VXL_OK);
        CHECK(psnr(a, b) < q - 6);
    }
}

/* A thin spike: pre-integration at a coarse step beats post-classification
 * at the same step, and pre-classification differs visibly from post. */
TEST(preintegration_pays_off_on_a_spike)
{
    static float tf[NTF * 4], ref[W * H * 4], img[W * H * 4], post[W * H * 4];
    spike_tf(tf, 0.5, 0.02);
    vxl_volume *v = NULL;
    REQUIRE(vxl_phantom_create(&sphere, &v) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(R, v) == VXL_OK);
    vxl_render_params p = scene(tf, VXL_CLASSIFY_POST, 1.0f);
    /* a narrow window makes the spike thinner than a voxel along the rays */
    p.window_low = 0.42f;
    p.window_high = 0.62f;
    p.shading_off = 1;
    REQUIRE(vxl_reference_render(&sphere, v, &p, ref, NULL) == VXL_OK);
    REQUIRE(vxl_render(R, &p, post, NULL) == VXL_OK);
    p.classify = VXL_CLASSIFY_PREINT;
    REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
    double q_post = psnr(post, ref), q_pre = psnr(img, ref);
    fprintf(stderr, "    spike at step 1: post %.1f dB, preint %.1f dB\n", q_post, q_pre);
    CHECKF(q_pre > q_post + 6, "preint %.1f vs post %.1f", q_pre, q_post);
    p.classify = VXL_CLASSIFY_PRE;
    REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
    CHECKF(psnr(img, post) < 30, "pre-classification looks like post (%.1f dB)", psnr(img, post));
    vxl_volume_destroy(v);
}

/* Levoy's opacity functions against the reference, and doing what they say. */
TEST(gradient_magnitude_opacity)
{
    static float tf[NTF * 4], ref[W * H * 4], img[W * H * 4], off[W * H * 4];
    smooth_tf(tf);
    for (int i = 0; i < NTF; i++) tf[4 * i + 3] = 0.3f; /* opacity everywhere: only |grad| shapes it */
    vxl_phantom_desc blob = {sizeof blob, VXL_PHANTOM_NOISY_BLOB, {40, 40, 40}, 1, 1e-9};
    vxl_volume *v = NULL;
    REQUIRE(vxl_phantom_create(&blob, &v) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(R, v) == VXL_OK);
    vxl_render_params p = scene(tf, VXL_CLASSIFY_POST, 0.25f);
    p.filter = VXL_FILTER_CUBIC;
    REQUIRE(vxl_render(R, &p, off, NULL) == VXL_OK);
    const char *names[3] = {"", "boundary", "iso"};
    for (uint32_t m = VXL_GOPACITY_BOUNDARY; m < VXL_GOPACITY_COUNT; m++) {
        p.gradient_opacity = m;
        p.gradient_ref = 0.05f;
        p.iso_value = 0.5f;
        p.iso_thickness = 1.5f;
        REQUIRE(vxl_reference_render(&blob, v, &p, ref, NULL) == VXL_OK);
        REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
        double q = psnr(img, ref);
        fprintf(stderr, "    %s: PSNR %.1f dB against the reference, %.1f dB from plain\n", names[m], q, psnr(img, off));
        CHECKF(q > 35, "%s: %.1f dB", names[m], q);
        CHECKF(psnr(img, off) < 30, "%s changes nothing", names[m]);
        CHECK(alpha_sum(img, W * H) > 20);
    }
    /* a thicker iso-surface is more opaque */
    p.gradient_opacity = VXL_GOPACITY_ISO;
    p.iso_thickness = 0.5f;
    REQUIRE(vxl_render(R, &p, off, NULL) == VXL_OK);
    p.iso_thickness = 3.0f;
    REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
    CHECK(alpha_sum(img, W * H) > alpha_sum(off, W * H) * 1.1);
    vxl_volume_destroy(v);
}

/* Gradient-magnitude opacity reads |grad| in value per voxel whatever the
 * filter: the precomputed filter stores g / max|g| and must scale it back
 * (it once did not, and its iso-surfaces came out 7x too opaque). */
TEST(gradient_opacity_units_agree_across_filters)
{
    static float tf[NTF * 4], img[W * H * 4];
    smooth_tf(tf);
    for (int i = 0; i < NTF; i++) tf[4 * i + 3] = 0.3f;
    vxl_phantom_desc sph = {sizeof sph, VXL_PHANTOM_SPHERE, {48, 48, 48}, 0, 0};
    vxl_volume *v = NULL;
    REQUIRE(vxl_phantom_create(&sph, &v) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(R, v) == VXL_OK);
    for (uint32_t m = VXL_GOPACITY_BOUNDARY; m < VXL_GOPACITY_COUNT; m++) {
        double base = 0;
        for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++) {
            vxl_render_params p = scene(tf, VXL_CLASSIFY_POST, 0.5f);
            p.filter = f;
            p.sample_distance = 1;
            p.gradient_opacity = m;
            p.gradient_ref = 0.05f;
            p.iso_value = 0.5f;
            p.iso_thickness = 1.5f;
            REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
            double a = alpha_sum(img, W * H);
            if (f == 0) base = a;
            CHECKF(a > 0.85 * base && a < 1.15 * base, "mode %u %s: alpha %.1f against central's %.1f", m,
                   vxl_filter_name(f), a, base);
        }
    }
    vxl_volume_destroy(v);
}

int main(void)
{
    R = make_renderer(software_backend());
    if (!R) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    RUN(preint_table_matches_brute_force_integration);
    RUN(every_mode_matches_the_reference);
    RUN(opacity_correction_makes_the_step_irrelevant);
    RUN(preintegration_pays_off_on_a_spike);
    RUN(gradient_magnitude_opacity);
    RUN(gradient_opacity_units_agree_across_filters);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
