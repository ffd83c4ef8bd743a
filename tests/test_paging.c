/* test_paging.c - bricked and sparse storage must render what one texture
 * renders: every filter (the on-the-fly ones, precomputed and cubic, whose
 * data is derived brick by brick) and every classification mode, PSNR >= 60
 * dB against DENSE; no seams at brick edges on a ramp (gradients through the
 * real shader, exact to 0.01 degrees at and across brick faces); a volume
 * over the backend's texture limit renders bricked; budgets and unsupported
 * combinations fail with a clear message. Small page bricks (8^3) so small
 * volumes cross many brick edges. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h" /* the test hooks */

#define W 64
#define H 64

/* compressed_domain: compressed storage filtered in the compressed domain */
static vxl_renderer *make_stored_in(uint32_t storage, uint32_t page_brick, uint64_t budget, uint32_t compressed_domain)
{
    return make_stored_renderer(storage, page_brick, budget, compressed_domain);
}

static vxl_renderer *make_stored(uint32_t storage, uint32_t page_brick, uint64_t budget)
{
    return make_stored_in(storage, page_brick, budget, 0);
}

static vxl_render_params scene(uint32_t filter, uint32_t mode) { return phantom_scene(W, H, filter, mode); }

/* Runs 0-6: every filter in post-classification (precomputed with its
 * default 8-bit store); 7 pre-integration, 8 pre-classification, 9 boundary
 * opacity (central differences), 10 iso-surface opacity with the cubic
 * filter, 11 skipping off. */
#define STORAGE_RUNS 12
static vxl_render_params storage_run(uint32_t run)
{
    vxl_render_params p = scene(run < VXL_FILTER_COUNT ? run : run == 10 ? VXL_FILTER_CUBIC : VXL_FILTER_CENTRAL,
                                run == 7 ? VXL_CLASSIFY_PREINT : run == 8 ? VXL_CLASSIFY_PRE : VXL_CLASSIFY_POST);
    if (run == 9) p.gradient_opacity = VXL_GOPACITY_BOUNDARY;
    if (run == 10) {
        p.gradient_opacity = VXL_GOPACITY_ISO;
        p.iso_value = 0.5f;
    }
    if (run == 11) p.no_skip = 1;
    return p;
}

/* Compressed storage keeps every brick's values only as codes on the GL
 * side, so the filters derived from them refuse (with a message), as does
 * pre-classification in the compressed domain. */
static int compressed_serves(const vxl_render_params *p, int domain)
{
    const int derived = (p->filter == VXL_FILTER_PRECOMPUTED || p->filter == VXL_FILTER_CUBIC);
    return !derived && !(domain && p->classify == VXL_CLASSIFY_PRE);
}

static vxl_render_stats stats_of(vxl_renderer *r) { return renderer_stats(r); }

/* The 45x40x37 phantom (45 is not a multiple of 8: partial bricks at the
 * far faces) on each of the n renderers. */
static int set_each(vxl_renderer *const *rs, int n, vxl_volume *v)
{
    int ok = v != NULL;
    for (int i = 0; i < n && ok; i++) ok = vxl_renderer_set_volume(rs[i], v) == VXL_OK;
    vxl_volume_destroy(v);
    return ok;
}

static int set_phantom(vxl_renderer *const *rs, int n, uint32_t kind)
{
    vxl_phantom_desc pd = {.struct_size = sizeof pd, .kind = kind, .dims = {45, 40, 37}, .seed = 3};
    vxl_volume *v = NULL;
    return vxl_phantom_create(&pd, &v) == VXL_OK && set_each(rs, n, v);
}

/* Renders p with each of the n renderers into imgs[i]; 0 on the first failure. */
static int render_each(vxl_renderer *const *rs, float *const *imgs, int n, const vxl_render_params *p)
{
    for (int i = 0; i < n; i++)
        if (vxl_render(rs[i], p, imgs[i], NULL) != VXL_OK) return 0;
    return 1;
}

/* Compressed storage (palette of <= 256 values + 8-bit codes per brick,
 * decoded into a linear cache, then filtered natively) against dense too,
 * and the compressed-domain variant (every tap decodes 8 codes) against
 * it. Float phantoms with P = 8: a brick holds 1000 voxels of up to 1000
 * distinct values in 256 Lloyd levels; the quantisation step is then about
 * (max - min) / 256 per brick, well under 1% of the range where values
 * vary fastest, so the image stays above 40 dB (measured 46.6-69.1). */
