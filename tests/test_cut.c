/* test_cut.c - cutaways (csrc/frame/frame_cut.c, csrc/cut/,
 * shaders/lib/cut.glsl): clip planes, slabs, the crop box and cutter
 * meshes remove what they should and nothing else, caps are shaded by the
 * cut's normal, every storage mode cuts alike, the GL image matches the
 * double-precision reference with planes and a crop box, bad input gets a
 * message naming the field, and odd cameras give no NaN.
 *
 * The scene: the sphere phantom (an ellipsoid with semi-axes 0.7, 0.5,
 * 0.6 in world units, field 0.5 on its surface, rising inwards) seen by an
 * orthographic camera on world +z looking down -z, so pixel (i, j) looks
 * along the line x = X(i), y = Y(j) and the depth output is 3 - z. */
#include <stdio.h>

#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h"

#define W 48
#define H 48
#define N 48      /* voxels per axis */
#define HALF 1.2  /* the orthographic half-width, world units */
#define EYE_Z 3.0

static vxl_renderer *R;
static vxl_phantom_desc PH = {.struct_size = sizeof PH, .kind = VXL_PHANTOM_SPHERE, .dims = {N, N, N}};
static vxl_volume *VOL;
static float IMG[W * H * 4], IMG2[W * H * 4], DEP[W * H], DEP2[W * H];

static double px_x(int i) { return -HALF + (i + 0.5) * 2 * HALF / W; }
static double px_y(int j) { return -HALF + (j + 0.5) * 2 * HALF / H; }

/* 1 inside the ellipsoid's outline seen along z (by `margin` inside it, or
 * -1 when within margin of it). */
static int in_outline(int i, int j, double margin)
{
    double x = px_x(i) / 0.7, y = px_y(j) / 0.5, r = sqrt(x * x + y * y);
    if (r < 1 - margin) return 1;
    return r > 1 + margin ? 0 : -1;
}

/* Opaque white above the surface: opacity ramps over [0.5, 0.56] of the
 * field; shading with ambient .2, diffuse .5, no specular, one light along
 * +z (towards the eye). */
static vxl_render_params scene(void)
{
    static const float tf[8] = {1, 1, 1, 0, 1, 1, 1, 1};
    vxl_render_params p = {.struct_size = sizeof p, .width = W, .height = H, .tf_rgba = tf, .tf_size = 2,
                           .has_window = 1, .window_low = 0.5f, .window_high = 0.56f, .jitter_off = 1,
                           .has_camera = 1, .has_material = 1, .ambient = 0.2f, .diffuse = 0.5f, .light_count = 1};
    p.lights[0].position[2] = 1; /* directional, towards +z */
    memset(p.view, 0, sizeof p.view);
    memset(p.proj, 0, sizeof p.proj);
    p.view[0] = p.view[5] = p.view[10] = p.view[15] = 1;
    p.view[14] = (float)-EYE_Z;
    const double n = 0.5, f = 6;
    p.proj[0] = p.proj[5] = (float)(1 / HALF);
    p.proj[10] = (float)(-2 / (f - n));
    p.proj[14] = (float)(-(f + n) / (f - n));
    p.proj[15] = 1;
    return p;
}

static vxl_cutaway no_cut(void)
{
    vxl_cutaway c;
    memset(&c, 0, sizeof c);
    c.struct_size = sizeof c;
    return c;
}

static void add_plane(vxl_cutaway *c, float a, float b, float cc, float d, float thickness)
{
    vxl_clip_plane *q = &c->clip_planes[c->clip_plane_count++];
    memset(q, 0, sizeof *q);
    q->plane[0] = a;
    q->plane[1] = b;
    q->plane[2] = cc;
    q->plane[3] = d;
    q->thickness = thickness;
}

/* The crop box [x0, x1] x [y0, y1] x [z0, z1] (world) as a box -> world matrix. */
static void set_crop(vxl_cutaway *c, double x0, double x1, double y0, double y1, double z0, double z1)
{
    memset(c->crop_box, 0, sizeof c->crop_box);
    c->crop_box[0] = (float)((x1 - x0) / 2);
    c->crop_box[5] = (float)((y1 - y0) / 2);
    c->crop_box[10] = (float)((z1 - z0) / 2);
    c->crop_box[12] = (float)((x0 + x1) / 2);
    c->crop_box[13] = (float)((y0 + y1) / 2);
    c->crop_box[14] = (float)((z0 + z1) / 2);
    c->crop_box[15] = 1;
    c->has_crop = 1;
}

/* An axis-aligned box mesh [lo, hi] with outward winding (flip: inward). */
typedef struct box_mesh {
    float v[24];
    uint32_t idx[36];
} box_mesh;

