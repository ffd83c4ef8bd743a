/* test_render.c - whole frames: golden images, determinism, occlusion by a
 * scene depth, output depth, and images that stay sane on hostile inputs.
 * Run with --update-golden to rewrite tests/golden/ (review the diff!). */
#include <errno.h>
#include <stdio.h>

#include "harness.h"
#include "test_util.h"

#ifndef GOLDEN_DIR
#define GOLDEN_DIR "tests/golden"
#endif

static vxl_renderer *R;
static int update_golden;

#define W 48
#define H 48
#define NPIX (W * H)

static int set_ball(uint32_t n)
{
    double c = (n - 1) / 2.0, prm[4] = {c, c, c, n * 0.35};
    vxl_volume *v = make_volume_f32(n, n, n, field_ball, prm);
    int rc = v ? vxl_renderer_set_volume(R, v) : -1;
    vxl_volume_destroy(v);
    return rc;
}

static vxl_render_params ball_params(void)
{
    vxl_render_params p = default_params(W, H);
    p.preset = VXL_PRESET_GRAY;
    p.has_window = 1;
    p.window_low = 0.0f;
    p.window_high = 1.0f;
    p.azimuth_deg = 30;
    p.elevation_deg = 20;
    return p;
}

static int golden_compare(const char *name, const float *img, size_t nfloat, double tol, double *rmse)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s.f32", GOLDEN_DIR, name);
    if (update_golden) {
        FILE *f = fopen(path, "wb");
        if (!f || fwrite(img, sizeof(float), nfloat, f) != nfloat) return 0;
        fclose(f);
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "  missing golden %s (%s)\n", path, strerror(errno));
        return 0;
    }
    float *g = malloc(nfloat * sizeof *g);
    size_t got = g ? fread(g, sizeof(float), nfloat, f) : 0;
    fclose(f);
    *rmse = got == nfloat ? image_rmse(img, g, nfloat) : 1e9;
    free(g);
    return *rmse <= tol;
}

TEST(golden_renders_match)
{
    REQUIRE(set_ball(40) == VXL_OK);
    static float img[NPIX * 4];
    const uint32_t filters[3] = {VXL_FILTER_CENTRAL, VXL_FILTER_SOBEL26, VXL_FILTER_PRECOMPUTED};
    const char *names[3] = {"ball_central", "ball_sobel26", "ball_precomputed"};
    for (int i = 0; i < 3; i++) {
        vxl_render_params p = ball_params();
        p.filter = filters[i];
        REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
        double rmse = 0;
        CHECKF(golden_compare(names[i], img, NPIX * 4, 2e-3, &rmse), "%s rmse %.5f", names[i], rmse);
        CHECK(alpha_sum(img, NPIX) > NPIX * 0.05); /* the ball (~13% of the frame) is there */
    }
}

TEST(renders_are_deterministic_with_jitter)
{
    REQUIRE(set_ball(32) == VXL_OK);
    static float a[NPIX * 4], b[NPIX * 4], c[NPIX * 4];
    vxl_render_params p = ball_params();
    REQUIRE(vxl_render(R, &p, a, NULL) == VXL_OK);
    REQUIRE(vxl_render(R, &p, b, NULL) == VXL_OK);
    CHECK(memcmp(a, b, sizeof a) == 0);
    p.jitter_seed = 99; /* a different pattern really changes the image */
    REQUIRE(vxl_render(R, &p, c, NULL) == VXL_OK);
    CHECK(memcmp(a, c, sizeof a) != 0);
}