TEST(every_storage_equals_dense)
{
    vxl_renderer *rd = make_stored(VXL_STORAGE_DENSE, 0, 0), *rb = make_stored(VXL_STORAGE_BRICKED, 8, 0),
                 *rs = make_stored(VXL_STORAGE_SPARSE, 8, 0), *rc = make_stored(VXL_STORAGE_COMPRESSED, 8, 0),
                 *rx = make_stored_in(VXL_STORAGE_COMPRESSED, 8, 0, 1);
    REQUIRE(rd && rb && rs && rc && rx);
    static float d[W * H * 4], b[W * H * 4], s[W * H * 4], c[W * H * 4], x[W * H * 4];
    const uint32_t kinds[3] = {VXL_PHANTOM_SPARSE_BALLS, VXL_PHANTOM_MARSCHNER_LOBB, VXL_PHANTOM_NOISY_BLOB};
    vxl_renderer *const all[5] = {rd, rb, rs, rc, rx};
    for (int k = 0; k < 3; k++) {
        REQUIRE(set_phantom(all, 5, kinds[k]));
        /* the five on-the-fly filters in post-classification, pre-integration
         * and boundary opacity with central differences, and skipping off */
        for (uint32_t run = 0; run < STORAGE_RUNS; run++) {
            vxl_render_params p = storage_run(run);
            const uint32_t f = p.filter;
            const char *ph = vxl_phantom_name(kinds[k]), *fn = vxl_filter_name(f);
            float *const imgs[5] = {d, b, s, c, x};
            const int nc = compressed_serves(&p, 0) ? compressed_serves(&p, 1) ? 5 : 4 : 3;
            CHECKF(render_each(all, imgs, nc, &p), "%s", vxl_last_error());
            for (int i = nc; i < 5; i++) { /* what compressed storage cannot serve, it says */
                CHECK(vxl_render(all[i], &p, imgs[i], NULL) == VXL_ERR_STATE);
                CHECKF(strstr(vxl_last_error(), "compressed") != NULL, "%s", vxl_last_error());
                memcpy(imgs[i], i == 4 ? c : d, sizeof d); /* stands in, so the checks below pass */
            }
            double qb = image_psnr(b, d, W * H * 4), qs = image_psnr(s, d, W * H * 4);
            double qc = image_psnr(c, d, W * H * 4), qx = image_psnr(x, c, W * H * 4);
            vxl_render_stats sb = stats_of(rb), ss = stats_of(rs), sc = stats_of(rc), sx = stats_of(rx);
            fprintf(stderr, "    %-15s %-11s run %2u: bricked %6.1f dB (%u/%u resident), sparse %6.1f dB (%u resident)",
                    ph, fn, run, qb, sb.pages_resident, sb.pages_total, qs, ss.pages_resident);
            if (nc >= 4) fprintf(stderr, ", compressed %5.1f dB", qc);
            if (nc == 5) fprintf(stderr, "; compressed domain %6.1f dB vs deferred", qx);
            fprintf(stderr, "\n");
            CHECKF(qb >= 60, "%s/%s run %u: bricked %.1f dB", ph, fn, run, qb);
            CHECKF(qs >= 60, "%s/%s run %u: sparse %.1f dB", ph, fn, run, qs);
            CHECKF(qc >= 40, "%s/%s run %u: compressed %.1f dB", ph, fn, run, qc);
            CHECKF(qx >= 60, "%s/%s run %u: compressed domain %.1f dB", ph, fn, run, qx);
            CHECK(alpha_sum(d, W * H) > 1);
            CHECK(sb.storage == VXL_STORAGE_BRICKED && ss.storage == VXL_STORAGE_SPARSE);
            CHECK(sb.page_brick == 8 && sb.pages_total == 6 * 5 * 5);
            CHECK(ss.pages_resident <= sb.pages_resident && sb.resident_bytes > 0);
            CHECK(sc.storage == VXL_STORAGE_COMPRESSED && sc.pages_total == 6 * 5 * 5 && sc.resident_bytes > 0);
            /* the code pool alone: no decode cache, nothing decoded */
            if (nc == 5) CHECK(sx.resident_bytes < sc.resident_bytes && sx.decode_ms == 0);
        }
    }
    for (int i = 0; i < 5; i++) vxl_renderer_destroy(all[i]);
}

/* Three Gaussian blobs (sigma 3) in 96^3: their float tails make almost
 * every brick non-constant, but a window shows only the cores. */
static double three_blobs(double x, double y, double z, const double *p)
{
    (void)p;
    const double c[3][3] = {{20, 24, 30}, {70, 50, 40}, {40, 80, 75}};
    double s = 0;
    for (int i = 0; i < 3; i++) {
        double dx = x - c[i][0], dy = y - c[i][1], dz = z - c[i][2];
        s += exp(-(dx * dx + dy * dy + dz * dz) / 18.0);
    }
    return s;
}

/* The precomputed filter's texture, derived per brick into a gradient pool
 * of its own: every store format equals the dense texture's image, bricked
 * and sparse (the stored gradients are scaled by the whole volume's largest
 * gradient, as with one texture, even where only some bricks' are made). */