static void make_box(box_mesh *m, const double lo[3], const double hi[3], int flip)
{
    for (int k = 0; k < 8; k++)
        for (int a = 0; a < 3; a++) m->v[3 * k + a] = (float)(((k >> a) & 1) ? hi[a] : lo[a]);
    /* faces as quads of corner indices (bit a of a corner: hi on axis a), counter-clockwise from outside */
    static const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                         {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (int f = 0; f < 6; f++) {
        const uint32_t *q = quads[f];
        uint32_t t[6] = {q[0], q[1], q[2], q[0], q[2], q[3]};
        for (int k = 0; k < 6; k++) m->idx[6 * f + k] = t[flip ? (k / 3) * 3 + 2 - k % 3 : k];
    }
}

static vxl_cutter cutter_of(const box_mesh *m, uint32_t remove_outside)
{
    vxl_cutter c = {.struct_size = sizeof c, .remove_outside = remove_outside, .vertices = m->v, .indices = m->idx,
                    .vertex_count = 8, .triangle_count = 12};
    return c;
}

/* A cutaway of one box cutter [lo, hi]: the mesh in *m, the cutter in *k. */
static vxl_cutaway box_cutaway(box_mesh *m, vxl_cutter *k, const double lo[3], const double hi[3], uint32_t remove_outside)
{
    make_box(m, lo, hi, 0);
    *k = cutter_of(m, remove_outside);
    vxl_cutaway c = no_cut();
    c.cutter_count = 1;
    c.cutters = k;
    return c;
}

static int render(vxl_renderer *r, const vxl_render_params *p, float *img, float *depth)
{
    int rc = vxl_render(r, p, img, depth);
    if (rc) fprintf(stderr, "    render failed: %s\n", vxl_renderer_error(r));
    return rc;
}

static vxl_renderer *renderer_with(uint32_t storage)
{
    vxl_renderer_options o = {.struct_size = sizeof o, .backend = software_backend(), .storage = storage,
                              .page_brick = 16};
    vxl_renderer *r = NULL;
    return vxl_renderer_create(&o, &r) == VXL_OK ? r : NULL;
}

/* Pixels whose opacity disagrees with `expect(i, j)` (1 opaque, 0 empty,
 * -1 either: on an edge). */
typedef int (*expect_fn)(int i, int j);

static int mismatches(const float *img, expect_fn expect, int *covered)
{
    int bad = 0;
    *covered = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            float a = img[4 * (j * W + i) + 3];
            int e = expect(i, j);
            *covered += a > 0.5f;
            if (e == 1 && a < 0.9f) bad++;
            if (e == 0 && a > 0.02f) bad++;
        }
    return bad;
}

static int expect_whole(int i, int j) { return in_outline(i, j, 0.06); }
/* keeps x >= 0: a pixel column straddling x = 0 may go either way */
static int expect_right_half(int i, int j)
{
    int e = in_outline(i, j, 0.06);
    if (fabs(px_x(i)) < HALF / W * 1.01) return e ? -1 : 0;
    return px_x(i) > 0 ? e : 0;
}

TEST(a_clip_plane_through_the_middle_removes_exactly_one_half)
{
    vxl_render_params p = scene();
    int covered_all, covered_half;
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    int bad = mismatches(IMG, expect_whole, &covered_all);
    CHECKF(bad == 0, "%d pixels differ from the uncut outline", bad);
    vxl_cutaway c = no_cut();
    add_plane(&c, 2, 0, 0, 0, 0); /* keep x >= 0; the normal need not be unit length */
    p.cutaway = &c;
    REQUIRE(render(R, &p, IMG2, NULL) == VXL_OK);
    bad = mismatches(IMG2, expect_right_half, &covered_half);
    fprintf(stderr, "    covered: %d uncut, %d cut\n", covered_all, covered_half);
    CHECKF(bad == 0, "%d pixels differ from the right half", bad);
    CHECK(covered_half > 0.4 * covered_all && covered_half < 0.6 * covered_all);
    /* the kept half is the uncut image's, pixel for pixel, away from the cut */
    double diff = 0;
    for (int j = 0; j < H; j++)
        for (int i = W / 2 + 1; i < W; i++)
            for (int k = 0; k < 4; k++) diff = fmax(diff, fabs(IMG[4 * (j * W + i) + k] - IMG2[4 * (j * W + i) + k]));
    CHECKF(diff < 1e-5, "kept half differs by %g", diff);
    /* the other side */
    c = no_cut();
    add_plane(&c, -1, 0, 0, 0, 0);
    REQUIRE(render(R, &p, IMG2, NULL) == VXL_OK);
    int left = 0, right = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++)
            if (IMG2[4 * (j * W + i) + 3] > 0.5f) *(px_x(i) < 0 ? &left : &right) += 1;
    CHECKF(right == 0 && left > 0.4 * covered_all, "left %d right %d", left, right);
}