TEST(every_setting_changes_the_image)
{
    REQUIRE(set_ball(32) == VXL_OK);
    static float base[NPIX * 4], img[NPIX * 4];
    vxl_render_params p0 = ball_params();
    REQUIRE(vxl_render(R, &p0, base, NULL) == VXL_OK);
    for (int k = 0; k < 9; k++) {
        vxl_render_params p = ball_params();
        switch (k) {
        case 0: p.filter = VXL_FILTER_FORWARD3; break;
        case 1: p.sample_distance = 2.5f; p.filter = VXL_FILTER_SOBEL8; break;
        case 2: p.step = 1.0f; break;
        case 3: p.shading_off = 1; break;
        case 4: p.window_high = 0.6f; break;
        case 5: p.opacity_scale = 0.3f; break;
        case 6: p.preset = VXL_PRESET_HOT; break;
        case 7: p.azimuth_deg = 100; break;
        case 8: p.light_count = 1; p.lights[0].position[0] = 1; p.lights[0].color[0] = 1; break;
        }
        REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
        CHECKF(image_rmse(base, img, NPIX * 4) > 1e-4, "setting %d had no effect", k);
    }
}

/* The depth output is the view-space planar distance where opacity passes the
 * threshold: for an opaque ball seen head-on, the centre pixel's depth is the
 * camera distance minus the radius, within a step. */
TEST(output_depth_is_planar_view_distance)
{
    const uint32_t n = 32;
    REQUIRE(set_ball(n) == VXL_OK);
    static float img[NPIX * 4], depth[NPIX];
    vxl_render_params p = ball_params();
    p.azimuth_deg = p.elevation_deg = 0;
    p.opacity_scale = 50; /* opaque at the surface */
    p.jitter_off = 1;
    float view[16], proj[16];
    REQUIRE(vxl_default_camera(R, &p, view, proj) == VXL_OK);
    REQUIRE(vxl_render(R, &p, img, depth) == VXL_OK);
    /* world = voxel space (identity affine); the ball centre in view space */
    double c = (n - 1) / 2.0;
    double zc = view[2] * c + view[6] * c + view[10] * c + view[14];
    double expect = -zc - n * 0.35;
    float d = depth[(H / 2) * W + W / 2];
    CHECKF(fabs(d - expect) < 1.0, "centre depth %.3f, expected %.3f", d, expect);
    CHECK(isinf(depth[0]) && depth[0] > 0); /* corner: no hit */
}

TEST(scene_depth_stops_rays)
{
    REQUIRE(set_ball(32) == VXL_OK);
    static float full[NPIX * 4], img[NPIX * 4], depth_in[NPIX];
    vxl_render_params p = ball_params();
    REQUIRE(vxl_render(R, &p, full, NULL) == VXL_OK);
    p.scene_depth = depth_in;
    for (int i = 0; i < NPIX; i++) depth_in[i] = INFINITY;
    REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
    CHECKF(image_rmse(full, img, NPIX * 4) < 1e-6, "+inf depth must change nothing");
    for (int i = 0; i < NPIX; i++) depth_in[i] = 0.0f;
    REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
    CHECKF(alpha_sum(img, NPIX) == 0, "zero depth must hide everything");
    /* geometry at the ball's centre depth on the left half only */
    float view[16], proj[16];
    REQUIRE(vxl_default_camera(R, &p, view, proj) == VXL_OK);
    double c = 15.5, zc = -(view[2] * c + view[6] * c + view[10] * c + view[14]);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) depth_in[y * W + x] = x < W / 2 ? (float)zc : INFINITY;
    REQUIRE(vxl_render(R, &p, img, NULL) == VXL_OK);
    CHECK(image_is_sane(img, NULL, NPIX));
    double left_full = 0, left = 0, right_full = 0, right = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int i = y * W + x;
            if (x < W / 2) { left_full += full[4 * i + 3]; left += img[4 * i + 3]; }
            else { right_full += full[4 * i + 3]; right += img[4 * i + 3]; }
        }
    CHECKF(left < left_full * 0.95, "left half not occluded: %.2f vs %.2f", left, left_full);
    CHECKF(fabs(right - right_full) < 1e-3, "right half changed: %.4f vs %.4f", right, right_full);
}