TEST(precomputed_gradients_bricked_and_sparse_equal_dense)
{
    vxl_renderer *rd = make_stored(VXL_STORAGE_DENSE, 0, 0), *rb = make_stored(VXL_STORAGE_BRICKED, 8, 0),
                 *rs = make_stored(VXL_STORAGE_SPARSE, 8, 0);
    REQUIRE(rd && rb && rs);
    static float d[W * H * 4], b[W * H * 4], s[W * H * 4];
    const uint32_t kinds[3] = {VXL_PHANTOM_SPARSE_BALLS, VXL_PHANTOM_MARSCHNER_LOBB, VXL_PHANTOM_NOISY_BLOB};
    vxl_renderer *const all[3] = {rd, rb, rs};
    float *const imgs[3] = {d, b, s};
    for (int k = 0; k < 3; k++) {
        REQUIRE(set_phantom(all, 3, kinds[k]));
        for (uint32_t store = 0; store <= VXL_GRADIENT_STORE_32F; store++) {
            vxl_render_params p = scene(VXL_FILTER_PRECOMPUTED, VXL_CLASSIFY_POST);
            p.gradient_store = store;
            CHECKF(render_each(all, imgs, 3, &p), "%s", vxl_last_error());
            double qb = image_psnr(b, d, W * H * 4), qs = image_psnr(s, d, W * H * 4);
            fprintf(stderr, "    %-15s precomputed store %u: bricked %6.1f dB, sparse %6.1f dB\n",
                    vxl_phantom_name(kinds[k]), store, qb, qs);
            CHECKF(qb >= 60, "%s store %u: bricked %.1f dB", vxl_phantom_name(kinds[k]), store, qb);
            CHECKF(qs >= 60, "%s store %u: sparse %.1f dB", vxl_phantom_name(kinds[k]), store, qs);
        }
    }
    /* a budget of 16 MiB blurs the three blobs' ~1450 bricks in chunks of
     * a sixteenth of it (about 150): the same image */
    vxl_renderer *rc = make_stored(VXL_STORAGE_BRICKED, 8, 16u << 20);
    REQUIRE(rc);
    vxl_volume *v = make_volume_f32(96, 96, 96, three_blobs, NULL);
    REQUIRE(v && vxl_renderer_set_volume(rc, v) == VXL_OK && vxl_renderer_set_volume(rd, v) == VXL_OK);
    vxl_volume_destroy(v);
    vxl_render_params p = scene(VXL_FILTER_PRECOMPUTED, VXL_CLASSIFY_POST);
    p.window_low = 0.05f;
    REQUIRE(vxl_render(rd, &p, d, NULL) == VXL_OK);
    CHECKF(vxl_render(rc, &p, b, NULL) == VXL_OK, "%s", vxl_last_error());
    double q = image_psnr(b, d, W * H * 4);
    fprintf(stderr, "    three blobs, bricked in a 16 MiB budget (blurred in chunks): %.1f dB\n", q);
    CHECKF(q >= 60 && alpha_sum(d, W * H) > 1, "chunked precomputed gradients: %.1f dB", q);
    vxl_renderer_destroy(rc);
    for (int i = 0; i < 3; i++) vxl_renderer_destroy(all[i]);
}

/* The derived filters through the shader at points all over the volume,
 * brick faces and the volume's edge included: the coefficient and gradient
 * bricks must give what the dense textures give (cubic: each brick's
 * coefficients come from a window 12 voxels wider; the prefilter's tail
 * beyond that weighs 0.268^13). Measured: cubic 1.2e-4 of the largest
 * component bricked (P = 8), 2e-5 sparse (P = 16), precomputed under 1e-4;
 * a 20-voxel margin gives the same numbers, so what remains is the sampler's
 * fixed-point filter weights (llvmpipe) at other texel positions in a pool,
 * multiplied by the spline coefficients' large neighbour differences. */
TEST(derived_filters_probe_as_dense)
{
    vxl_renderer *rd = make_stored(VXL_STORAGE_DENSE, 0, 0), *rb = make_stored(VXL_STORAGE_BRICKED, 8, 0),
                 *rs = make_stored(VXL_STORAGE_SPARSE, 16, 0);
    REQUIRE(rd && rb && rs);
    vxl_renderer *const all[3] = {rd, rb, rs};
    enum { N = 2000 };
    static float pts[N * 3], out[3][N * 3];
    uint32_t seed = 12345;
    const float dims[3] = {45, 40, 37};
    for (int i = 0; i < N * 3; i++) { /* the box -0.5 .. dims - 0.5, and half a voxel beyond */
        seed = seed * 1664525u + 1013904223u;
        pts[i] = (float)(seed >> 8) / 16777216.0f * (dims[i % 3] + 1.0f) - 1.0f;
    }
    const uint32_t kinds[2] = {VXL_PHANTOM_MARSCHNER_LOBB, VXL_PHANTOM_NOISY_BLOB};
    const uint32_t filters[2] = {VXL_FILTER_CUBIC, VXL_FILTER_PRECOMPUTED};
    for (int k = 0; k < 2; k++) {
        REQUIRE(set_phantom(all, 3, kinds[k]));
        for (int f = 0; f < 2; f++) {
            vxl_render_params p = scene(filters[f], VXL_CLASSIFY_POST);
            p.gradient_store = VXL_GRADIENT_STORE_32F;
            for (int i = 0; i < 3; i++)
                CHECKF(vxl_probe_gradients(all[i], &p, pts, N, out[i]) == VXL_OK, "%s", vxl_last_error());
            double gmax = 0, eb = 0, es = 0;
            for (int i = 0; i < N * 3; i++) {
                gmax = fmax(gmax, fabs(out[0][i]));
                eb = fmax(eb, fabs(out[1][i] - out[0][i]));
                es = fmax(es, fabs(out[2][i] - out[0][i]));
            }
            fprintf(stderr, "    %-15s %-11s largest component %.4f; off dense by at most %.2e bricked, %.2e sparse\n",
                    vxl_phantom_name(kinds[k]), vxl_filter_name(filters[f]), gmax, eb, es);
            CHECK(gmax > 0.01);
            CHECKF(eb <= 5e-4 * gmax && es <= 5e-4 * gmax, "%s/%s: %.2e, %.2e of %.3f", vxl_phantom_name(kinds[k]),
                   vxl_filter_name(filters[f]), eb, es, gmax);
        }
    }
    for (int i = 0; i < 3; i++) vxl_renderer_destroy(all[i]);
}

