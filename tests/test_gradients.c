/* test_gradients.c - the gradient filters, measured through
 * vxl_probe_gradients, i.e. through the real GLSL the ray caster runs. */
#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h" /* the test hooks */

static vxl_renderer *R;

/* Random points at least `margin` voxels inside the box (clamp-to-edge
 * breaks linearity at the border). Deterministic LCG. */
static void interior_points(float *pts, uint32_t n, uint32_t dim, double margin, uint32_t seed)
{
    uint64_t s = seed * 6364136223846793005ull + 1442695040888963407ull;
    for (uint32_t i = 0; i < 3 * n; i++) {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        double u = (double)(s >> 11) / 9007199254740992.0;
        pts[i] = (float)(margin + u * (dim - 1 - 2 * margin));
    }
}

static vxl_render_params probe_params(uint32_t filter, float d, uint32_t store)
{
    vxl_render_params p = default_params(1, 1);
    p.filter = filter;
    p.sample_distance = d;
    p.gradient_store = store;
    return p;
}

/* Max angular error of a filter on a ramp with direction dir. */
static double ramp_max_error(uint32_t filter, float d, uint32_t store, const double dir[3])
{
    const uint32_t N = 24, n = 200;
    double prm[4] = {dir[0] / N, dir[1] / N, dir[2] / N, 0.5};
    vxl_volume *v = make_volume_f32(N, N, N, field_ramp, prm);
    if (!v || vxl_renderer_set_volume(R, v)) {
        vxl_volume_destroy(v);
        return 999;
    }
    vxl_volume_destroy(v);
    float pts[3 * 200], g[3 * 200];
    /* The cubic prefilter assumes a mirrored border, under which a ramp is not
     * linear; the disturbance decays by |sqrt(3) - 2| = 0.27 per voxel, so its
     * exactness holds from ~9 voxels in. */
    double margin = filter == VXL_FILTER_CUBIC ? 9.0 : d + 2.5;
    interior_points(pts, n, N, margin, 7);
    vxl_render_params p = probe_params(filter, d, store);
    if (vxl_probe_gradients(R, &p, pts, n, g)) return 999;
    double worst = 0;
    for (uint32_t i = 0; i < n; i++) worst = fmax(worst, angle_deg(g + 3 * i, prm));
    return worst;
}

TEST(every_filter_is_exact_on_a_ramp)
{
    const double dirs[4][3] = {{1, 0, 0}, {0.3, -0.8, 0.5}, {-0.2, 0.1, 0.97}, {0.577, 0.577, 0.577}};
    const float ds[3] = {0.5f, 1.0f, 1.5f};
    for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++)
        for (int k = 0; k < 4; k++)
            for (int j = 0; j < 3; j++) {
                /* precomputed stores exactly only as 32-bit float; its d is fixed */
                double e = ramp_max_error(f, ds[j], VXL_GRADIENT_STORE_32F, dirs[k]);
                CHECKF(e < 0.01, "%s d=%.1f dir %d: max error %.5f deg", vxl_filter_name(f), ds[j], k, e);
            }
}

TEST(precomputed_storage_formats_are_within_their_quantisation)
{
    const double dir[3] = {0.3, -0.8, 0.5};
    double e8 = ramp_max_error(VXL_FILTER_PRECOMPUTED, 1, VXL_GRADIENT_STORE_8BIT, dir);
    double e16 = ramp_max_error(VXL_FILTER_PRECOMPUTED, 1, VXL_GRADIENT_STORE_16F, dir);
    CHECKF(e8 < 0.6, "8-bit: %.4f deg", e8);
    CHECKF(e16 < 0.1, "16f: %.4f deg", e16);
}

/* Mean angular error on a Gaussian blob sampled at N^3, at points near the
 * iso-surface f = 0.5 (radius sigma*sqrt(2 ln 2)). */