/* Hostile volumes and views: every output pixel finite and premultiplied. */
static void render_sane(vxl_test_ctx *T_, vxl_volume *v, vxl_render_params *p, const char *what)
{
    static float img[NPIX * 4], depth[NPIX];
    REQUIRE(v);
    int rc = vxl_renderer_set_volume(R, v);
    vxl_volume_destroy(v);
    CHECKF(rc == VXL_OK, "%s: set_volume: %s", what, vxl_last_error());
    if (rc) return;
    for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++) {
        p->filter = f;
        rc = vxl_render(R, p, img, depth);
        CHECKF(rc == VXL_OK, "%s/%s: %s", what, vxl_filter_name(f), vxl_last_error());
        CHECKF(rc || image_is_sane(img, depth, NPIX), "%s/%s: insane pixels", what, vxl_filter_name(f));
    }
}

static vxl_volume *volume_from(const float *data, uint32_t nx, uint32_t ny, uint32_t nz)
{
    vxl_volume_desc d;
    memset(&d, 0, sizeof d);
    d.dtype = VXL_DTYPE_F32;
    d.dims[0] = nx;
    d.dims[1] = ny;
    d.dims[2] = nz;
    d.data = data;
    vxl_volume *v = NULL;
    vxl_volume_create(&d, NULL, &v);
    return v;
}

TEST(hostile_volumes_give_sane_images)
{
    static float data[16 * 16 * 16];
    vxl_render_params p = ball_params();
    p.preset = VXL_PRESET_AUTO;
    p.has_window = 0;
    for (int i = 0; i < 4096; i++) data[i] = 3.0f;
    render_sane(T_, volume_from(data, 16, 16, 16), &p, "constant");
    for (int i = 0; i < 4096; i++) data[i] = (i % 7 == 0) ? NAN : (i % 11 == 0) ? INFINITY : (i % 13 == 0) ? -INFINITY : (float)(i % 16);
    render_sane(T_, volume_from(data, 16, 16, 16), &p, "nan/inf voxels");
    for (int i = 0; i < 4096; i++) data[i] = (i % 3 == 0) ? 1e30f : (i % 3 == 1) ? -1e30f : 1e-40f;
    render_sane(T_, volume_from(data, 16, 16, 16), &p, "+-1e30 and denormals");
    data[0] = 5.0f;
    render_sane(T_, volume_from(data, 1, 1, 1), &p, "1x1x1");
    for (int i = 0; i < 256; i++) data[i] = (float)i;
    render_sane(T_, volume_from(data, 1, 16, 16), &p, "1xNxN");
    for (int i = 0; i < 4096; i++) data[i] = 0;
    data[8 + 16 * (8 + 16 * 8)] = 1000;
    render_sane(T_, volume_from(data, 16, 16, 16), &p, "single bright voxel");
}

TEST(camera_inside_and_axis_parallel_views_are_sane)
{
    static float img[NPIX * 4], depth[NPIX];
    REQUIRE(set_ball(16) == VXL_OK);
    vxl_render_params p = ball_params();
    p.has_camera = 1;
    /* projection: 60 degrees, near 0.01, far 100 */
    double f = 1 / tan(M_PI / 6), n = 0.01, fa = 100;
    memset(p.proj, 0, sizeof p.proj);
    p.proj[0] = (float)f;
    p.proj[5] = (float)f;
    p.proj[10] = (float)((fa + n) / (n - fa));
    p.proj[11] = -1;
    p.proj[14] = (float)(2 * fa * n / (n - fa));
    /* eye at several places looking down -Z (axis-parallel central ray): inside,
     * exactly on the face plane z = 15.5, and exactly on a voxel slab plane */
    const float eyes[4][3] = {{7.5f, 7.5f, 7.5f}, {7.5f, 7.5f, 15.5f}, {-0.5f, 7.5f, 30}, {7.5f, -0.5f, 30}};
    for (int k = 0; k < 4; k++) {
        memset(p.view, 0, sizeof p.view);
        p.view[0] = p.view[5] = p.view[10] = p.view[15] = 1;
        p.view[12] = -eyes[k][0];
        p.view[13] = -eyes[k][1];
        p.view[14] = -eyes[k][2];
        REQUIRE(vxl_render(R, &p, img, depth) == VXL_OK);
        CHECKF(image_is_sane(img, depth, NPIX), "eye %d", k);
        if (k < 2) CHECKF(alpha_sum(img, NPIX) > 1, "eye %d inside sees nothing", k);
    }
}