/* Cutting away the front half (keep z <= 0) exposes the inside at z = 0:
 * with caps, shaded by the plane's normal (+z, along the light): ambient +
 * diffuse = 0.7 everywhere on the cap. Without caps the data gradient is
 * radial, perpendicular to the light there: little more than ambient. */
TEST(the_cap_is_shaded_by_the_plane_normal)
{
    vxl_render_params p = scene();
    vxl_cutaway c = no_cut();
    add_plane(&c, 0, 0, -1, 0, 0);
    p.cutaway = &c;
    REQUIRE(render(R, &p, IMG, DEP) == VXL_OK);
    c.caps_off = 1;
    REQUIRE(render(R, &p, IMG2, DEP2) == VXL_OK);
    double cap_sum = 0, cap_sq = 0, off_sum = 0, depth_err = 0;
    int n = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            if (in_outline(i, j, 0.4) != 1) continue; /* the cap's middle: opaque from the first sample */
            const float *a = IMG + 4 * (j * W + i), *b = IMG2 + 4 * (j * W + i);
            cap_sum += a[0];
            cap_sq += a[0] * a[0];
            off_sum += b[0];
            depth_err = fmax(depth_err, fabs(DEP[j * W + i] - EYE_Z));
            n++;
        }
    REQUIRE(n > 50);
    double mean = cap_sum / n, sd = sqrt(fmax(0, cap_sq / n - mean * mean)), off = off_sum / n;
    fprintf(stderr, "    cap %.4f (sd %.5f), caps off %.4f, depth error %.4f\n", mean, sd, off, depth_err);
    CHECKF(fabs(mean - 0.7) < 0.01 && sd < 0.005, "cap %.4f sd %.5f", mean, sd);
    CHECKF(off < 0.45, "caps off %.4f", off);
    /* the cut face is where the plane is: depth 3 (the eye at z = 3) */
    CHECKF(depth_err < 0.05, "depth error %.4f", depth_err);
}

/* A slab keeps 0 <= signed distance <= thickness on the kept side. */
TEST(a_slab_keeps_only_its_thickness)
{
    vxl_render_params p = scene();
    vxl_cutaway c = no_cut();
    add_plane(&c, 1, 0, 0, 0.1f, 0.2f); /* -0.1 <= x <= 0.1 */
    p.cutaway = &c;
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    int bad = 0, inside = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            float a = IMG[4 * (j * W + i) + 3];
            double x = fabs(px_x(i));
            if (x > 0.1 + HALF / W) bad += a > 0.02f;
            else if (x < 0.1 - HALF / W && in_outline(i, j, 0.1) == 1) {
                inside++;
                bad += a < 0.9f;
            }
        }
    CHECKF(bad == 0 && inside > 20, "%d bad, %d inside", bad, inside);
}

static int crop_expect(int i, int j)
{
    double x = px_x(i), y = px_y(j), e = HALF / W * 1.01;
    if (fabs(x - 0.15) < e || fabs(x + 0.35) < e || fabs(y - 0.2) < e || fabs(y + 0.1) < e) return -1;
    int in = x > -0.35 && x < 0.15 && y > -0.1 && y < 0.2;
    return in ? in_outline(i, j, 0.06) : 0;
}

TEST(the_crop_box_keeps_exactly_its_inside)
{
    vxl_render_params p = scene();
    vxl_cutaway c = no_cut();
    set_crop(&c, -0.35, 0.15, -0.1, 0.2, -2, 2);
    p.cutaway = &c;
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    int covered, bad = mismatches(IMG, crop_expect, &covered);
    CHECKF(bad == 0 && covered > 50, "%d bad, %d covered", bad, covered);
    /* rotated 90 degrees about z (columns of the matrix swapped): the same box */
    float m[16];
    memcpy(m, c.crop_box, sizeof m);
    for (int k = 0; k < 3; k++) {
        c.crop_box[k] = -m[4 + k];
        c.crop_box[4 + k] = m[k];
    }
    REQUIRE(render(R, &p, IMG2, NULL) == VXL_OK);
    CHECKF(image_rmse(IMG, IMG2, W * H * 4) < 1e-3, "rmse %g", image_rmse(IMG, IMG2, W * H * 4));
    /* a crop box in front of the volume keeps nothing */
    set_crop(&c, -2, 2, -2, 2, 1.5, 2.5);
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    CHECK(alpha_sum(IMG, W * H) == 0);
}

/* The notch: a box in front of the ellipsoid's middle, reaching into it
 * down to z = 0. */
static const double NOTCH_LO[3] = {-0.3, -0.2, 0}, NOTCH_HI[3] = {0.3, 0.2, 1.5};

