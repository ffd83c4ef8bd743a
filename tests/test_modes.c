/* test_modes.c - the render modes and the MatCap
 * (shaders/lib/modes.glsl, lib/matcap.glsl, csrc/render/modes.c, matcap.c,
 * csrc/frame/frame_mode.c): through an orthographic axis view whose pixels
 * are one voxel wide (csrc/cli/axis_view.h), MIP, MinIP and average equal
 * the max, min and mean of the voxels along the axis; ISO finds an analytic
 * sphere to a tenth of a voxel; a MatCap colours each side of a sphere by
 * its half of the image; brick skipping changes no result; every storage
 * mode projects the same; MinIP's floor keeps only samples at or above it;
 * bad input is refused naming the field. */
#include <stdio.h>

#include "axis_view.h"
#include "harness.h"
#include "test_util.h"

#define NX 24
#define NY 20
#define NZ 16
#define TF_N 4096
#define S 40 /* sphere volume side */

static vxl_renderer *R;
static vxl_volume *NOISE, *SPHERE;
static float TF[TF_N * 4];
static float VOX[NX * NY * NZ];
static const double CENTRE[3] = {19.3, 19.6, 19.45}, RADIUS = 12;

/* Noise quantised to 64 levels, so compressed storage's palettes hold it exactly. */
static double noise(double x, double y, double z, const double *prm)
{
    (void)prm;
    uint32_t h = (uint32_t)x * 73856093u ^ (uint32_t)y * 19349663u ^ (uint32_t)z * 83492791u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return (double)((h >> 7) % 64) / 63.0;
}

static double distance_field(double x, double y, double z, const double *prm)
{
    (void)prm;
    return sqrt((x - CENTRE[0]) * (x - CENTRE[0]) + (y - CENTRE[1]) * (y - CENTRE[1]) + (z - CENTRE[2]) * (z - CENTRE[2]));
}

/* The grey ramp: colour = the windowed value, opacity 1. */
static void ramp(float *tf, int n)
{
    for (int i = 0; i < n; i++) {
        float x = (float)i / (float)(n - 1);
        tf[4 * i] = tf[4 * i + 1] = tf[4 * i + 2] = x;
        tf[4 * i + 3] = 1;
    }
}

/* An orthographic view along `view` (axis_view.h) of vol, pixels one voxel wide. */
static vxl_render_params axis_params(const vxl_volume *vol, int view, uint32_t mode, uint32_t *w, uint32_t *h)
{
    vxl_volume_info in = {.struct_size = sizeof in};
    vxl_volume_get_info(vol, &in);
    double lo[3], hi[3], back[3], right[3], up[3];
    vxl_axis_view_box(in.dims, in.affine, lo, hi);
    vxl_axis_view_frame(view, back, right, up);
    *w = *h = 0;
    for (int a = 0; a < 3; a++) {
        *w += (uint32_t)lround(fabs(right[a]) * (hi[a] - lo[a]));
        *h += (uint32_t)lround(fabs(up[a]) * (hi[a] - lo[a]));
    }
    vxl_render_params p = default_params(*w, *h);
    p.has_camera = 1;
    vxl_axis_view_camera(view, 1, lo, hi, *w, *h, p.view, p.proj);
    p.mode = mode;
    p.jitter_off = 1;
    p.step = 0.5f;
    p.tf_rgba = TF;
    p.tf_size = TF_N;
    p.has_window = 1;
    p.window_low = 0;
    p.window_high = 1;
    return p;
}

static int render(vxl_renderer *r, const vxl_render_params *p, float *img, float *depth)
{
    int rc = vxl_render(r, p, img, depth);
    if (rc) fprintf(stderr, "    render failed: %s\n", vxl_renderer_error(r));
    return rc;
}

/* The voxel (x, y, z) under pixel (px, py) of view at depth index k from
 * the eye (voxel space = world here: the volumes have the identity affine). */
