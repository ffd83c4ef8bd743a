/* test_path.c - the PATH shading model (voxlight.h's VXL_SHADING_PATH;
 * csrc/render/path.c, shaders/render/path.frag): one bounce is scatter's
 * sum within the noise, more bounces only add light, the same seed gives
 * the same image bit for bit and another seed another one, k calls of one
 * sample merged with vxl_path_accumulate are one call of k samples, a clip
 * plane cuts the medium away, the World alone lights it, bricked storage
 * (the whole table's majorant) traces the same medium, a colour volume's
 * colour is its albedo, and what PATH does not draw is refused by name.
 *
 * The scene: the two-blobs phantom at 24^3 voxels, 48 x 24 pixels, the
 * default camera (the +x blob on the left half, the -x blob on the right). */
#include <stdio.h>

#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h"

#define W 48
#define H 24
#define N 24
#define PX (W * H)

static vxl_renderer *R;
static float A[PX * 4], B[PX * 4], S[PX * 4], ACC[PX * 4];
static float DA[PX], DB[PX], DACC[PX];

static vxl_volume *blobs_volume(void)
{
    vxl_phantom_desc d = {.struct_size = sizeof d, .kind = VXL_PHANTOM_TWO_BLOBS, .dims = {N, N, N}};
    vxl_volume *v = NULL;
    return vxl_phantom_create(&d, &v) == VXL_OK ? v : NULL;
}

/* Blobs of albedo `albedo` (grey), opacity ramping to `opacity` per voxel
 * over their edge, one sun from +x+y+z, no ambient light, no specular, no
 * surface term (gradient_ref far above any gradient: w = 0, the medium). */
static vxl_render_params scene(uint32_t model, float albedo, float opacity)
{
    static float tf[8];
    const float t[8] = {albedo, albedo, albedo, 0, albedo, albedo, albedo, 0};
    memcpy(tf, t, sizeof tf);
    tf[7] = opacity;
    vxl_render_params p = {.struct_size = sizeof p, .width = W, .height = H, .tf_rgba = tf, .tf_size = 2,
                           .has_window = 1, .window_low = 0.05f, .window_high = 0.35f, .shading_model = model,
                           .jitter_off = 1, .has_material = 1, .ambient = 0, .diffuse = 0.7f, .specular = 0,
                           .shininess = 1, .gradient_ref = 1000, .light_count = 1, .path_seed = 1};
    p.lights[0].position[0] = 0.6f;
    p.lights[0].position[1] = 0.6f;
    p.lights[0].position[2] = 0.5f;
    return p;
}

static int render(const vxl_render_params *p, float *img, float *depth)
{
    int rc = vxl_render(R, p, img, depth);
    if (rc) fprintf(stderr, "    render failed: %s\n", vxl_renderer_error(R));
    return rc;
}

static double mean_rgb(const float *img)
{
    double s = 0;
    for (int i = 0; i < PX; i++) s += img[4 * i] + img[4 * i + 1] + img[4 * i + 2];
    return s / (3.0 * PX);
}

/* Root mean square of a - b over the colour channels. */
static double rms_rgb(const float *a, const float *b)
{
    double s = 0;
    for (int i = 0; i < PX; i++)
        for (int c = 0; c < 3; c++) s += (a[4 * i + c] - b[4 * i + c]) * (double)(a[4 * i + c] - b[4 * i + c]);
    return sqrt(s / (3.0 * PX));
}

/* One collision: its light is not sampled but integrated along the eye ray
 * by the march that gives alpha, the sum over steps of T * a * (scatter's
 * lighting) that scatter composites too. So a path of one bounce is
 * scatter's image (nothing here is bright enough for scatter's per-sample
 * clamp to act), the same for every seed: no noise is left in the single
 * scattering, only in the bounces after it. */
TEST(one_bounce_is_scatters_sum)
{
    vxl_render_params p = scene(VXL_SHADING_SCATTER, 0.8f, 0.35f);
    p.step = 0.25f;
    p.early_termination = 1;
    REQUIRE(render(&p, S, NULL) == VXL_OK);
    p.shading_model = VXL_SHADING_PATH;
    p.path_bounces = 1;
    p.path_samples = 4;
    REQUIRE(render(&p, A, NULL) == VXL_OK);
    p.path_seed = 2;
    REQUIRE(render(&p, B, NULL) == VXL_OK);
    const double e = rms_rgb(A, S), ms = mean_rgb(S);
    double dmax = 0;
    for (int i = 0; i < PX * 4; i++) dmax = fmax(dmax, fabs(A[i] - S[i]));
    fprintf(stderr, "    scatter mean %.5f, path %.5f; rmse %.2e, largest difference %.2e\n", ms, mean_rgb(A), e,
            dmax);
    CHECK(ms > 0.01); /* the scene is lit */
    CHECK(memcmp(A, B, sizeof A) == 0); /* no random number decides a single scattering */
    CHECKF(dmax < 1e-5, "largest difference %.2e", dmax);
}