TEST(extreme_steps_are_bounded)
{
    static float img[NPIX * 4];
    REQUIRE(set_ball(16) == VXL_OK);
    const float steps[2] = {1e-4f, 100.0f};
    for (int k = 0; k < 2; k++) {
        vxl_render_params p = ball_params();
        p.step = steps[k];
        CHECK(vxl_render(R, &p, img, NULL) == VXL_OK);
        CHECK(image_is_sane(img, NULL, NPIX));
        vxl_render_stats st = {.struct_size = sizeof st};
        CHECK(vxl_renderer_get_stats(R, &st) == VXL_OK);
        CHECKF(st.rays > 0 && st.max_ray_samples <= st.sample_bound && st.sample_bound <= 16384 + 3,
               "step %g: rays %u, longest ray %u samples, bound %u", steps[k], st.rays, st.max_ray_samples,
               st.sample_bound);
        CHECKF(st.samples > 0 && st.samples <= (uint64_t)st.rays * st.max_ray_samples, "samples %llu", (unsigned long long)st.samples);
    }
}

/* R against a second context on `backend`, rendering the same ball. */
static void second_context_matches(vxl_test_ctx *T_, uint32_t backend)
{
    vxl_renderer *e = make_renderer(backend);
    REQUIRE(e);
    vxl_renderer_info info = {.struct_size = sizeof info};
    CHECK(vxl_renderer_get_info(e, &info) == VXL_OK && info.backend == backend);
    fprintf(stderr, "    second context: %s, %s, %s\n", info.backend_name, info.gl_renderer, info.gl_version);
    double c = 15.5, prm[4] = {c, c, c, 11};
    vxl_volume *v = make_volume_f32(32, 32, 32, field_ball, prm);
    REQUIRE(v);
    CHECK(vxl_renderer_set_volume(e, v) == VXL_OK && vxl_renderer_set_volume(R, v) == VXL_OK);
    vxl_volume_destroy(v);
    static float a[NPIX * 4], b[NPIX * 4];
    vxl_render_params p = ball_params();
    CHECK(vxl_render(R, &p, a, NULL) == VXL_OK && vxl_render(e, &p, b, NULL) == VXL_OK);
    double rmse = image_rmse(a, b, NPIX * 4);
    CHECKF(rmse < 2e-3, "%s against R's context: rmse %.5f", info.backend_name, rmse);
    vxl_renderer_destroy(e);
}

/* OSMesa and EGL are two ways to llvmpipe and must agree. */
TEST(egl_on_mesa_matches_osmesa)
{
    if (getenv("VOXLIGHT_TEST_NO_EGL")) {
        fprintf(stderr, "    VOXLIGHT_TEST_NO_EGL set: EGL comparison not run\n");
        CHECK(0 && "EGL test disabled by environment");
        return;
    }
    second_context_matches(T_, VXL_BACKEND_EGL);
}

/* Without OSMesa (R on EGL), or on Windows (WGL): two contexts of the one
 * backend, which share a process-wide display or llvmpipe screen. */
TEST(two_contexts_of_one_backend_match)
{
    second_context_matches(T_, software_backend());
}

int main(int argc, char **argv)
{
    update_golden = argc > 1 && !strcmp(argv[1], "--update-golden");
    R = make_renderer(software_backend());
    if (!R) {
        fprintf(stderr, "cannot create the software renderer: %s\n", vxl_last_error());
        printf("0 passed, 1 failed\n");
        return 1;
    }
    RUN(golden_renders_match);
    RUN(renders_are_deterministic_with_jitter);
    RUN(every_setting_changes_the_image);
    RUN(output_depth_is_planar_view_distance);
    RUN(scene_depth_stops_rays);
    RUN(hostile_volumes_give_sane_images);
    RUN(camera_inside_and_axis_parallel_views_are_sane);
    RUN(extreme_steps_are_bounded);
    if (osmesa_installed()) RUN(egl_on_mesa_matches_osmesa);
    else RUN(two_contexts_of_one_backend_match);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