static void pixel_voxel(int view, uint32_t w, uint32_t h, uint32_t px, uint32_t py, uint32_t k, const uint32_t dims[3],
                        int v[3])
{
    double back[3], right[3], up[3];
    vxl_axis_view_frame(view, back, right, up);
    for (int a = 0; a < 3; a++) {
        double c = 0.5 * (dims[a] - 1.0);
        double pos = c + right[a] * (px + 0.5 - 0.5 * w) + up[a] * (py + 0.5 - 0.5 * h);
        if (back[a] != 0) pos = back[a] > 0 ? dims[a] - 1.0 - k : k; /* from the eye's side inwards */
        v[a] = (int)lround(pos);
    }
}

static double view_depth(const float *view, const double x[3])
{
    return -(view[2] * x[0] + view[6] * x[1] + view[10] * x[2] + view[14]);
}

TEST(projections_equal_max_min_mean_along_the_axis)
{
    const int views[3] = {4, 0, 3}; /* z, x, -y */
    const uint32_t dims[3] = {NX, NY, NZ};
    static float img[NX * NY * 4 * 2], depth[NX * NY * 2];
    for (int vi = 0; vi < 3; vi++)
        for (uint32_t mode = VXL_MODE_MIP; mode <= VXL_MODE_AVERAGE; mode++) {
            uint32_t w, h;
            vxl_render_params p = axis_params(NOISE, views[vi], mode, &w, &h);
            REQUIRE(w * h <= NX * NY * 2);
            REQUIRE(render(R, &p, img, depth) == VXL_OK);
            int axis = views[vi] / 2, bad = 0;
            uint32_t n = dims[axis];
            double worst = 0;
            for (uint32_t py = 0; py < h; py++)
                for (uint32_t px = 0; px < w; px++) {
                    double mx = -1, mn = 2, sum = 0, first = 0, last = 0;
                    for (uint32_t k = 0; k < n; k++) {
                        int v[3];
                        pixel_voxel(views[vi], w, h, px, py, k, dims, v);
                        double x = VOX[v[0] + NX * (v[1] + NY * v[2])];
                        mx = x > mx ? x : mx;
                        mn = x < mn ? x : mn;
                        sum += x;
                        if (k == 0) first = x;
                        last = x;
                    }
                    const float *px4 = img + 4 * (py * w + px);
                    double got = px4[0], want, tol = 2e-3;
                    if (mode == VXL_MODE_MIP) want = mx;
                    else if (mode == VXL_MODE_MINIP) want = mn;
                    else { /* the step-0.5 samples weigh the two end voxels differently (docs/modes.md) */
                        want = sum / n;
                        tol += fabs(first - last) / (4.0 * n);
                    }
                    double err = fabs(got - want);
                    worst = err > worst ? err : worst;
                    if (err > tol || fabs(px4[3] - 1) > 1e-6) bad++;
                    if (mode != VXL_MODE_AVERAGE) { /* depth: at a voxel holding the projected value */
                        int at_one = 0;
                        for (uint32_t k = 0; k < n; k++) {
                            int v[3];
                            pixel_voxel(views[vi], w, h, px, py, k, dims, v);
                            double x[3] = {v[0], v[1], v[2]};
                            /* the first voxel's value is also the sample's on the entry face, half a voxel nearer */
                            double got = depth[py * w + px], want = view_depth(p.view, x);
                            int here = fabs(got - want) < 1e-2 || (k == 0 && fabs(got - (want - 0.5)) < 1e-2);
                            if (here && VOX[v[0] + NX * (v[1] + NY * v[2])] == (mode == VXL_MODE_MIP ? mx : mn))
                                at_one = 1;
                        }
                        if (!at_one) bad++;
                    }
                }
            fprintf(stderr, "    view %d %s: worst |error| %.5f\n", views[vi], vxl_mode_name(mode), worst);
            CHECKF(bad == 0, "view %d mode %s: %d pixels off", views[vi], vxl_mode_name(mode), bad);
        }
}