static int in_notch(int i, int j, double margin)
{
    double x = px_x(i), y = px_y(j);
    if (fabs(x) < 0.3 - margin && fabs(y) < 0.2 - margin) return 1;
    return fabs(x) > 0.3 + margin || fabs(y) > 0.2 + margin ? 0 : -1;
}

TEST(a_cube_cutter_removes_its_inside_and_nothing_else)
{
    vxl_render_params p = scene();
    REQUIRE(render(R, &p, IMG, DEP) == VXL_OK);
    box_mesh m;
    vxl_cutter k;
    vxl_cutaway c = box_cutaway(&m, &k, NOTCH_LO, NOTCH_HI, 0);
    p.cutaway = &c;
    REQUIRE(render(R, &p, IMG2, DEP2) == VXL_OK);
    double outside = 0, notch_err = 0;
    int notch = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            int q = j * W + i, e = in_notch(i, j, HALF / W * 1.01);
            if (e == 0) {
                for (int ch = 0; ch < 4; ch++) outside = fmax(outside, fabs(IMG[4 * q + ch] - IMG2[4 * q + ch]));
            } else if (e == 1) {
                notch++;
                notch_err = fmax(notch_err, fabs(DEP2[q] - EYE_Z)); /* the notch's floor at z = 0 */
                CHECK(IMG2[4 * q + 3] > 0.9f);
            }
        }
    fprintf(stderr, "    outside the notch: max diff %g; notch floor depth error %.4f (%d px)\n", outside, notch_err,
            notch);
    CHECKF(outside < 1e-5, "outside the notch the image changed by %g", outside);
    CHECKF(notch > 30 && notch_err < 0.05, "notch depth error %.4f", notch_err);
    /* the notch's floor is capped: lit by its normal (+z) like the plane cap */
    double floor_c = IMG2[4 * ((H / 2) * W + W / 2)];
    CHECKF(fabs(floor_c - 0.7) < 0.01, "notch floor %.4f", floor_c);

    /* the same mesh wound inward (a mirrored export) cuts the same */
    box_mesh inward;
    make_box(&inward, NOTCH_LO, NOTCH_HI, 1);
    vxl_cutter ki = cutter_of(&inward, 0);
    c.cutters = &ki;
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    CHECKF(image_rmse(IMG, IMG2, W * H * 4) < 1e-6, "inward winding: rmse %g", image_rmse(IMG, IMG2, W * H * 4));

    /* remove_outside keeps only the notch's inside: nothing outside it, and
     * inside it the uncut front surface (in front of the notch's floor) */
    vxl_render_params plain = scene();
    REQUIRE(render(R, &plain, IMG2, DEP2) == VXL_OK);
    k.remove_outside = 1;
    c.cutters = &k;
    REQUIRE(render(R, &p, IMG, DEP) == VXL_OK);
    int bad = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            int q = j * W + i, e = in_notch(i, j, HALF / W * 1.01);
            if (e == 0) bad += IMG[4 * q + 3] > 0.02f;
            if (e == 1) bad += !(fabs(DEP[q] - DEP2[q]) < 1e-4 && DEP[q] < EYE_Z);
        }
    CHECKF(bad == 0, "remove_outside: %d pixels wrong", bad);
}

/* The camera inside a cutter (its front faces behind the eye, clipped by
 * the near plane) still removes the cutter's inside up to its back face. */
TEST(a_cutter_around_the_eye_removes_up_to_its_back_face)
{
    vxl_render_params p = scene();
    const double lo[3] = {-2, -2, 0.2}, hi[3] = {2, 2, 5}; /* holds the eye at z = 3 */
    box_mesh m;
    vxl_cutter k;
    vxl_cutaway c = box_cutaway(&m, &k, lo, hi, 0);
    p.cutaway = &c;
    REQUIRE(render(R, &p, IMG, DEP) == VXL_OK);
    double err = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++)
            if (in_outline(i, j, 0.5) == 1) err = fmax(err, fabs(DEP[j * W + i] - (EYE_Z - 0.2)));
    CHECKF(err < 0.05, "depth error %.4f", err);
}

/* More crossings on a pixel than the layers hold: those rays are dropped
 * (empty), the others are cut as usual. 5 nested boxes cross the middle
 * pixels 10 times, over the 8 layers. */