TEST(sparse_follows_the_transfer_function)
{
    vxl_renderer *rd = make_stored(VXL_STORAGE_DENSE, 0, 0), *rs = make_stored(VXL_STORAGE_SPARSE, 8, 0);
    REQUIRE(rd && rs);
    vxl_volume *v = make_volume_f32(96, 96, 96, three_blobs, NULL);
    REQUIRE(v);
    REQUIRE(vxl_renderer_set_volume(rd, v) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(rs, v) == VXL_OK);
    vxl_volume_destroy(v);
    static float d[W * H * 4], s[W * H * 4];
    uint32_t resident[2], data_pages = 0;
    const float lows[2] = {0.6f, 0.02f}; /* a narrow window, then one that shows the faint tails */
    for (int i = 0; i < 2; i++) {
        /* every filter and mode: the derived filters' bricks are made only
         * near visible samples, from the CPU bricks */
        for (uint32_t run = 0; run < STORAGE_RUNS; run++) {
            vxl_render_params p = storage_run(run);
            p.window_low = lows[i];
            REQUIRE(vxl_render(rd, &p, d, NULL) == VXL_OK);
            CHECKF(vxl_render(rs, &p, s, NULL) == VXL_OK, "%s", vxl_last_error());
            vxl_render_stats st = stats_of(rs);
            if (run == VXL_FILTER_SOBEL26) resident[i] = st.pages_resident;
            data_pages = st.pages_total - st.pages_constant;
            double q = image_psnr(s, d, W * H * 4);
            fprintf(stderr, "    window low %.2f, %-11s run %2u: %u of %u bricks resident (%u constant), %.1f dB\n",
                    lows[i], vxl_filter_name(p.filter), run, st.pages_resident, st.pages_total, st.pages_constant, q);
            CHECKF(q >= 60, "window low %.2f run %u: %.1f dB", lows[i], run, q);
        }
    }
    CHECKF(resident[0] < resident[1], "resident %u then %u", resident[0], resident[1]);
    CHECKF(resident[0] < data_pages / 2, "%u of %u data bricks resident", resident[0], data_pages);
    vxl_renderer_destroy(rd);
    vxl_renderer_destroy(rs);
}

/* A ramp along (1,2,3): every brick face is crossed; the gradient of every
 * filter must be the ramp's at brick faces, inside the ghost reach and in
 * the middle of bricks, bricked and sparse, and the shaded image must equal
 * the dense one. */