/* The modes see only the kept volume: a clip plane keeping z <= 7 (through
 * voxel centres, so the first sample is voxel 7's) leaves the max and min of
 * voxels 0..7 along z. */
TEST(projections_see_only_the_kept_side_of_a_clip_plane)
{
    static float img[NX * NY * 4];
    const uint32_t dims[3] = {NX, NY, NZ};
    for (uint32_t mode = VXL_MODE_MIP; mode <= VXL_MODE_MINIP; mode++) {
        uint32_t w, h;
        vxl_render_params p = axis_params(NOISE, 4, mode, &w, &h);
        vxl_cutaway cut = {.struct_size = sizeof cut, .clip_plane_count = 1};
        cut.clip_planes[0] = (vxl_clip_plane){.plane = {0, 0, -1, 7}};
        p.cutaway = &cut;
        REQUIRE(render(R, &p, img, NULL) == VXL_OK);
        int bad = 0;
        for (uint32_t py = 0; py < h; py++)
            for (uint32_t px = 0; px < w; px++) {
                double want = mode == VXL_MODE_MIP ? -1 : 2;
                for (uint32_t k = NZ - 8; k < NZ; k++) { /* from the eye: z = NZ - 1 - k */
                    int v[3];
                    pixel_voxel(4, w, h, px, py, k, dims, v);
                    double x = VOX[v[0] + NX * (v[1] + NY * v[2])];
                    want = mode == VXL_MODE_MIP ? fmax(want, x) : fmin(want, x);
                }
                if (fabs(img[4 * (py * w + px)] - want) > 2e-3) bad++;
            }
        CHECKF(bad == 0, "%s: %d pixels off", vxl_mode_name(mode), bad);
    }
}

/* A cutter (a closed cube mesh, depth-peeled by csrc/cut/) around the whole
 * volume: removing its inside leaves every mode nothing; keeping only its
 * inside leaves each image as it is without the cutter. */
TEST(a_cutter_around_the_volume_removes_all_or_nothing)
{
    static float a[NX * NY * 4], b[NX * NY * 4];
    float v[8 * 3];
    for (int c = 0; c < 8; c++) { /* x in [-2, NX + 1], y in [-2, NY + 1], z in [-1, NZ] */
        v[3 * c] = (c & 1) ? NX + 1.0f : -2.0f;
        v[3 * c + 1] = (c & 2) ? NY + 1.0f : -2.0f;
        v[3 * c + 2] = (c & 4) ? (float)NZ : -1.0f;
    }
    const uint32_t tri[36] = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                              2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6}; /* outward */
    vxl_cutter cube = {.struct_size = sizeof cube, .vertices = v, .indices = tri, .vertex_count = 8, .triangle_count = 12};
    vxl_cutaway cut = {.struct_size = sizeof cut, .cutter_count = 1, .cutters = &cube};
    for (uint32_t mode = VXL_MODE_MIP; mode <= VXL_MODE_ISO; mode++) {
        uint32_t w, h;
        vxl_render_params p = axis_params(NOISE, 4, mode, &w, &h);
        p.iso_value = 0.5f;
        REQUIRE(render(R, &p, a, NULL) == VXL_OK);
        p.cutaway = &cut;
        cube.remove_outside = 0;
        REQUIRE(render(R, &p, b, NULL) == VXL_OK);
        CHECKF(alpha_sum(b, (size_t)w * h) == 0, "%s: the removed inside shows (alpha sum %g)", vxl_mode_name(mode),
               alpha_sum(b, (size_t)w * h));
        cube.remove_outside = 1;
        REQUIRE(render(R, &p, b, NULL) == VXL_OK);
        double diff = 0;
        for (uint32_t i = 0; i < 4 * w * h; i++) diff = fmax(diff, fabs(a[i] - b[i]));
        CHECKF(diff < 1e-5, "%s: keeping the inside changed the image by %g", vxl_mode_name(mode), diff);
    }
}