/* A thick, nearly white medium: every further collision adds light that the
 * shorter paths do not have. With one seed, a path of more bounces is the
 * shorter one's path (the same random numbers for the same collisions) plus
 * more non-negative terms, so no pixel ever darkens; the image brightens
 * clearly from 1 to 2 to 4 bounces. */
TEST(more_bounces_brighten_a_thick_white_volume_and_never_darken_it)
{
    vxl_render_params p = scene(VXL_SHADING_PATH, 0.95f, 0.9f);
    p.path_samples = 8;
    const uint32_t bounces[4] = {1, 2, 4, 8};
    double prev_mean = 0;
    for (int k = 0; k < 4; k++) {
        p.path_bounces = bounces[k];
        REQUIRE(render(&p, k % 2 ? B : A, NULL) == VXL_OK);
        const float *now = k % 2 ? B : A, *before = k % 2 ? A : B;
        double m = mean_rgb(now);
        fprintf(stderr, "    %u bounces: mean %.5f\n", bounces[k], m);
        if (k > 0) {
            int darker = 0;
            for (int i = 0; i < PX * 4; i++) darker += now[i] < before[i];
            CHECKF(darker == 0, "%d values darker at %u bounces than at %u", darker, bounces[k], bounces[k - 1]);
            if (k < 3) CHECKF(m > 1.1 * prev_mean, "%u bounces: %.5f, %u: %.5f", bounces[k], m, bounces[k - 1], prev_mean);
        }
        prev_mean = m;
    }
}

TEST(the_same_seed_gives_the_same_image_and_another_seed_another)
{
    vxl_render_params p = scene(VXL_SHADING_PATH, 0.8f, 0.5f);
    p.path_samples = 2;
    p.path_seed = 7;
    REQUIRE(render(&p, A, DA) == VXL_OK);
    REQUIRE(render(&p, B, DB) == VXL_OK);
    CHECK(memcmp(A, B, sizeof A) == 0);
    CHECK(memcmp(DA, DB, sizeof DA) == 0);
    p.path_seed = 8;
    REQUIRE(render(&p, B, NULL) == VXL_OK);
    int covered = 0, differ = 0;
    for (int i = 0; i < PX; i++) {
        if (A[4 * i + 3] < 0.2f) continue;
        covered++;
        differ += memcmp(A + 4 * i, B + 4 * i, 3 * sizeof(float)) != 0;
    }
    fprintf(stderr, "    %d of %d covered pixels differ with another seed\n", differ, covered);
    CHECK(covered >= 32);
    CHECKF(differ > covered / 2, "%d of %d", differ, covered);
}

/* The viewport's refinement: calls of one sample at offsets 0..k-1, merged
 * by vxl_path_accumulate, against one call of k samples. The samples are
 * the same numbers (a function of seed, pixel and index); only the order
 * of the float sums differs, a few ulps of the values. */
TEST(k_calls_of_one_sample_merge_into_one_call_of_k)
{
    enum { K = 6 };
    vxl_render_params p = scene(VXL_SHADING_PATH, 0.8f, 0.5f);
    p.path_bounces = 3;
    p.path_samples = K;
    REQUIRE(render(&p, A, DA) == VXL_OK);
    p.path_samples = 1;
    for (uint32_t k = 0; k < K; k++) {
        p.path_sample_offset = k;
        REQUIRE(render(&p, B, DB) == VXL_OK);
        REQUIRE(vxl_path_accumulate(ACC, B, PX * 4, k, 1) == VXL_OK);
        REQUIRE(vxl_path_accumulate(DACC, DB, PX, k, 1) == VXL_OK);
    }
    double worst = 0;
    for (int i = 0; i < PX * 4; i++) worst = fmax(worst, fabs(ACC[i] - A[i]) / (1e-3 + fabs(A[i])));
    fprintf(stderr, "    largest relative difference %.3g, mean %.5f\n", worst, mean_rgb(A));
    CHECK(mean_rgb(A) > 0.01);
    CHECKF(worst < 1e-5, "%.3g", worst);
    CHECK(memcmp(DA, DACC, sizeof DA) == 0); /* the depth, +inf included, stays as it is */
    /* a later call is no repeat of an earlier one */
    p.path_sample_offset = 0;
    REQUIRE(render(&p, A, NULL) == VXL_OK);
    p.path_sample_offset = 1;
    REQUIRE(render(&p, S, NULL) == VXL_OK);
    CHECK(memcmp(A, S, sizeof A) != 0);
}