TEST(an_over_full_pixel_is_drawn_empty)
{
    vxl_render_params p = scene();
    box_mesh m[5];
    vxl_cutter k[4];
    for (int s = 0; s < 4; s++) { /* one box per cutter */
        double lo[3] = {-0.1 - 0.05 * s, -0.1 - 0.05 * s, 1.1 + 0.05 * s}, hi[3] = {0.1 + 0.05 * s, 0.1 + 0.05 * s, 2.3 - 0.05 * s};
        make_box(&m[s], lo, hi, 0);
        k[s] = cutter_of(&m[s], 0);
    }
    vxl_cutaway c = no_cut();
    c.cutter_count = 4;
    c.cutters = k;
    p.cutaway = &c;
    /* 4 nested boxes in front of the volume: 8 crossings, kept; the image is the uncut one */
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    vxl_render_params plain = scene();
    REQUIRE(render(R, &plain, IMG2, NULL) == VXL_OK);
    CHECKF(image_rmse(IMG, IMG2, W * H * 4) < 1e-6, "rmse %g", image_rmse(IMG, IMG2, W * H * 4));
    /* a fifth box on the first cutter (two boxes in one mesh): 10 crossings in the middle */
    float v[48];
    uint32_t idx[72];
    double lo[3] = {-0.05, -0.05, 1.15}, hi[3] = {0.05, 0.05, 1.3};
    make_box(&m[4], lo, hi, 0);
    memcpy(v, m[0].v, sizeof m[0].v);
    memcpy(v + 24, m[4].v, sizeof m[4].v);
    for (int t = 0; t < 36; t++) {
        idx[t] = m[0].idx[t];
        idx[36 + t] = m[4].idx[t] + 8;
    }
    k[0].vertices = v;
    k[0].indices = idx;
    k[0].vertex_count = 16;
    k[0].triangle_count = 24;
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    int q = (H / 2) * W + W / 2;
    CHECKF(IMG[4 * q + 3] == 0, "middle alpha %g", IMG[4 * q + 3]);
    int q2 = (H / 2) * W + W / 2 + 10; /* beside the small box: 8 crossings, drawn */
    CHECKF(IMG[4 * q2 + 3] > 0.9f, "beside alpha %g", IMG[4 * q2 + 3]);
}

/* The double-precision reference clips its rays with the same planes, slab
 * and crop box, and caps the same first step: the GL image agrees. */
TEST(planes_and_crop_box_match_the_reference)
{
    vxl_render_params p = scene();
    p.window_high = 1.2f; /* a soft edge: the GL step's own error stays small */
    static float REF[W * H * 4];
    REQUIRE(vxl_reference_render(&PH, VOL, &p, REF, NULL) == VXL_OK);
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    double e_uncut = image_rmse(IMG, REF, W * H * 4);
    vxl_cutaway c = no_cut();
    add_plane(&c, 0.3f, -0.2f, -1, 0.1f, 0);
    add_plane(&c, 1, 1, 0, 0.31f, 0.8f); /* 0.31: no pixel's ray lies in the plane */
    set_crop(&c, -0.6, 0.5, -0.45, 0.4, -0.5, 0.5);
    p.cutaway = &c;
    REQUIRE(vxl_reference_render(&PH, VOL, &p, REF, NULL) == VXL_OK);
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    double e = image_rmse(IMG, REF, W * H * 4);
    c.caps_off = 1;
    REQUIRE(render(R, &p, IMG2, NULL) == VXL_OK);
    double e_off = image_rmse(IMG2, REF, W * H * 4);
    REQUIRE(vxl_reference_render(&PH, VOL, &p, REF, NULL) == VXL_OK);
    double e_both_off = image_rmse(IMG2, REF, W * H * 4);
    fprintf(stderr, "    rmse %.5f against the reference (uncut %.5f); caps off %.5f (against a capped reference %.5f)\n",
            e, e_uncut, e_both_off, e_off);
    CHECKF(e < 0.005 && e_both_off < 0.005, "rmse %.5f, caps off %.5f", e, e_both_off);
    CHECK(e_off > e && e_off > e_both_off);
    CHECK(alpha_sum(IMG, W * H) > 100);
}

/* The cut is the same whatever holds the volume. */
TEST(every_storage_mode_gives_the_same_cut)
{
    vxl_render_params p = scene();
    box_mesh m;
    make_box(&m, NOTCH_LO, NOTCH_HI, 0);
    vxl_cutter k = cutter_of(&m, 0);
    vxl_cutaway c = no_cut();
    add_plane(&c, 1, 0.2f, 0, 0.4f, 0);
    set_crop(&c, -0.6, 0.6, -0.4, 0.45, -2, 2);
    c.cutter_count = 1;
    c.cutters = &k;
    p.cutaway = &c;
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    const uint32_t modes[3] = {VXL_STORAGE_BRICKED, VXL_STORAGE_SPARSE, VXL_STORAGE_COMPRESSED};
    for (int s = 0; s < 3; s++) {
        vxl_renderer *r = renderer_with(modes[s]);
        REQUIRE(r);
        int rc = vxl_renderer_set_volume(r, VOL);
        if (!rc) rc = render(r, &p, IMG2, NULL);
        vxl_render_stats st = {.struct_size = sizeof st};
        if (!rc) rc = vxl_renderer_get_stats(r, &st);
        vxl_renderer_destroy(r);
        REQUIRE(rc == VXL_OK);
        CHECK(st.storage == modes[s]);
        double q = image_psnr(IMG, IMG2, W * H * 4);
        fprintf(stderr, "    %s vs dense: %.1f dB\n", vxl_storage_name(modes[s]), q);
        CHECKF(q > 40, "%s: %.1f dB", vxl_storage_name(modes[s]), q);
    }
}