/* ISO depth against the analytic sphere |x - CENTRE| = RADIUS, seen from +z. */
static double iso_depth_error(float step, uint32_t filter, double *mean_err, int *covered_ok)
{
    uint32_t w, h;
    vxl_render_params p = axis_params(SPHERE, 4, VXL_MODE_ISO, &w, &h);
    p.iso_value = (float)RADIUS;
    p.step = step;
    p.filter = filter;
    p.window_high = 2 * (float)RADIUS;
    static float img[S * S * 4], depth[S * S];
    if (render(R, &p, img, depth)) return 1e9;
    double worst = 0, sum = 0;
    int n = 0, cover = 1;
    for (uint32_t py = 0; py < h; py++)
        for (uint32_t px = 0; px < w; px++) {
            double x = px, y = py, rho2 = (x - CENTRE[0]) * (x - CENTRE[0]) + (y - CENTRE[1]) * (y - CENTRE[1]);
            float a = img[4 * (py * w + px) + 3];
            if (rho2 > (RADIUS + 1) * (RADIUS + 1)) {
                if (a != 0 || !isinf(depth[py * w + px])) cover = 0;
                continue;
            }
            if (rho2 > (RADIUS - 1.5) * (RADIUS - 1.5)) continue; /* grazing rays */
            double hit[3] = {x, y, CENTRE[2] + sqrt(RADIUS * RADIUS - rho2)};
            double err = fabs(depth[py * w + px] - view_depth(p.view, hit));
            if (a != 1) cover = 0;
            worst = err > worst ? err : worst;
            sum += err;
            n++;
        }
    *mean_err = n ? sum / n : 1e9;
    *covered_ok = cover;
    return worst;
}

TEST(iso_depth_matches_the_sphere_to_a_tenth_of_a_voxel)
{
    double mean;
    int cover;
    double worst = iso_depth_error(0.5f, VXL_FILTER_CENTRAL, &mean, &cover);
    fprintf(stderr, "    step 0.5: worst %.4f, mean %.4f voxels\n", worst, mean);
    CHECKF(worst < 0.1, "worst depth error %.4f voxels", worst);
    CHECK(cover);
    /* the hit is refined on the trilinear field whatever the gradient filter */
    for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++) {
        double m;
        int c;
        double e = iso_depth_error(0.5f, f, &m, &c);
        CHECKF(e < 0.1 && c, "filter %s: worst %.4f", vxl_filter_name(f), e);
    }
}

TEST(iso_converges_as_the_step_shrinks)
{
    const float steps[4] = {3.0f, 1.0f, 0.5f, 0.125f};
    double mean[4], worst[4];
    for (int i = 0; i < 4; i++) {
        int cover;
        worst[i] = iso_depth_error(steps[i], VXL_FILTER_CENTRAL, &mean[i], &cover);
        fprintf(stderr, "    step %.3f: worst %.4f, mean %.4f voxels\n", steps[i], worst[i], mean[i]);
        CHECK(cover);
        CHECKF(worst[i] < 0.1, "step %g: worst %.4f", steps[i], worst[i]);
    }
    /* refinement leaves the interpolant's own error: shrinking the step never makes it worse */
    for (int i = 1; i < 4; i++) CHECKF(mean[i] <= mean[0] + 2e-3, "step %g mean %.4f vs %.4f", steps[i], mean[i], mean[0]);
}

/* Red on the image's left half, green on its right. */
static void two_halves(float *m, int n, int swap)
{
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            float *t = m + 4 * (j * n + i);
            int left = (i < n / 2) != swap;
            t[0] = left ? 1.0f : 0.0f;
            t[1] = left ? 0.0f : 1.0f;
            t[2] = 0;
            t[3] = 1;
        }
}