/* A clip plane keeping world x >= 0 removes the -x blob (the image's
 * right half) from the primary rays and from every bounce: nothing is left
 * there, and the +x blob still gets its light. */
TEST(a_clip_plane_cuts_the_medium_away)
{
    vxl_render_params p = scene(VXL_SHADING_PATH, 0.8f, 0.5f);
    p.path_samples = 4;
    p.path_bounces = 3;
    vxl_cutaway cut = {.struct_size = sizeof cut, .clip_plane_count = 1};
    cut.clip_planes[0].plane[0] = 1;
    p.cutaway = &cut;
    REQUIRE(render(&p, A, NULL) == VXL_OK);
    double left = 0, right = 0;
    for (int i = 0; i < PX; i++)
        for (int c = 0; c < 4; c++) *(i % W < W / 2 ? &left : &right) += A[4 * i + c];
    fprintf(stderr, "    left half %.4f, right half %.4f\n", left, right);
    CHECK(left > 1);
    CHECK(right == 0);
}

/* An HDRI-only scene: no lamp, a uniform World; every collision gathers
 * the World's irradiance, so the blobs are lit, and more bounces add to it. */
TEST(the_world_alone_lights_the_volume)
{
    vxl_render_params p = scene(VXL_SHADING_PATH, 0.9f, 0.6f);
    static const float grey[3] = {0.6f, 0.6f, 0.6f};
    vxl_environment env = {.struct_size = sizeof env, .width = 1, .height = 1, .rgb = grey, .strength = 1};
    p.environment = &env;
    p.light_count = 0;
    p.path_samples = 4;
    p.path_bounces = 1;
    REQUIRE(render(&p, A, NULL) == VXL_OK);
    p.path_bounces = 4;
    REQUIRE(render(&p, B, NULL) == VXL_OK);
    double a = 0, lit1 = 0, lit4 = 0;
    for (int i = 0; i < PX; i++) {
        if (A[4 * i + 3] < 0.5f) continue;
        a += A[4 * i + 3];
        lit1 += A[4 * i];
        lit4 += B[4 * i];
    }
    fprintf(stderr, "    straight red over the opaque pixels: %.4f (1 bounce), %.4f (4)\n", lit1 / a, lit4 / a);
    CHECK(a > 10);
    CHECKF(lit1 / a > 0.1, "%.4f", lit1 / a);
    CHECKF(lit4 > lit1, "%.4f vs %.4f", lit4 / a, lit1 / a);
}

/* Bricked storage samples a pool the full-resolution min-max does not
 * bound, so its bricks take the whole table's majorant: more null
 * collisions, another noise, the same expectation. The images' means agree
 * within 4 standard errors (from the two renders' difference) plus 1%. */
TEST(bricked_storage_traces_the_same_medium)
{
    vxl_renderer_options o = {.struct_size = sizeof o, .backend = software_backend(), .storage = VXL_STORAGE_BRICKED,
                              .page_brick = 16};
    vxl_renderer *rb = NULL;
    vxl_volume *v = blobs_volume();
    REQUIRE(v && vxl_renderer_create(&o, &rb) == VXL_OK);
    int rc = vxl_renderer_set_volume(rb, v);
    vxl_volume_destroy(v);
    vxl_render_params p = scene(VXL_SHADING_PATH, 0.8f, 0.5f);
    p.path_samples = 32;
    p.path_bounces = 2;
    if (!rc) rc = vxl_render(rb, &p, B, NULL);
    if (rc) fprintf(stderr, "    bricked: %s\n", vxl_renderer_error(rb));
    vxl_renderer_destroy(rb);
    REQUIRE(rc == VXL_OK);
    REQUIRE(render(&p, A, NULL) == VXL_OK);
    const double ma = mean_rgb(A), mb = mean_rgb(B), se = rms_rgb(A, B) / sqrt(3.0 * PX);
    fprintf(stderr, "    dense %.5f, bricked %.5f, se of the difference %.5f\n", ma, mb, se);
    CHECK(ma > 0.005);
    CHECKF(fabs(ma - mb) <= 4 * se + 0.01 * ma, "%.5f vs %.5f", ma, mb);
    double da = 0;
    for (int i = 0; i < PX; i++) da = fmax(da, fabs(A[4 * i + 3] - B[4 * i + 3]));
    CHECKF(da < 1e-3, "alpha differs by %.5f", da);
}