/* Samples are taken only where something is kept: half the volume cut
 * away takes about half the samples; nothing kept takes none. */
TEST(samples_are_counted_only_in_kept_space)
{
    vxl_render_params p = scene();
    p.no_skip = 1; /* every sample of the box counts */
    vxl_render_stats all = {.struct_size = sizeof all}, half = {.struct_size = sizeof half};
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &all) == VXL_OK);
    vxl_cutaway c = no_cut();
    add_plane(&c, 0, 0, 1, 0, 0); /* keep z >= 0: the rays' first half */
    p.cutaway = &c;
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &half) == VXL_OK);
    fprintf(stderr, "    samples %llu uncut, %llu with half cut away\n", (unsigned long long)all.samples,
            (unsigned long long)half.samples);
    CHECK(half.samples > 0.4 * all.samples && half.samples < 0.6 * all.samples);
    /* a cutter removing the slab |z| < 0.2 (x, y within 0.3) from the middle
     * of the rays: each of the 12 x 12 rays through it skips 0.4 world units
     * = 9.6 voxels, about 19 samples of 0.5, and keeps both ends */
    const double slo[3] = {-0.3, -0.3, -0.2}, shi[3] = {0.3, 0.3, 0.2};
    box_mesh m;
    vxl_cutter k;
    c = box_cutaway(&m, &k, slo, shi, 0);
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &half) == VXL_OK);
    double skipped = (double)all.samples - (double)half.samples;
    fprintf(stderr, "    a middle slab cut out: %.0f samples fewer (expected about %d)\n", skipped, 144 * 19);
    CHECK(skipped >= 144 * 18 && skipped <= 144 * 21);
    /* a cutter removing the whole volume: no samples */
    const double lo[3] = {-2, -2, -2}, hi[3] = {2, 2, 2};
    c = box_cutaway(&m, &k, lo, hi, 0);
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &half) == VXL_OK);
    CHECK(half.samples == 0 && alpha_sum(IMG, W * H) == 0);
}

/* A cutaway that cuts nothing renders the image of no cutaway at all. */
TEST(an_empty_cutaway_changes_nothing)
{
    vxl_render_params p = scene();
    p.azimuth_deg = 30;
    p.has_camera = 0;
    REQUIRE(render(R, &p, IMG, DEP) == VXL_OK);
    vxl_cutaway c = no_cut();
    p.cutaway = &c;
    REQUIRE(render(R, &p, IMG2, DEP2) == VXL_OK);
    CHECK(memcmp(IMG, IMG2, sizeof IMG) == 0 && memcmp(DEP, DEP2, sizeof DEP) == 0);
    /* a plane keeping everything and a crop box holding the volume: the same pixels */
    add_plane(&c, 0, 0, 1, 10, 0);
    set_crop(&c, -3, 3, -3, 3, -3, 3);
    REQUIRE(render(R, &p, IMG2, NULL) == VXL_OK);
    CHECKF(image_rmse(IMG, IMG2, W * H * 4) < 1e-6, "rmse %g", image_rmse(IMG, IMG2, W * H * 4));
}

static int fails_naming(vxl_render_params *p, const char *field)
{
    int rc = vxl_render(R, p, IMG, NULL);
    const char *msg = vxl_renderer_error(R);
    int ok = rc != VXL_OK && msg && strstr(msg, field);
    if (!ok) fprintf(stderr, "    expected an error naming %s, got %d: %s\n", field, rc, msg ? msg : "(null)");
    return ok;
}