/* Mean colour of the sphere's pixels whose normal leans left (side 0) or right (side 1). */
static void side_colour(const float *img, uint32_t w, uint32_t h, int side, double rgb[3])
{
    double n = 0;
    rgb[0] = rgb[1] = rgb[2] = 0;
    for (uint32_t py = 0; py < h; py++)
        for (uint32_t px = 0; px < w; px++) {
            double dx = (px - CENTRE[0]) / RADIUS, dy = (py - CENTRE[1]) / RADIUS;
            if (dx * dx + dy * dy > 0.8 || (side ? dx < 0.5 : dx > -0.5)) continue;
            const float *c = img + 4 * (py * w + px);
            if (c[3] < 0.99f) continue;
            for (int k = 0; k < 3; k++) rgb[k] += c[k] / c[3];
            n++;
        }
    for (int k = 0; n && k < 3; k++) rgb[k] /= n;
}

TEST(a_matcap_colours_each_side_of_a_sphere)
{
    enum { M = 64 };
    static float cap[M * M * 4], img[S * S * 4];
    two_halves(cap, M, 0);
    vxl_matcap mc = {.struct_size = sizeof mc, .width = M, .height = M, .rgba = cap, .key = 0};
    float opaque_inside[8] = {1, 1, 1, 1, 1, 1, 1, 0}; /* r < RADIUS (window [0, 2R]) is opaque */
    float white[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    for (uint32_t mode = VXL_MODE_DVR; mode <= VXL_MODE_ISO; mode += VXL_MODE_ISO) {
        uint32_t w, h;
        vxl_render_params p = axis_params(SPHERE, 4, mode, &w, &h);
        p.iso_value = (float)RADIUS;
        p.window_high = 2 * (float)RADIUS;
        p.tf_rgba = white; /* the MatCap's colours as they are */
        p.tf_size = 2;
        if (mode == VXL_MODE_DVR) {
            p.tf_rgba = opaque_inside;
            p.tf_size = 2;
            p.window_low = (float)RADIUS - 0.5f;
            p.window_high = (float)RADIUS + 0.5f;
        }
        p.matcap = &mc;
        REQUIRE(render(R, &p, img, NULL) == VXL_OK);
        double l[3], r[3];
        side_colour(img, w, h, 0, l);
        side_colour(img, w, h, 1, r);
        fprintf(stderr, "    %s: left (%.2f %.2f %.2f) right (%.2f %.2f %.2f)\n", vxl_mode_name(mode), l[0], l[1], l[2],
                r[0], r[1], r[2]);
        CHECKF(l[0] > 0.8 && l[1] < 0.2 && r[1] > 0.8 && r[0] < 0.2, "%s", vxl_mode_name(mode));
        /* without it, the headlight lights both sides alike */
        p.matcap = NULL;
        REQUIRE(render(R, &p, img, NULL) == VXL_OK);
        side_colour(img, w, h, 0, l);
        side_colour(img, w, h, 1, r);
        CHECKF(fabs(l[0] - l[1]) < 0.05 && fabs(r[0] - r[1]) < 0.05 && fabs(l[0] - r[0]) < 0.1, "%s unlit by the MatCap",
               vxl_mode_name(mode));
    }
}

/* A nonzero key names the image: the same key is not uploaded again, a new
 * key or a hashed (key 0) change is. */
TEST(the_matcap_is_cached_by_its_key)
{
    enum { M = 16 };
    static float cap[M * M * 4], img[S * S * 4];
    uint32_t w, h;
    vxl_render_params p = axis_params(SPHERE, 4, VXL_MODE_ISO, &w, &h);
    p.iso_value = (float)RADIUS;
    p.window_high = 2 * (float)RADIUS;
    vxl_matcap mc = {.struct_size = sizeof mc, .width = M, .height = M, .rgba = cap, .key = 77};
    float white[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    p.tf_rgba = white;
    p.tf_size = 2;
    p.matcap = &mc;
    double l[3], r[3];
    two_halves(cap, M, 0);
    REQUIRE(render(R, &p, img, NULL) == VXL_OK);
    two_halves(cap, M, 1); /* same key, new pixels: the caller said it is the same image */
    REQUIRE(render(R, &p, img, NULL) == VXL_OK);
    side_colour(img, w, h, 0, l);
    CHECKF(l[0] > 0.8, "key 77 re-uploaded: left red %.2f", l[0]);
    mc.key = 0; /* hashed: the swap shows */
    REQUIRE(render(R, &p, img, NULL) == VXL_OK);
    side_colour(img, w, h, 0, l);
    side_colour(img, w, h, 1, r);
    CHECKF(l[1] > 0.8 && r[0] > 0.8, "hashed key missed the change: left green %.2f right red %.2f", l[1], r[0]);
}

/* Skipping bricks by their min-max (dense storage) leaves every pixel as
 * marching every sample does, with fewer samples. */
TEST(brick_skipping_changes_no_result_and_saves_samples)
{
    static float a[S * S * 4], b[S * S * 4], da[S * S], db[S * S];
    for (uint32_t mode = VXL_MODE_MIP; mode <= VXL_MODE_ISO; mode++) {
        if (mode == VXL_MODE_AVERAGE) continue; /* every sample counts */
        uint32_t w, h;
        vxl_render_params p = axis_params(SPHERE, 4, mode, &w, &h);
        p.iso_value = (float)RADIUS;
        p.window_high = 2 * (float)RADIUS;
        REQUIRE(render(R, &p, a, da) == VXL_OK);
        vxl_render_stats sa = {.struct_size = sizeof sa}, sb = {.struct_size = sizeof sb};
        REQUIRE(vxl_renderer_get_stats(R, &sa) == VXL_OK);
        p.no_skip = 1;
        REQUIRE(render(R, &p, b, db) == VXL_OK);
        REQUIRE(vxl_renderer_get_stats(R, &sb) == VXL_OK);
        double diff = 0, ddiff = 0;
        for (uint32_t i = 0; i < w * h; i++) {
            for (int c = 0; c < 4; c++) diff = fmax(diff, fabs(a[4 * i + c] - b[4 * i + c]));
            if (isinf(da[i]) != isinf(db[i])) ddiff = INFINITY;
            else if (!isinf(da[i])) ddiff = fmax(ddiff, fabs(da[i] - db[i]));
        }
        fprintf(stderr, "    %s: samples %llu skipping, %llu not; max diff %.2g colour, %.2g depth\n",
                vxl_mode_name(mode), (unsigned long long)sa.samples, (unsigned long long)sb.samples, diff, ddiff);
        CHECKF(diff < 1e-6 && ddiff < 1e-4, "%s", vxl_mode_name(mode));
        CHECKF(sa.samples < sb.samples, "%s skipped nothing", vxl_mode_name(mode));
    }
}

TEST(every_storage_mode_gives_the_same_projection)
{
    static float a[NX * NY * 4], b[NX * NY * 4];
    const uint32_t storages[3] = {VXL_STORAGE_BRICKED, VXL_STORAGE_SPARSE, VXL_STORAGE_COMPRESSED};
    for (int s = 0; s < 3; s++) {
        vxl_renderer_options o = {.struct_size = sizeof o, .backend = software_backend(), .storage = storages[s],
                                  .page_brick = 8};
        vxl_renderer *r = NULL;
        REQUIRE(vxl_renderer_create(&o, &r) == VXL_OK);
        int rc = vxl_renderer_set_volume(r, NOISE);
        for (uint32_t mode = VXL_MODE_MIP; !rc && mode <= VXL_MODE_AVERAGE; mode++) {
            uint32_t w, h;
            vxl_render_params p = axis_params(NOISE, 4, mode, &w, &h);
            p.tf_rgba = TF;
            /* a table that hides most values: sparse storage must still keep every brick */
            for (int i = 0; i < TF_N / 2; i++) TF[4 * i + 3] = 0;
            rc = render(R, &p, a, NULL);
            if (!rc) rc = render(r, &p, b, NULL);
            ramp(TF, TF_N);
            double diff = 0;
            for (uint32_t i = 0; !rc && i < 4 * w * h; i++) diff = fmax(diff, fabs(a[i] - b[i]));
            CHECKF(!rc && diff < 1e-5, "%s %s: max diff %.3g", vxl_storage_name(storages[s]), vxl_mode_name(mode), diff);
        }
        vxl_render_stats st = {.struct_size = sizeof st};
        if (!rc) rc = vxl_renderer_get_stats(r, &st);
        vxl_renderer_destroy(r);
        CHECK(rc == VXL_OK && st.storage == storages[s]);
    }
}

/* Bad input: a clear VXL_ERR_INVALID_ARGUMENT naming the field, and the
 * renderer still renders afterwards. */
TEST(bad_input_is_refused_naming_the_field)
{
    enum { CASES = 11 };
    static float img[S * S * 4];
    float cap[4] = {1, 1, 1, 1};
    struct {
        const char *field;
        vxl_render_params p;
        vxl_matcap m;
        int use_matcap;
    } cases[CASES];
    int n = 0;
    uint32_t w, h;
    vxl_render_params base = axis_params(SPHERE, 4, VXL_MODE_MIP, &w, &h);
    vxl_matcap good = {.struct_size = sizeof good, .width = 1, .height = 1, .rgba = cap};
    for (int i = 0; i < CASES; i++) {
        cases[i].p = base;
        cases[i].m = good;
        cases[i].use_matcap = 0;
    }
    cases[n].field = "mode", cases[n++].p.mode = VXL_MODE_COUNT;
    cases[n].field = "iso_value", cases[n].p.mode = VXL_MODE_ISO, cases[n++].p.iso_value = NAN;
    cases[n].field = "classify", cases[n++].p.classify = VXL_CLASSIFY_PRE;
    cases[n].field = "classify", cases[n].p.mode = VXL_MODE_ISO, cases[n++].p.classify = VXL_CLASSIFY_PREINT;
    cases[n].field = "gradient_opacity", cases[n++].p.gradient_opacity = VXL_GOPACITY_BOUNDARY;
    cases[n].field = "technique", cases[n++].p.technique = VXL_TECHNIQUE_SLICES3D;
    cases[n].field = "matcap size", cases[n].use_matcap = 1, cases[n++].m.width = 0;
    cases[n].field = "matcap size", cases[n].use_matcap = 1, cases[n++].m.height = 5000;
    cases[n].field = "matcap.rgba", cases[n].use_matcap = 1, cases[n++].m.rgba = NULL;
    cases[n].field = "matcap.reserved", cases[n].use_matcap = 1, cases[n++].m.reserved = 1;
    cases[n].field = "technique raycast", cases[n].use_matcap = 1, cases[n].p.mode = VXL_MODE_DVR,
    cases[n++].p.technique = VXL_TECHNIQUE_SLICES2D;
    for (int i = 0; i < n; i++) {
        if (cases[i].use_matcap) cases[i].p.matcap = &cases[i].m;
        int rc = vxl_render(R, &cases[i].p, img, NULL);
        const char *msg = vxl_renderer_error(R);
        CHECKF(rc == VXL_ERR_INVALID_ARGUMENT && msg && strstr(msg, cases[i].field), "case %d (%s): rc %d, '%s'", i,
               cases[i].field, rc, msg ? msg : "");
    }
    /* a MatCap with shading off, or in a projection, has nothing to shade: accepted, unused */
    vxl_render_params p = base;
    p.matcap = &good;
    CHECK(render(R, &p, img, NULL) == VXL_OK);
    CHECK(render(R, &base, img, NULL) == VXL_OK);
}

/* MinIP with a floor: each pixel is the smallest sample at or above the
 * floor, so no lower than the floor and no higher than the smallest voxel at
 * or above it (samples between two voxels interpolate them); a ray whose
 * voxels all lie below the floor has no such sample and draws nothing.
 * Brick skipping (which also leaps bricks wholly below the floor) changes
 * nothing. */
TEST(minip_floor_skips_samples_below_it)
{
    const int views[3] = {4, 0, 3};
    const uint32_t dims[3] = {NX, NY, NZ};
    static float img[NX * NY * 4 * 2], ref[NX * NY * 4 * 2];
    const double floor_v = 0.975; /* between the noise's two top levels */
    for (int vi = 0; vi < 3; vi++) {
        uint32_t w, h;
        vxl_render_params p = axis_params(NOISE, views[vi], VXL_MODE_MINIP, &w, &h);
        p.minip_floor_on = 1;
        p.minip_floor = (float)floor_v;
        REQUIRE(render(R, &p, img, NULL) == VXL_OK);
        p.no_skip = 1;
        REQUIRE(render(R, &p, ref, NULL) == VXL_OK);
        int axis = views[vi] / 2, bad = 0, empty = 0, drawn = 0, differ = 0;
        for (uint32_t py = 0; py < h; py++)
            for (uint32_t px = 0; px < w; px++) {
                double mn = 2;
                for (uint32_t k = 0; k < dims[axis]; k++) {
                    int v[3];
                    pixel_voxel(views[vi], w, h, px, py, k, dims, v);
                    double x = VOX[v[0] + NX * (v[1] + NY * v[2])];
                    if (x >= floor_v && x < mn) mn = x;
                }
                const float *px4 = img + 4 * (py * w + px), *r4 = ref + 4 * (py * w + px);
                if (mn > 1) {
                    empty++;
                    if (px4[3] != 0) bad++;
                } else {
                    drawn++;
                    if (fabs(px4[3] - 1) > 1e-6 || px4[0] < floor_v - 2e-3 || px4[0] > mn + 2e-3) bad++;
                }
                if (fabs(px4[0] - r4[0]) > 1e-6 || px4[3] != r4[3]) differ++;
            }
        CHECKF(empty > 0 && drawn > 0, "view %d: %d empty, %d drawn rays (the case needs both)", views[vi], empty,
               drawn);
        CHECKF(bad == 0, "view %d: %d pixels off", views[vi], bad);
        CHECKF(differ == 0, "view %d: %d pixels differ with brick skipping", views[vi], differ);
        p.minip_floor = NAN;
        CHECK(vxl_render(R, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    }
}

int main(void)
{
    ramp(TF, TF_N);
    for (uint32_t k = 0; k < NZ; k++)
        for (uint32_t j = 0; j < NY; j++)
            for (uint32_t i = 0; i < NX; i++) VOX[i + NX * (j + NY * k)] = (float)noise(i, j, k, NULL);
    R = make_renderer(software_backend());
    NOISE = make_volume_f32(NX, NY, NZ, noise, NULL);
    SPHERE = make_volume_f32(S, S, S, distance_field, NULL);
    if (!R || !NOISE || !SPHERE || vxl_renderer_set_volume(R, NOISE) != VXL_OK) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    RUN(projections_equal_max_min_mean_along_the_axis);
    RUN(projections_see_only_the_kept_side_of_a_clip_plane);
    RUN(a_cutter_around_the_volume_removes_all_or_nothing);
    RUN(every_storage_mode_gives_the_same_projection);
    RUN(minip_floor_skips_samples_below_it);
    if (vxl_renderer_set_volume(R, SPHERE) != VXL_OK) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    RUN(iso_depth_matches_the_sphere_to_a_tenth_of_a_voxel);
    RUN(iso_converges_as_the_step_shrinks);
    RUN(a_matcap_colours_each_side_of_a_sphere);
    RUN(the_matcap_is_cached_by_its_key);
    RUN(brick_skipping_changes_no_result_and_saves_samples);
    RUN(bad_input_is_refused_naming_the_field);
    vxl_renderer_destroy(R);
    vxl_volume_destroy(NOISE);
    vxl_volume_destroy(SPHERE);
    return TEST_SUMMARY();
}