TEST(no_seams_on_a_ramp_across_brick_edges)
{
    const double prm[4] = {0.01, 0.02, 0.03, 0.0}, g[3] = {0.01, 0.02, 0.03};
    vxl_volume *v = make_volume_f32(40, 40, 24, field_ramp, prm);
    REQUIRE(v);
    vxl_renderer *rd = make_stored(VXL_STORAGE_DENSE, 0, 0), *rb = make_stored(VXL_STORAGE_BRICKED, 8, 0),
                 *rs = make_stored(VXL_STORAGE_SPARSE, 8, 0);
    REQUIRE(rd && rb && rs);
    vxl_renderer *const paged[2] = {rb, rs};
    REQUIRE(vxl_renderer_set_volume(rd, v) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(rb, v) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(rs, v) == VXL_OK);
    vxl_volume_destroy(v);
    enum { N = 64 };
    float pts[N * 3], out[N * 3];
    for (int i = 0; i < N; i++) { /* faces at 7.5, 15.5, ...; points on, just before and after them */
        const float offs[4] = {-0.25f, 0.0f, 0.3f, 0.5f};
        pts[3 * i] = 7.5f + 8.0f * (i % 4) + offs[i % 4];
        pts[3 * i + 1] = 7.5f + 8.0f * (i / 4 % 4) + offs[(i / 4) % 4];
        pts[3 * i + 2] = 7.5f + 8.0f * (i / 16 % 2) + offs[(i / 32) % 2];
    }
    for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++) {
        for (int k = 0; k < 2; k++) {
            vxl_render_params p = scene(f, VXL_CLASSIFY_POST);
            p.gradient_store = VXL_GRADIENT_STORE_32F; /* precomputed: no 8-bit rounding of the direction */
            REQUIRE(vxl_probe_gradients(paged[k], &p, pts, N, out) == VXL_OK);
            double worst = 0;
            for (int i = 0; i < N; i++) worst = fmax(worst, angle_deg(out + 3 * i, g));
            CHECKF(worst < 0.01, "%s %s: %.4f degrees off the ramp at a brick edge", k ? "sparse" : "bricked",
                   vxl_filter_name(f), worst);
            static float d[W * H * 4], b[W * H * 4];
            p.has_window = 1;
            p.window_low = 0.3f;
            p.window_high = 1.5f;
            p.preset = VXL_PRESET_GRAY;
            REQUIRE(vxl_render(rd, &p, d, NULL) == VXL_OK);
            CHECKF(vxl_render(paged[k], &p, b, NULL) == VXL_OK, "%s", vxl_last_error());
            double q = image_psnr(b, d, W * H * 4);
            CHECKF(q >= 60, "%s %s: ramp %.1f dB", k ? "sparse" : "bricked", vxl_filter_name(f), q);
        }
    }
    vxl_renderer_destroy(rd);
    vxl_renderer_destroy(rb);
    vxl_renderer_destroy(rs);
}