static double blob_mean_error(uint32_t filter, uint32_t N)
{
    double c = (N - 1) / 2.0, sigma = N / 6.0;
    double prm[4] = {c, c, c, sigma};
    vxl_volume *v = make_volume_f32(N, N, N, field_blob, prm);
    if (!v || vxl_renderer_set_volume(R, v)) {
        vxl_volume_destroy(v);
        return 999;
    }
    vxl_volume_destroy(v);
    enum { n = 256 };
    float pts[3 * n], g[3 * n];
    double radius = sigma * sqrt(2 * log(2.0));
    for (int i = 0; i < n; i++) { /* Fibonacci sphere */
        double z = 1 - 2 * (i + 0.5) / n, r = sqrt(1 - z * z), ph = i * 2.39996322972865332;
        pts[3 * i] = (float)(c + radius * r * cos(ph));
        pts[3 * i + 1] = (float)(c + radius * r * sin(ph));
        pts[3 * i + 2] = (float)(c + radius * z);
    }
    vxl_render_params p = probe_params(filter, 1.0f, VXL_GRADIENT_STORE_32F);
    if (vxl_probe_gradients(R, &p, pts, n, g)) return 999;
    double sum = 0;
    for (int i = 0; i < n; i++) {
        double truth[3] = {c - pts[3 * i], c - pts[3 * i + 1], c - pts[3 * i + 2]}; /* grad points inwards */
        sum += angle_deg(g + 3 * i, truth);
    }
    return sum / n;
}

TEST(filters_converge_on_a_smooth_blob)
{
    for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++) {
        double e16 = blob_mean_error(f, 16), e32 = blob_mean_error(f, 32), e64 = blob_mean_error(f, 64);
        fprintf(stderr, "    %-11s mean error 16^3 %.3f  32^3 %.3f  64^3 %.3f deg\n", vxl_filter_name(f), e16, e32, e64);
        /* forward3 is a one-sided difference: first order, so the error
         * halves per doubling; every other filter is second order (x4). */
        int first_order = f == VXL_FILTER_FORWARD3;
        double min_ratio = first_order ? 1.8 : 3.0;
        CHECKF(e16 / e32 > min_ratio && e32 / e64 > min_ratio, "%s converges too slowly", vxl_filter_name(f));
        CHECKF(e64 < (first_order ? 3.0 : 0.1), "%s at 64^3: %.3f deg", vxl_filter_name(f), e64);
    }
}

/* Mean angle between a filter's gradient and the noise-free blob's analytic
 * gradient, at points near its 0.5 iso-surface, on the noisy-blob phantom. */
static double noisy_blob_error(uint32_t filter, double sigma)
{
    vxl_phantom_desc d = {sizeof d, VXL_PHANTOM_NOISY_BLOB, {64, 64, 64}, 3, sigma};
    vxl_volume *v = NULL;
    if (vxl_phantom_create(&d, &v) || vxl_renderer_set_volume(R, v)) {
        vxl_volume_destroy(v);
        return 999;
    }
    vxl_volume_destroy(v);
    enum { n = 400 };
    float pts[3 * n], g[3 * n];
    uint32_t got = 0;
    if (vxl_phantom_iso_points(&d, 0.5, 0.02, 11, pts, n, &got) || got < n / 2) return 999;
    vxl_render_params p = probe_params(filter, 1.0f, VXL_GRADIENT_STORE_32F);
    if (vxl_probe_gradients(R, &p, pts, got, g)) return 999;
    double sum = 0;
    for (uint32_t i = 0; i < got; i++) {
        double q[3] = {pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]}, val, truth[3];
        if (vxl_phantom_eval(&d, q, &val, truth)) return 999;
        sum += angle_deg(g + 3 * i, truth);
    }
    return sum / got;
}

/* The approximating B-spline is offered for noisy scans: on noise it must
 * beat the interpolating one, which passes every voxel's noise on (measured:
 * about a third of its error, on a par with central differences at d = 1). */
TEST(cubic_smooth_is_the_better_spline_on_noise)
{
    for (int k = 0; k < 2; k++) {
        double sigma = k ? 0.05 : 0.02;
        double smooth = noisy_blob_error(VXL_FILTER_CUBIC_SMOOTH, sigma), cubic = noisy_blob_error(VXL_FILTER_CUBIC, sigma);
        double central = noisy_blob_error(VXL_FILTER_CENTRAL, sigma);
        fprintf(stderr, "    noise %.2f: mean error cubic-smooth %.2f, cubic %.2f, central %.2f deg\n", sigma, smooth,
                cubic, central);
        CHECKF(smooth < 0.6 * cubic, "noise %.2f: cubic-smooth %.2f vs cubic %.2f", sigma, smooth, cubic);
        CHECKF(smooth < 1.2 * central, "noise %.2f: cubic-smooth %.2f vs central %.2f", sigma, smooth, central);
    }
}