TEST(bad_cutaways_fail_naming_the_field)
{
    vxl_render_params p = scene();
    vxl_cutaway c = no_cut();
    p.cutaway = &c;
    c.clip_plane_count = 7;
    CHECK(fails_naming(&p, "clip_plane_count"));
    c = no_cut();
    add_plane(&c, 0, 0, 0, 1, 0);
    CHECK(fails_naming(&p, "clip_planes[0].plane has a zero normal"));
    c = no_cut();
    add_plane(&c, 1, 0, 0, 0, 0);
    add_plane(&c, 1, 0, 0, NAN, 0);
    CHECK(fails_naming(&p, "clip_planes[1].plane is not finite"));
    c.clip_planes[1].plane[3] = 0;
    c.clip_planes[1].thickness = -1;
    CHECK(fails_naming(&p, "clip_planes[1].thickness"));
    c.clip_planes[1].thickness = NAN;
    CHECK(fails_naming(&p, "clip_planes[1].thickness"));
    c.clip_planes[1].thickness = INFINITY;
    CHECK(fails_naming(&p, "clip_planes[1].thickness"));
    c.clip_planes[1].thickness = 0;
    c.clip_planes[1].reserved = 1;
    CHECK(fails_naming(&p, "clip_planes[1].reserved"));
    c = no_cut();
    set_crop(&c, 0, 0, -1, 1, -1, 1); /* flat */
    CHECK(fails_naming(&p, "crop_box is singular"));
    set_crop(&c, -1, 1, -1, 1, -1, 1);
    c.crop_box[5] = INFINITY;
    CHECK(fails_naming(&p, "crop_box is not finite"));
    set_crop(&c, -1, 1, -1, 1, -1, 1);
    c.crop_box[3] = 0.5f;
    CHECK(fails_naming(&p, "crop_box must be affine"));
    c = no_cut();
    c.reserved = 3;
    CHECK(fails_naming(&p, "cutaway.reserved"));
    c = no_cut();
    c.struct_size = 0;
    CHECK(fails_naming(&p, "cutaway.struct_size"));
    c = no_cut();
    c.cutter_count = 5;
    box_mesh m;
    const double lo[3] = {-0.2, -0.2, -0.2}, hi[3] = {0.2, 0.2, 0.2};
    make_box(&m, lo, hi, 0);
    vxl_cutter k[2] = {cutter_of(&m, 0), cutter_of(&m, 0)};
    c.cutters = k;
    CHECK(fails_naming(&p, "cutter_count 5 exceeds"));
    c.cutter_count = 1;
    c.cutters = NULL;
    CHECK(fails_naming(&p, "cutaway.cutters is NULL"));
    c.cutters = k;
    c.cutter_count = 2;
    k[1].vertices = NULL;
    CHECK(fails_naming(&p, "cutters[1] has 12 triangles but its vertices or indices are NULL"));
    k[1] = cutter_of(&m, 2);
    CHECK(fails_naming(&p, "cutters[1].remove_outside"));
    k[1] = cutter_of(&m, 0);
    uint32_t idx[36];
    memcpy(idx, m.idx, sizeof idx);
    idx[7] = 8;
    k[1].indices = idx;
    CHECK(fails_naming(&p, "cutters[1].indices[7] = 8 is out of range"));
    float v[24];
    memcpy(v, m.v, sizeof v);
    v[4] = NAN;
    k[1] = cutter_of(&m, 0);
    k[1].vertices = v;
    CHECK(fails_naming(&p, "cutters[1].vertices are not all finite"));
    k[1] = cutter_of(&m, 0);
    k[1].struct_size = 8;
    CHECK(fails_naming(&p, "cutters[1].struct_size"));
    c = no_cut();
    add_plane(&c, 1, 0, 0, 0, 0);
    p.technique = VXL_TECHNIQUE_SLICES3D;
    CHECK(fails_naming(&p, "slicing techniques"));
    /* and the renderer still renders after every refusal */
    p = scene();
    REQUIRE(render(R, &p, IMG, NULL) == VXL_OK);
    CHECK(alpha_sum(IMG, W * H) > 100);
}

/* Every render mode sees only kept samples: a plane empties the removed
 * half (MinIP, average and ISO at 0.9 show little or nothing on the other),
 * and a cutter removing the slab |z| < 0.2 through the middle takes the
 * field's maximum (1.0 at the centre) out of MIP, leaving 0.83 at the slab's
 * faces (0.667 of the window [0.5, 1]), and takes the iso-surface at 0.9
 * (|q| = 0.2, inside the slab) away. */