static double ball_row(double x, double y, double z, const double *p)
{
    (void)p;
    const double c[3] = {fmod(x, 300.0) - 150.0, y - 12, z - 12};
    return exp(-(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / 50.0);
}

TEST(over_the_texture_limit_renders_bricked)
{
    vxl_renderer *ra = make_stored(VXL_STORAGE_AUTO, 0, 0), *rd = make_stored(VXL_STORAGE_DENSE, 0, 0),
                 *rs = make_stored(VXL_STORAGE_SPARSE, 0, 0);
    REQUIRE(ra && rd && rs);
    vxl_renderer_info info = {.struct_size = sizeof info};
    vxl_renderer_get_info(ra, &info);
    uint32_t nx = (uint32_t)info.max_3d_texture_size + 52;
    vxl_volume *v = make_volume_f32(nx, 24, 24, ball_row, NULL);
    REQUIRE(v);
    CHECK(vxl_renderer_set_volume(rd, v) == VXL_ERR_LIMIT);
    CHECKF(strstr(vxl_last_error(), "texture limit") != NULL, "%s", vxl_last_error());
    REQUIRE(vxl_renderer_set_volume(ra, v) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(rs, v) == VXL_OK);
    vxl_volume_destroy(v);
    enum { WW = 256, WH = 256 }; /* 8 voxels a pixel: each ball covers a few pixels */
    static float a[WW * WH * 4], s[WW * WH * 4];
    vxl_render_params p = scene(VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
    p.width = WW;
    p.height = WH;
    p.window_low = 0.3f;
    p.window_high = 1.0f;
    p.azimuth_deg = p.elevation_deg = 0;
    REQUIRE(vxl_render(ra, &p, a, NULL) == VXL_OK);
    REQUIRE(vxl_render(rs, &p, s, NULL) == VXL_OK);
    vxl_render_stats sa = stats_of(ra), ss = stats_of(rs);
    CHECK(sa.storage == VXL_STORAGE_BRICKED);
    CHECK(image_is_sane(a, NULL, WW * WH));
    CHECKF(alpha_sum(a, WW * WH) > 1, "alpha sum %g", alpha_sum(a, WW * WH));
    double q = image_psnr(s, a, WW * WH * 4);
    CHECKF(q >= 60, "sparse vs bricked %.1f dB", q);
    /* AUTO with a budget that all the bricks exceed but the visible ones
     * fit: sparse, the same image, instead of a refusal */
    vxl_renderer *rb = make_stored(VXL_STORAGE_AUTO, 0, ss.resident_bytes + (sa.resident_bytes - ss.resident_bytes) / 2);
    REQUIRE(rb);
    CHECKF(ss.resident_bytes < sa.resident_bytes, "sparse %llu vs bricked %llu bytes",
           (unsigned long long)ss.resident_bytes, (unsigned long long)sa.resident_bytes);
    v = make_volume_f32(nx, 24, 24, ball_row, NULL);
    REQUIRE(v);
    CHECKF(vxl_renderer_set_volume(rb, v) == VXL_OK, "%s", vxl_last_error());
    vxl_volume_destroy(v);
    static float b[WW * WH * 4];
    CHECKF(vxl_render(rb, &p, b, NULL) == VXL_OK, "%s", vxl_renderer_error(rb));
    vxl_render_stats sb = stats_of(rb);
    CHECK(sb.storage == VXL_STORAGE_SPARSE && sb.lod_level == 0);
    q = image_psnr(b, a, WW * WH * 4);
    CHECKF(q >= 60, "auto-sparse vs bricked %.1f dB", q);
    vxl_renderer_destroy(rb);
    fprintf(stderr, "    %ux24x24: bricked %u/%u bricks, %.2f MiB; sparse %u, %.2f MiB\n", nx, sa.pages_resident,
            sa.pages_total, sa.resident_bytes / 1048576.0, ss.pages_resident, ss.resident_bytes / 1048576.0);
    CHECK(ss.resident_bytes < sa.resident_bytes);
    vxl_renderer_destroy(ra);
    vxl_renderer_destroy(rd);
    vxl_renderer_destroy(rs);
}

TEST(budgets_and_unsupported_modes_fail_clearly)
{
    vxl_volume *v = make_volume_f32(96, 96, 96, three_blobs, NULL);
    REQUIRE(v);
    /* 64 KiB cannot hold the data bricks: bricked refuses, naming the budget */
    vxl_renderer *rb = make_stored(VXL_STORAGE_BRICKED, 8, 64 << 10);
    REQUIRE(rb);
    CHECK(vxl_renderer_set_volume(rb, v) == VXL_ERR_LIMIT);
    CHECKF(strstr(vxl_last_error(), "memory budget") != NULL, "%s", vxl_last_error());
    vxl_renderer_destroy(rb);
    /* sparse holds what a narrow window shows and says so when a wide one
     * overflows: the budget lies between the two, measured unbudgeted */
    static float img[W * H * 4];
    vxl_render_params p = scene(VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
    p.window_low = 0.7f;
    vxl_renderer *rs = make_stored(VXL_STORAGE_SPARSE, 8, 0);
    REQUIRE(rs);
    REQUIRE(vxl_renderer_set_volume(rs, v) == VXL_OK);
    REQUIRE(vxl_render(rs, &p, img, NULL) == VXL_OK);
    uint64_t narrow = stats_of(rs).resident_bytes;
    vxl_renderer_destroy(rs);
    rs = make_stored(VXL_STORAGE_SPARSE, 8, narrow + 4096);
    REQUIRE(rs);
    REQUIRE(vxl_renderer_set_volume(rs, v) == VXL_OK);
    CHECKF(vxl_render(rs, &p, img, NULL) == VXL_OK, "%s", vxl_last_error());
    CHECK(stats_of(rs).resident_bytes == narrow);
    CHECK(stats_of(rs).lod_level == 0 && stats_of(rs).lod_wanted_bytes == 0);
    /* a window that shows the far tails wants more than the budget: the
     * frame falls back to a coarser level, says so, and stays close */
    p.window_low = 1e-6f;
    p.window_high = 1e-5f;
    static float coarse[W * H * 4], full[W * H * 4];
    CHECKF(vxl_render(rs, &p, coarse, NULL) == VXL_OK, "%s", vxl_last_error());
    vxl_render_stats sl = stats_of(rs);
    vxl_renderer *rd = make_stored(VXL_STORAGE_DENSE, 0, 0);
    REQUIRE(rd);
    REQUIRE(vxl_renderer_set_volume(rd, v) == VXL_OK);
    REQUIRE(vxl_render(rd, &p, full, NULL) == VXL_OK);
    double q = image_psnr(coarse, full, W * H * 4);
    fprintf(stderr, "    LOD fallback: level %u, %.1f KiB resident (full resolution wanted %.1f KiB, budget %.1f KiB), "
            "%.1f dB against full resolution\n", sl.lod_level, sl.resident_bytes / 1024.0, sl.lod_wanted_bytes / 1024.0,
            (narrow + 4096) / 1024.0, q);
    CHECK(sl.lod_level >= 1 && sl.lod_wanted_bytes > narrow + 4096 && sl.resident_bytes <= narrow + 4096);
    CHECKF(q >= 20, "LOD image %.1f dB from full resolution", q);
    /* back to the narrow window: full resolution again */
    p.window_low = 0.7f;
    p.window_high = 0.75f;
    REQUIRE(vxl_render(rs, &p, img, NULL) == VXL_OK);
    CHECK(stats_of(rs).lod_level == 0);
    /* the derived filters and pre-classification fall back too, their pools
     * made from the coarser level's own bricks and counted in the budget */
    p.window_low = 1e-6f;
    p.window_high = 1e-5f;
    const uint32_t derived[3] = {VXL_FILTER_CUBIC, VXL_FILTER_PRECOMPUTED, VXL_FILTER_CENTRAL};
    for (int i = 0; i < 3; i++) {
        vxl_render_params q = p;
        q.filter = derived[i];
        q.classify = i == 2 ? VXL_CLASSIFY_PRE : VXL_CLASSIFY_POST;
        REQUIRE(vxl_render(rd, &q, full, NULL) == VXL_OK);
        CHECKF(vxl_render(rs, &q, coarse, NULL) == VXL_OK, "%s", vxl_last_error());
        vxl_render_stats sd = stats_of(rs);
        double qq = image_psnr(coarse, full, W * H * 4);
        fprintf(stderr, "    LOD fallback, %s%s: level %u, %.1f dB against full resolution\n", vxl_filter_name(q.filter),
                i == 2 ? " pre-classified" : "", sd.lod_level, qq);
        CHECK(sd.lod_level >= 1);
        /* 4x coarser per axis when the derived pool must fit too: the
         * shape stays (15 dB), the fine detail goes */
        CHECKF(qq >= 15, "LOD %s: %.1f dB", vxl_filter_name(q.filter), qq);
    }
    vxl_renderer_destroy(rd);
    vxl_renderer_destroy(rs);
    vxl_volume_destroy(v);
}

/* A volume from memory on three renderers: dense, compressed (deferred
 * filtering) and compressed filtered in the compressed domain. */
static int dense_and_compressed(const vxl_volume_desc *vd, vxl_renderer *out[3])
{
    out[0] = make_stored(VXL_STORAGE_DENSE, 0, 0);
    out[1] = make_stored(VXL_STORAGE_COMPRESSED, 8, 0);
    out[2] = make_stored_in(VXL_STORAGE_COMPRESSED, 8, 0, 1);
    vxl_volume *v = NULL;
    return out[0] && out[1] && out[2] && vxl_volume_create(vd, NULL, &v) == VXL_OK && set_each(out, 3, v);
}

/* Irregular 8-bit levels: every brick has <= 256 values, so the palette is
 * exact and compressed storage renders what dense renders. Filtering the
 * codes instead of the values would not: value = palette[code] is not
 * linear in the code. Between a voxel of code 0 (value 0) and one of code 3
 * (value 255) the filtered value is 127.5, but the filtered code 1.5 lies
 * between palette entries 3 and 250 (126.5 interpolating the palette, 250
 * rounding the code): wrong, and on other pairs by far more. */
static const double levels4[4] = {0, 3, 250, 255};
static double stripes(double x, double y, double z, const double *p)
{
    (void)p;
    return levels4[((int)x / 3 + (int)y / 5 + (int)z / 7) % 4] / 255.0;
}

TEST(compressed_is_exact_on_8bit_levels_and_codes_cannot_be_filtered)
{
    /* the arithmetic of the comment above, for every pair of codes */
    double worst = 0;
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++) {
            double value = 0.5 * (levels4[a] + levels4[b]), code = 0.5 * (a + b);
            double decoded = levels4[(int)(code + 0.5)]; /* decoding a filtered code */
            worst = fabs(decoded - value) > worst ? fabs(decoded - value) : worst;
        }
    fprintf(stderr, "    filtering the codes: worst error %.1f of 255 at a midpoint\n", worst);
    CHECK(worst > 100);
    /* an 8-bit volume of those levels */
    const uint32_t n[3] = {45, 40, 37};
    static uint8_t raw[45 * 40 * 37];
    for (uint32_t z = 0; z < n[2]; z++)
        for (uint32_t y = 0; y < n[1]; y++)
            for (uint32_t i = 0; i < n[0]; i++)
                raw[i + n[0] * (y + n[1] * z)] = (uint8_t)(stripes(i, y, z, NULL) * 255 + 0.5);
    vxl_volume_desc vd = {.struct_size = sizeof vd, .dtype = VXL_DTYPE_U8, .dims = {n[0], n[1], n[2]}, .data = raw};
    vxl_renderer *all[3];
    REQUIRE(dense_and_compressed(&vd, all));
    vxl_renderer *const rd = all[0], *const rc = all[1], *const rx = all[2];
    static float d[W * H * 4], c[W * H * 4], x[W * H * 4];
    float *const imgs[3] = {d, c, x};
    for (uint32_t f = 0; f <= VXL_FILTER_SOBEL26; f++) {
        vxl_render_params p = scene(f, VXL_CLASSIFY_POST);
        p.window_low = 0.0f;
        p.window_high = 1.0f;
        REQUIRE(render_each(all, imgs, 3, &p));
        double qc = image_psnr(c, d, W * H * 4), qx = image_psnr(x, d, W * H * 4);
        fprintf(stderr, "    8-bit levels %-8s: compressed %6.1f dB, compressed domain %6.1f dB vs dense\n",
                vxl_filter_name(f), qc, qx);
        /* deferred filtering samples an R8 cache exactly as dense samples
         * its R8 texture; the compressed domain weights the 8 decoded
         * values in float, while llvmpipe filters 8-bit textures with
         * coarser fixed-point weights, which these 0/255 steps expose (on
         * the float phantoms above the two agree to 89-127 dB) */
        CHECKF(qc >= 60 && qx >= 30, "%s: %.1f / %.1f dB", vxl_filter_name(f), qc, qx);
        CHECK(alpha_sum(d, W * H) > 1);
    }
    vxl_renderer_destroy(rd);
    vxl_renderer_destroy(rc);
    vxl_renderer_destroy(rx);
}

/* 16-bit data with more than 256 values per brick: the histogram + Lloyd
 * path with integer levels, so the R16 cache holds the palette exactly
 * (compressed domain and deferred agree) and the image stays close to dense. */
TEST(compressed_16bit_fits_integer_levels)
{
    const uint32_t n[3] = {45, 40, 37};
    static uint16_t raw[45 * 40 * 37];
    for (uint32_t z = 0; z < n[2]; z++)
        for (uint32_t y = 0; y < n[1]; y++)
            for (uint32_t i = 0; i < n[0]; i++)
                raw[i + n[0] * (y + n[1] * z)] = (uint16_t)(30000 + 20000 * sin(i / 5.0) * cos(y / 7.0) + 300.0 * z);
    vxl_volume_desc vd = {.struct_size = sizeof vd, .dtype = VXL_DTYPE_U16, .dims = {n[0], n[1], n[2]}, .data = raw};
    vxl_renderer *all[3];
    REQUIRE(dense_and_compressed(&vd, all));
    vxl_renderer *const rd = all[0], *const rc = all[1], *const rx = all[2];
    static float d[W * H * 4], c[W * H * 4], x[W * H * 4];
    float *const imgs[3] = {d, c, x};
    vxl_render_params p = scene(VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
    p.has_window = 0;
    REQUIRE(render_each(all, imgs, 3, &p));
    double qc = image_psnr(c, d, W * H * 4), qx = image_psnr(x, c, W * H * 4);
    fprintf(stderr, "    16-bit: compressed %.1f dB vs dense, compressed domain %.1f dB vs deferred\n", qc, qx);
    CHECK(alpha_sum(d, W * H) > 1);
    CHECKF(qc >= 50 && qx >= 60, "%.1f / %.1f dB", qc, qx);
    vxl_renderer_destroy(rd);
    vxl_renderer_destroy(rc);
    vxl_renderer_destroy(rx);
}

/* Compressed storage's budget covers codes, palettes and the decode cache:
 * too small for the codes, set_volume refuses; room for the codes but not
 * for the visible bricks' cache, the frame fails; both name the budget. */
TEST(compressed_budget_counts_codes_and_cache)
{
    vxl_renderer *rx = make_stored_in(VXL_STORAGE_COMPRESSED, 8, 0, 1), *tiny = make_stored(VXL_STORAGE_COMPRESSED, 8, 4096);
    REQUIRE(rx && tiny);
    vxl_renderer *const one[1] = {rx};
    REQUIRE(set_phantom(one, 1, VXL_PHANTOM_MARSCHNER_LOBB));
    vxl_render_params p = scene(VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
    static float img[W * H * 4];
    REQUIRE(vxl_render(rx, &p, img, NULL) == VXL_OK);
    const uint64_t codes = stats_of(rx).resident_bytes; /* codes + palettes + page table */
    vxl_renderer *const small[1] = {tiny};
    CHECK(!set_phantom(small, 1, VXL_PHANTOM_MARSCHNER_LOBB));
    CHECKF(strstr(vxl_renderer_error(tiny), "memory budget") != NULL, "%s", vxl_renderer_error(tiny));
    vxl_renderer *rc = make_stored(VXL_STORAGE_COMPRESSED, 8, codes + 8192);
    REQUIRE(rc);
    vxl_renderer *const mid[1] = {rc};
    CHECKF(set_phantom(mid, 1, VXL_PHANTOM_MARSCHNER_LOBB), "%s", vxl_renderer_error(rc));
    CHECK(vxl_render(rc, &p, img, NULL) != VXL_OK);
    fprintf(stderr, "    codes %.1f KiB; %s\n", codes / 1024.0, vxl_renderer_error(rc));
    CHECKF(strstr(vxl_renderer_error(rc), "memory budget") != NULL, "%s", vxl_renderer_error(rc));
    vxl_renderer_destroy(rx);
    vxl_renderer_destroy(tiny);
    vxl_renderer_destroy(rc);
}

int main(void)
{
    RUN(every_storage_equals_dense);
    RUN(precomputed_gradients_bricked_and_sparse_equal_dense);
    RUN(derived_filters_probe_as_dense);
    RUN(sparse_follows_the_transfer_function);
    RUN(no_seams_on_a_ramp_across_brick_edges);
    RUN(over_the_texture_limit_renders_bricked);
    RUN(budgets_and_unsupported_modes_fail_clearly);
    RUN(compressed_is_exact_on_8bit_levels_and_codes_cannot_be_filtered);
    RUN(compressed_16bit_fits_integer_levels);
    RUN(compressed_budget_counts_codes_and_cache);
    return TEST_SUMMARY();
}