/* A colour volume (a red ball in black): the voxels' colour replaces the
 * table's white at every collision, so the light that comes back is red
 * only, after any number of bounces. */
TEST(a_colour_volumes_colour_is_the_albedo)
{
    enum { C = 12 };
    static uint8_t rgb[C * C * C * 3];
    for (int z = 0; z < C; z++)
        for (int y = 0; y < C; y++)
            for (int x = 0; x < C; x++) {
                double d = sqrt((x - 5.5) * (x - 5.5) + (y - 5.5) * (y - 5.5) + (z - 5.5) * (z - 5.5));
                rgb[3 * (x + C * (y + C * z))] = d < 4.5 ? 255 : 0;
            }
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U8, .dims = {C, C, C}, .data = rgb,
                         .components = 3};
    vxl_volume *v = NULL;
    vxl_renderer *rcol = make_renderer(software_backend());
    REQUIRE(rcol && vxl_volume_create(&d, NULL, &v) == VXL_OK);
    int rc = vxl_renderer_set_volume(rcol, v);
    vxl_volume_destroy(v);
    vxl_render_params p = scene(VXL_SHADING_PATH, 1.0f, 0.5f);
    p.has_window = 0; /* the data's range: the ball's luminance at the table's top */
    p.path_samples = 4;
    p.path_bounces = 3;
    if (!rc) rc = vxl_render(rcol, &p, A, NULL);
    if (rc) fprintf(stderr, "    colour volume: %s\n", vxl_renderer_error(rcol));
    vxl_renderer_destroy(rcol);
    REQUIRE(rc == VXL_OK);
    double red = 0, other = 0;
    for (int i = 0; i < PX; i++) {
        red += A[4 * i];
        other += A[4 * i + 1] + A[4 * i + 2];
    }
    fprintf(stderr, "    red %.4f, green + blue %.4f\n", red, other);
    CHECK(red > 0.5);
    CHECK(other == 0);
}

TEST(what_path_cannot_draw_is_refused_by_name)
{
    vxl_render_params p = scene(VXL_SHADING_PATH, 0.8f, 0.5f);
    p.path_bounces = VXL_PATH_MAX_BOUNCES + 1;
    CHECK(vxl_render(R, &p, A, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_renderer_error(R), "path_bounces") != NULL);
    p.path_bounces = 0;
    p.path_samples = VXL_PATH_MAX_SAMPLES + 1;
    CHECK(vxl_render(R, &p, A, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_renderer_error(R), "path_samples") != NULL);
    p.path_samples = 2;
    p.path_sample_offset = UINT32_MAX;
    CHECK(vxl_render(R, &p, A, NULL) == VXL_ERR_INVALID_ARGUMENT);
    p.path_sample_offset = 0;
    p.gradient_opacity = VXL_GOPACITY_BOUNDARY;
    CHECK(vxl_render(R, &p, A, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_renderer_error(R), "gradient_opacity") != NULL);
    p.gradient_opacity = 0;
    static const float grey[4] = {0.5f, 0.5f, 0.5f, 1};
    vxl_matcap mc = {.struct_size = sizeof mc, .width = 1, .height = 1, .rgba = grey};
    p.matcap = &mc;
    CHECK(vxl_render(R, &p, A, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_renderer_error(R), "MatCap") != NULL);
    p.matcap = NULL;
    CHECK(vxl_render(R, &p, A, NULL) == VXL_OK);
    /* the other models ignore the path fields */
    p.shading_model = VXL_SHADING_SCATTER;
    p.path_bounces = 1000;
    CHECK(vxl_render(R, &p, A, NULL) == VXL_OK);
    CHECK(vxl_path_accumulate(NULL, A, 4, 0, 1) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_path_accumulate(ACC, A, 4, 0, 0) == VXL_ERR_INVALID_ARGUMENT);
}

int main(void)
{
    R = make_renderer(software_backend());
    vxl_volume *v = blobs_volume();
    if (!R || !v || vxl_renderer_set_volume(R, v) != VXL_OK) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    vxl_volume_destroy(v);
    RUN(one_bounce_is_scatters_sum);
    RUN(more_bounces_brighten_a_thick_white_volume_and_never_darken_it);
    RUN(the_same_seed_gives_the_same_image_and_another_seed_another);
    RUN(k_calls_of_one_sample_merge_into_one_call_of_k);
    RUN(a_clip_plane_cuts_the_medium_away);
    RUN(the_world_alone_lights_the_volume);
    RUN(bricked_storage_traces_the_same_medium);
    RUN(a_colour_volumes_colour_is_the_albedo);
    RUN(what_path_cannot_draw_is_refused_by_name);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