TEST(every_mode_sees_only_kept_samples)
{
    static const float ramp[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    box_mesh m;
    const double lo[3] = {-0.3, -0.3, -0.2}, hi[3] = {0.3, 0.3, 0.2};
    make_box(&m, lo, hi, 0);
    vxl_cutter k = cutter_of(&m, 0);
    const int mid = (H / 2) * W + W / 2;
    for (uint32_t mode = VXL_MODE_MIP; mode < VXL_MODE_COUNT; mode++) {
        vxl_render_params p = scene();
        p.mode = mode;
        p.tf_rgba = ramp;
        p.window_low = 0.5f;
        p.window_high = 1.0f;
        p.iso_value = 0.9f;
        vxl_cutaway c = no_cut();
        add_plane(&c, 1, 0, 0, 0, 0);
        p.cutaway = &c;
        REQUIRE(render(R, &p, IMG, DEP) == VXL_OK);
        int left = 0;
        for (int j = 0; j < H; j++)
            for (int i = 0; i < W / 2 - 1; i++) left += IMG[4 * (j * W + i) + 3] != 0;
        CHECKF(left == 0 && image_is_sane(IMG, DEP, W * H), "%s: %d pixels left of the plane", vxl_mode_name(mode), left);
        if (mode == VXL_MODE_MIP) CHECKF(alpha_sum(IMG, W * H) > 10, "mip: nothing right of the plane");
        if (mode != VXL_MODE_MIP && mode != VXL_MODE_ISO) continue;
        c = no_cut();
        REQUIRE(render(R, &p, IMG2, NULL) == VXL_OK);
        c.cutter_count = 1;
        c.cutters = &k;
        REQUIRE(render(R, &p, IMG, DEP) == VXL_OK);
        CHECK(image_is_sane(IMG, DEP, W * H));
        fprintf(stderr, "    %s: centre alpha %.3f uncut, %.3f with the slab removed\n", vxl_mode_name(mode),
                IMG2[4 * mid + 3], IMG[4 * mid + 3]);
        CHECK(IMG2[4 * mid + 3] > 0.9f);
        if (mode == VXL_MODE_MIP) CHECKF(fabs(IMG[4 * mid + 3] - 0.667) < 0.05, "MIP %.3f", IMG[4 * mid + 3]);
        else CHECKF(IMG[4 * mid + 3] == 0, "ISO %.3f", IMG[4 * mid + 3]);
    }
}

/* Odd cameras and cuts: the eye inside the volume, planes along the rays,
 * a tiny crop box, a huge slab, a perspective camera close up, a cutter
 * through the eye: every pixel finite and premultiplied. */
TEST(no_nan_with_odd_cameras_and_cuts)
{
    box_mesh m;
    const double lo[3] = {-0.5, -0.5, -5}, hi[3] = {0.5, 0.5, 5};
    make_box(&m, lo, hi, 0);
    vxl_cutter k = cutter_of(&m, 0);
    for (int v = 0; v < 6; v++) {
        vxl_render_params p = scene();
        vxl_cutaway c = no_cut();
        p.cutaway = &c;
        p.jitter_off = 0;
        switch (v) {
        case 0: add_plane(&c, 1, 0, 0, 0, 0); add_plane(&c, 0, 1, 0, 0, 0); break; /* planes along the rays */
        case 1: set_crop(&c, -1e-3, 1e-3, -1e-3, 1e-3, -1e-3, 1e-3); break;
        case 2: add_plane(&c, 0, 0, 1, 0, 1e30f); break;
        case 3: p.view[14] = 0; add_plane(&c, 0.2f, 0.1f, -1, 0, 0); break; /* eye inside the volume */
        case 4: p.has_camera = 0; p.azimuth_deg = 45; p.elevation_deg = 89.9f; c.cutter_count = 1; c.cutters = &k;
                add_plane(&c, 1e-6f, 0, 1, 0, 0); break;
        default: p.has_camera = 0; p.elevation_deg = -90; set_crop(&c, -2, 2, -2, 2, -1e-2, 1e-2); c.cutter_count = 1;
                 c.cutters = &k; break;
        }
        int rc = render(R, &p, IMG, DEP);
        CHECKF(rc == VXL_OK && image_is_sane(IMG, DEP, W * H), "case %d", v);
    }
}

int main(void)
{
    R = renderer_with(VXL_STORAGE_DENSE);
    if (!R || vxl_phantom_create(&PH, &VOL) != VXL_OK || vxl_renderer_set_volume(R, VOL) != VXL_OK) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    RUN(a_clip_plane_through_the_middle_removes_exactly_one_half);
    RUN(the_cap_is_shaded_by_the_plane_normal);
    RUN(a_slab_keeps_only_its_thickness);
    RUN(the_crop_box_keeps_exactly_its_inside);
    RUN(a_cube_cutter_removes_its_inside_and_nothing_else);
    RUN(a_cutter_around_the_eye_removes_up_to_its_back_face);
    RUN(an_over_full_pixel_is_drawn_empty);
    RUN(planes_and_crop_box_match_the_reference);
    RUN(every_storage_mode_gives_the_same_cut);
    RUN(samples_are_counted_only_in_kept_space);
    RUN(an_empty_cutaway_changes_nothing);
    RUN(bad_cutaways_fail_naming_the_field);
    RUN(every_mode_sees_only_kept_samples);
    RUN(no_nan_with_odd_cameras_and_cuts);
    vxl_renderer_destroy(R);
    vxl_volume_destroy(VOL);
    return TEST_SUMMARY();
}