/* prm: cy, cz: f = A(x)(y-cy) + B(x)(z-cz) with A falling and B small, so
 * along the line y=cy, z=cz the gradient is (0, A, B): its magnitude falls
 * for x < N/2 and rises after, and its direction turns all the way. */
static double field_turning(double x, double y, double z, const double *p)
{
    double t = x / 31.0;
    double a = 1.0 - 1.6 * t, b = 0.2 + 0.8 * t;
    return 0.5 + 0.01 * (a * (y - p[0]) + b * (z - p[1]));
}

TEST(reuse_gradients_keeps_direction_while_magnitude_falls)
{
    const uint32_t N = 32;
    double prm[2] = {15.5, 15.5};
    vxl_volume *v = make_volume_f32(N, N, N, field_turning, prm);
    REQUIRE(v && vxl_renderer_set_volume(R, v) == VXL_OK);
    vxl_volume_destroy(v);
    enum { n = 40 };
    float pts[3 * n], plain[3 * n], reused[3 * n];
    for (int i = 0; i < n; i++) {
        pts[3 * i] = 2 + 27.0f * i / (n - 1);
        pts[3 * i + 1] = pts[3 * i + 2] = 15.5f;
    }
    vxl_render_params p = probe_params(VXL_FILTER_CENTRAL, 1, 0);
    REQUIRE(vxl_probe_gradients(R, &p, pts, n, plain) == VXL_OK);
    p.reuse_gradients = 1;
    REQUIRE(vxl_probe_gradients(R, &p, pts, n, reused) == VXL_OK);
    /* expected: the rule applied in C to the plain gradients */
    double dir[3] = {0}, mag = -1;
    int kept = 0, followed = 0;
    for (int i = 0; i < n; i++) {
        const float *g = plain + 3 * i;
        double m = sqrt((double)g[0] * g[0] + (double)g[1] * g[1] + (double)g[2] * g[2]);
        if (!(m < mag)) {
            for (int k = 0; k < 3; k++) dir[k] = g[k];
            followed++;
        } else {
            kept++;
        }
        mag = m;
        CHECKF(angle_deg(reused + 3 * i, dir) < 0.01, "sample %d", i);
    }
    CHECKF(kept > 5 && followed > 5, "the constructed ray must exercise both branches (kept %d, followed %d)", kept, followed);
    /* and reuse changed something: the kept direction differs from the plain one */
    double turned = angle_deg(reused + 3 * (n / 3), (double[3]){plain[3 * (n / 3)], plain[3 * (n / 3) + 1], plain[3 * (n / 3) + 2]});
    CHECKF(turned > 5, "reuse had no visible effect (%.2f deg)", turned);
}

TEST(zero_gradient_is_never_nan)
{
    double prm[4] = {0, 0, 0, 0.25};
    vxl_volume *v = make_volume_f32(8, 8, 8, field_ramp, prm); /* constant */
    REQUIRE(v && vxl_renderer_set_volume(R, v) == VXL_OK);
    vxl_volume_destroy(v);
    float pts[6] = {3.5f, 3.5f, 3.5f, 0, 0, 0}, g[6];
    for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++) {
        vxl_render_params p = probe_params(f, 1, 0);
        CHECK(vxl_probe_gradients(R, &p, pts, 2, g) == VXL_OK);
        for (int i = 0; i < 6; i++) CHECKF(g[i] == 0.0f, "%s component %d = %g", vxl_filter_name(f), i, g[i]);
    }
}

int main(void)
{
    R = make_renderer(software_backend());
    if (!R) {
        fprintf(stderr, "cannot create the software renderer: %s\n", vxl_last_error());
        printf("0 passed, 1 failed\n");
        return 1;
    }
    RUN(every_filter_is_exact_on_a_ramp);
    RUN(precomputed_storage_formats_are_within_their_quantisation);
    RUN(filters_converge_on_a_smooth_blob);
    RUN(cubic_smooth_is_the_better_spline_on_noise);
    RUN(reuse_gradients_keeps_direction_while_magnitude_falls);
    RUN(zero_gradient_is_never_nan);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
