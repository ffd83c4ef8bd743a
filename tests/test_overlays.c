/* test_overlays.c - several volumes in one ray march (overlays;
 * csrc/overlay/, csrc/frame/frame_overlays.c, shaders/lib/overlays.glsl):
 * an overlay on another grid (scaled, rotated, translated, partly outside
 * the base box) lands where its affine says; an identical copy as OVER
 * doubles the extinction; OVER, MAX and ADD against a double-precision CPU
 * march of the header's formulas; skipping on and off give the same image
 * with fewer samples; frames without overlays are unchanged; bad input
 * fails with a message; a refused overlay keeps the slot's old volume.
 *
 * The scene: the base grid is N^3 voxels centred on the world origin (voxel
 * = world + C), seen by an orthographic camera on world +z looking down -z,
 * so pixel (i, j) looks along x = X(i), y = Y(j). */
#include <stdio.h>

#include "harness.h"
#include "test_util.h"

#define N 16
#define C ((N - 1) / 2.0)
#define EYE_Z 40.0
#define NEAR 1.0
#define W 48
#define HALF 10.0
#define STEP 0.5

static vxl_renderer *R;
static float IMG[W * W * 4], IMG2[W * W * 4];

static double px_c(int i) { return -HALF + (i + 0.5) * 2 * HALF / W; }

/* Unshaded orthographic view, no jitter. */
static vxl_render_params scene(void)
{
    vxl_render_params p = default_params(W, W);
    p.jitter_off = 1;
    p.shading_off = 1;
    p.step = (float)STEP;
    p.has_camera = 1;
    memset(p.view, 0, sizeof p.view);
    memset(p.proj, 0, sizeof p.proj);
    p.view[0] = p.view[5] = p.view[10] = p.view[15] = 1;
    p.view[14] = (float)-EYE_Z;
    const double n = NEAR, f = 100;
    p.proj[0] = p.proj[5] = (float)(1 / HALF);
    p.proj[10] = (float)(-2 / (f - n));
    p.proj[14] = (float)(-(f + n) / (f - n));
    p.proj[15] = 1;
    return p;
}

/* voxel -> world: rotation by rz about z then rx about x, scale s, so that
 * voxel c lands on world t. */
static void affine_srt(double a[16], double s, double rz_deg, double rx_deg, const double c[3], const double t[3])
{
    const double z = rz_deg * M_PI / 180, x = rx_deg * M_PI / 180;
    const double rzm[9] = {cos(z), -sin(z), 0, sin(z), cos(z), 0, 0, 0, 1}; /* row-major */
    const double rxm[9] = {1, 0, 0, 0, cos(x), -sin(x), 0, sin(x), cos(x)};
    double m[9];
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) {
            m[r * 3 + k] = 0;
            for (int j = 0; j < 3; j++) m[r * 3 + k] += rxm[r * 3 + j] * rzm[j * 3 + k];
        }
    memset(a, 0, 16 * sizeof *a);
    for (int r = 0; r < 3; r++) {
        double tr = t[r];
        for (int k = 0; k < 3; k++) {
            a[k * 4 + r] = s * m[r * 3 + k];
            tr -= s * m[r * 3 + k] * c[k];
        }
        a[12 + r] = tr;
    }
    a[15] = 1;
}

static vxl_volume *make_f32(const uint32_t dims[3], const float *data, const double affine[16])
{
    vxl_volume_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = sizeof d;
    d.dtype = VXL_DTYPE_F32;
    memcpy(d.dims, dims, sizeof d.dims);
    d.data = data;
    d.has_affine = 1;
    memcpy(d.affine, affine, sizeof d.affine);
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, NULL, &v) == VXL_OK ? v : NULL;
}

/* A volume of the field f (voxel coordinates) on dims with the affine. */
static vxl_volume *make_field(const uint32_t dims[3], field_fn f, const double *prm, const double affine[16])
{
    size_t n = (size_t)dims[0] * dims[1] * dims[2];
    float *d = malloc(n * sizeof *d);
    if (!d) return NULL;
    for (uint32_t z = 0; z < dims[2]; z++)
        for (uint32_t y = 0; y < dims[1]; y++)
            for (uint32_t x = 0; x < dims[0]; x++) d[x + dims[0] * (y + (size_t)dims[1] * z)] = (float)f(x, y, z, prm);
    vxl_volume *v = make_f32(dims, d, affine);
    free(d);
    return v;
}

static double field_const(double x, double y, double z, const double *p)
{
    (void)x, (void)y, (void)z;
    return p[0];
}

static void base_affine(double a[16])
{
    const double c[3] = {C, C, C}, t[3] = {0, 0, 0};
    affine_srt(a, 1, 0, 0, c, t);
}

/* Sets the base volume to the field; 0 on success. */
static int set_base(field_fn f, const double *prm)
{
    double a[16];
    base_affine(a);
    const uint32_t dims[3] = {N, N, N};
    vxl_volume *v = make_field(dims, f, prm, a);
    if (!v) return -1;
    int rc = vxl_renderer_set_volume(R, v);
    vxl_volume_destroy(v);
    return rc;
}

static int set_overlay(uint32_t slot, const uint32_t dims[3], field_fn f, const double *prm, const double affine[16])
{
    vxl_volume *v = make_field(dims, f, prm, affine);
    if (!v) return -1;
    int rc = vxl_renderer_set_overlay(R, slot, v);
    vxl_volume_destroy(v);
    return rc;
}

/* A table of n entries with constant colour and alpha. */
static void const_tf(float *tf, int n, float r, float g, float b, float a)
{
    for (int i = 0; i < n; i++) {
        tf[4 * i] = r;
        tf[4 * i + 1] = g;
        tf[4 * i + 2] = b;
        tf[4 * i + 3] = a;
    }
}

/* A table transparent below the middle, colour (r, g, b) and alpha a above. */
static void step_tf(float *tf, int n, float r, float g, float b, float a)
{
    const_tf(tf, n, r, g, b, a);
    for (int i = 0; i < n / 2; i++) tf[4 * i + 3] = 0;
}

static vxl_overlay_style style(uint32_t slot, uint32_t blend, const float *tf, uint32_t tf_size)
{
    vxl_overlay_style s;
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    s.slot = slot;
    s.blend = blend;
    s.tf_rgba = tf;
    s.tf_size = tf_size;
    return s;
}

static double max_diff(const float *a, const float *b, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; i++) m = fmax(m, fabs((double)a[i] - b[i]));
    return m;
}

/* The ball scene the landing and clip tests share: a transparent base and,
 * in slot 0, a ball of radius 3 voxels in a 20x16x12 grid, scaled by 0.7,
 * turned 30 degrees about z and 20 about x, its centre put at world BALL_AT:
 * the ball reaches past the base box's x = 8 face, so the ray must walk the
 * union of the boxes. *s is the overlay's style p points to. */
static const double BALL_AT[3] = {8.6, -3.2, 2};

static int ball_scene(vxl_render_params *p, vxl_overlay_style *s)
{
    const double zero = 0;
    const uint32_t dims[3] = {20, 16, 12};
    const double ball[4] = {12, 6, 5, 3}, c[3] = {12, 6, 5};
    double a[16];
    affine_srt(a, 0.7, 30, 20, c, BALL_AT);
    if (set_base(field_const, &zero) || set_overlay(0, dims, field_ball, ball, a)) return -1;
    static float base_tf[2 * 4], tf[256 * 4];
    const_tf(base_tf, 2, 1, 1, 1, 0);
    step_tf(tf, 256, 1, 0.8f, 0.2f, 0.6f);
    *p = scene();
    p->tf_rgba = base_tf;
    p->tf_size = 2;
    *s = style(0, VXL_BLEND_OVER, tf, 256);
    s->has_window = 1;
    s->window_low = 0;
    s->window_high = 1;
    p->overlay_count = 1;
    p->overlays = s;
    return 0;
}

TEST(an_overlay_on_another_grid_lands_where_its_affine_says)
{
    vxl_render_params p;
    vxl_overlay_style s;
    REQUIRE(ball_scene(&p, &s) == 0);
    const double *t = BALL_AT;
    for (uint32_t interp = 0; interp < VXL_INTERP_COUNT; interp++) {
        s.interpolation = interp;
        s.interpolation_set = 1;
        REQUIRE(vxl_render(R, &p, IMG, NULL) == VXL_OK);
        REQUIRE(image_is_sane(IMG, NULL, W * W));
        double sw = 0, sx = 0, sy = 0;
        for (int j = 0; j < W; j++)
            for (int i = 0; i < W; i++) {
                double w = IMG[4 * (i + W * j) + 3];
                sw += w;
                sx += w * i;
                sy += w * j;
            }
        REQUIRE(sw > 20); /* a ball of radius 2.1 world units covers ~70 pixels */
        /* the orthographic view projects world (x, y) to pixel (x + HALF) / (2 HALF) W - 0.5 */
        double ex = (t[0] + HALF) / (2 * HALF) * W - 0.5, ey = (t[1] + HALF) / (2 * HALF) * W - 0.5;
        CHECKF(fabs(sx / sw - ex) < 0.5 && fabs(sy / sw - ey) < 0.5,
               "interpolation %u: centroid (%.3f, %.3f), expected (%.3f, %.3f)", interp, sx / sw, sy / sw, ex, ey);
        /* the part past the base box is drawn: pixels right of x = 8 */
        double right = 0;
        for (int j = 0; j < W; j++)
            for (int i = 0; i < W; i++)
                if (px_c(i) > 8.3) right += IMG[4 * (i + W * j) + 3];
        CHECKF(right > 2, "interpolation %u: alpha %.3f beyond the base box", interp, right);
    }
    REQUIRE(vxl_renderer_set_overlay(R, 0, NULL) == VXL_OK);
}

TEST(a_clip_plane_cuts_the_overlays_too)
{
    vxl_render_params p;
    vxl_overlay_style s;
    REQUIRE(ball_scene(&p, &s) == 0);
    vxl_cutaway cut;
    memset(&cut, 0, sizeof cut);
    cut.struct_size = sizeof cut;
    cut.clip_plane_count = 1;
    cut.clip_planes[0].plane[0] = 1; /* keeps x >= 9, the ball's right part */
    cut.clip_planes[0].plane[3] = -9;
    p.cutaway = &cut;
    REQUIRE(vxl_render(R, &p, IMG, NULL) == VXL_OK);
    double left = 0, right = 0;
    for (int j = 0; j < W; j++)
        for (int i = 0; i < W; i++) {
            double x = px_c(i), al = IMG[4 * (i + W * j) + 3];
            if (x < 8.8) left += al;
            if (x > 9.2) right += al;
        }
    CHECKF(left == 0 && right > 2, "alpha %.3f left of the plane, %.3f right of it", left, right);
    REQUIRE(vxl_renderer_set_overlay(R, 0, NULL) == VXL_OK);
}

TEST(mask_labels_mask_the_base_volume_only)
{
    /* labels on the base grid: 1 on x < N/2, 2 on the rest. Set first:
     * labels.c leaves GL_UNPACK_ALIGNMENT at 4 after its upload, which
     * spoils the base's skipping map (2 bricks a row) if it is uploaded
     * after; ball_scene's overlay upload sets it back to 1 */
    static uint8_t ids[N * N * N];
    for (int i = 0; i < N * N * N; i++) ids[i] = i % N < N / 2 ? 1 : 2;
    double a[16];
    base_affine(a);
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U8, .dims = {N, N, N}, .data = ids, .has_affine = 1};
    memcpy(d.affine, a, sizeof d.affine);
    vxl_volume *lv = NULL;
    REQUIRE(vxl_volume_create(&d, NULL, &lv) == VXL_OK);
    REQUIRE(vxl_renderer_set_labels(R, lv) == VXL_OK);
    vxl_volume_destroy(lv);
    vxl_render_params p;
    vxl_overlay_style s;
    REQUIRE(ball_scene(&p, &s) == 0);
    const double val = 0.5; /* a visible base */
    REQUIRE(set_base(field_const, &val) == 0);
    static float base_tf[2 * 4];
    const_tf(base_tf, 2, 0.2f, 0.4f, 0.9f, 0.02f);
    p.tf_rgba = base_tf;
    vxl_label_entry e[2];
    memset(e, 0, sizeof e);
    for (int k = 0; k < 2; k++) {
        e[k].struct_size = sizeof e[k];
        e[k].id = k + 1;
        e[k].color[0] = e[k].color[1] = e[k].color[2] = e[k].color[3] = 1;
        e[k].visible = k == 0; /* only the left half */
    }
    vxl_label_style ls = {.struct_size = sizeof ls, .mode = VXL_LABEL_MODE_MASK, .entry_count = 2, .entries = e};
    p.labels = &ls;
    int rc = vxl_render(R, &p, IMG, NULL);
    CHECKF(rc == VXL_OK, "%s", vxl_renderer_error(R));
    /* the base shows left of x = -1 and not right of x = 1 (away from the ball), the ball shows */
    double left = 0, right = 0, ball = 0;
    for (int j = 0; j < W; j++)
        for (int i = 0; i < W; i++) {
            double x = px_c(i), y = px_c(j), al = IMG[4 * (i + W * j) + 3];
            double dx = x - BALL_AT[0], dy = y - BALL_AT[1];
            if (x < -1 && fabs(y) < 7) left += al;
            if (x > 1 && x < 5 && fabs(y) < 7) right += al;
            if (dx * dx + dy * dy < 1) ball += al;
        }
    CHECKF(left > 10 && right == 0 && ball > 1, "base alpha %.3f left, %.3f right (masked), ball %.3f", left, right, ball);
    vxl_renderer_destroy(R); /* a fresh renderer for the tests after: see above */
    R = make_renderer(software_backend());
    REQUIRE(R);
}

TEST(every_shading_model_lights_the_overlays)
{
    vxl_render_params p;
    vxl_overlay_style s;
    REQUIRE(ball_scene(&p, &s) == 0);
    p.shading_off = 0;
    float lit[VXL_SHADING_COUNT];
    for (uint32_t m = 0; m < VXL_SHADING_COUNT; m++) {
        p.shading_model = m;
        if (m == VXL_SHADING_PATH) { /* path tracing does not draw overlays yet: refused by name */
            CHECK(vxl_render(R, &p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT);
            CHECK(strstr(vxl_renderer_error(R), "overlay") != NULL);
            lit[m] = 2;
            continue;
        }
        REQUIRE(vxl_render(R, &p, IMG, NULL) == VXL_OK);
        CHECKF(image_is_sane(IMG, NULL, W * W), "shading model %u", m);
        double sum = 0;
        for (int i = 0; i < W * W; i++) sum += IMG[4 * i] + IMG[4 * i + 1];
        lit[m] = (float)sum;
        CHECKF(lit[m] > 1, "shading model %u: colour %g", m, sum);
    }
    /* shading_off: the table's colour unlit, which Phong's ambient 0.3 +
     * diffuse 0.7 cos never exceeds */
    s.shading_off = 1;
    p.shading_model = VXL_SHADING_PHONG;
    REQUIRE(vxl_render(R, &p, IMG2, NULL) == VXL_OK);
    double unlit = 0;
    for (int i = 0; i < W * W; i++) unlit += IMG2[4 * i] + IMG2[4 * i + 1];
    CHECKF(unlit > lit[VXL_SHADING_PHONG], "unlit colour %g, lit %g", unlit, (double)lit[VXL_SHADING_PHONG]);
    REQUIRE(vxl_renderer_set_overlay(R, 0, NULL) == VXL_OK);
}

/* The blob the copy and skipping tests share: value in (0, 1]. */
static const double BLOB[4] = {C + 1, C - 1, C, 3.5};

TEST(an_identical_copy_as_over_doubles_the_extinction)
{
    REQUIRE(set_base(field_blob, BLOB) == 0);
    double a[16];
    base_affine(a);
    const uint32_t dims[3] = {N, N, N};
    REQUIRE(set_overlay(1, dims, field_blob, BLOB, a) == VXL_OK);
    /* constant opacity (so the doubled table is exactly 1 - (1 - a)^2 at
     * every lookup), colour varying with the value */
    enum { T = 64 };
    static float tf[T * 4], tf2[T * 4];
    const float alpha = 0.05f;
    for (int i = 0; i < T; i++) {
        float x = (float)i / (T - 1);
        tf[4 * i] = tf2[4 * i] = x;
        tf[4 * i + 1] = tf2[4 * i + 1] = 1 - x;
        tf[4 * i + 2] = tf2[4 * i + 2] = 0.5f;
        tf[4 * i + 3] = alpha;
        tf2[4 * i + 3] = (float)(1 - (1 - (double)alpha) * (1 - (double)alpha));
    }
    for (int shaded = 0; shaded < 2; shaded++) {
        vxl_render_params p = scene();
        p.shading_off = (uint32_t)!shaded;
        p.has_window = 1;
        p.window_low = 0;
        p.window_high = 1;
        p.tf_rgba = tf;
        p.tf_size = T;
        vxl_overlay_style s = style(1, VXL_BLEND_OVER, tf, T);
        s.has_window = 1;
        s.window_low = 0;
        s.window_high = 1;
        p.overlay_count = 1;
        p.overlays = &s;
        REQUIRE(vxl_render(R, &p, IMG, NULL) == VXL_OK);
        vxl_render_params q = p;
        q.overlay_count = 0;
        q.overlays = NULL;
        q.tf_rgba = tf2;
        REQUIRE(vxl_render(R, &q, IMG2, NULL) == VXL_OK);
        REQUIRE(alpha_sum(IMG2, W * W) > 100);
        double d = max_diff(IMG, IMG2, (size_t)W * W * 4);
        CHECKF(d < (shaded ? 2e-3 : 2e-4), "shaded %d: max difference %g from the base with doubled extinction", shaded, d);
        /* and it is not the base alone */
        q.tf_rgba = tf;
        REQUIRE(vxl_render(R, &q, IMG2, NULL) == VXL_OK);
        CHECK(max_diff(IMG, IMG2, (size_t)W * W * 4) > 0.02);
    }
    REQUIRE(vxl_renderer_set_overlay(R, 1, NULL) == VXL_OK);
}

/* A volume of constant value as the CPU reference sees it: its box in its
 * voxels, colour and per-voxel opacity, blend. */
typedef struct ref_vol {
    double inv[16];      /* world -> voxel */
    uint32_t dims[3];
    double rgb[3], alpha;
    uint32_t blend;
} ref_vol;

static void invert_affine(const double a[16], double inv[16])
{
    /* a = [M t]: inv = [M^-1, -M^-1 t] */
    double m[9] = {a[0], a[4], a[8], a[1], a[5], a[9], a[2], a[6], a[10]}; /* row-major */
    double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) + m[2] * (m[3] * m[7] - m[4] * m[6]);
    double r[9] = {(m[4] * m[8] - m[5] * m[7]) / det, (m[2] * m[7] - m[1] * m[8]) / det, (m[1] * m[5] - m[2] * m[4]) / det,
                   (m[5] * m[6] - m[3] * m[8]) / det, (m[0] * m[8] - m[2] * m[6]) / det, (m[2] * m[3] - m[0] * m[5]) / det,
                   (m[3] * m[7] - m[4] * m[6]) / det, (m[1] * m[6] - m[0] * m[7]) / det, (m[0] * m[4] - m[1] * m[3]) / det};
    memset(inv, 0, 16 * sizeof *inv);
    for (int row = 0; row < 3; row++) {
        double tr = 0;
        for (int k = 0; k < 3; k++) {
            inv[k * 4 + row] = r[row * 3 + k];
            tr -= r[row * 3 + k] * a[12 + k];
        }
        inv[12 + row] = tr;
    }
    inv[15] = 1;
}

static void to_voxel(const ref_vol *v, const double w[3], double q[3])
{
    for (int r = 0; r < 3; r++) q[r] = v->inv[r] * w[0] + v->inv[4 + r] * w[1] + v->inv[8 + r] * w[2] + v->inv[12 + r];
}

/* The ray's span in t through v's box (ray world o + t d, d = -z). */
static int ref_span(const ref_vol *v, const double o[3], double *ta, double *tb)
{
    double q0[3], q1[3], o1[3] = {o[0], o[1], o[2] - 1};
    to_voxel(v, o, q0);
    to_voxel(v, o1, q1);
    *ta = 0;
    *tb = 1e30;
    for (int a = 0; a < 3; a++) {
        double d = q1[a] - q0[a], lo = -0.5, hi = v->dims[a] - 0.5;
        if (fabs(d) < 1e-12) {
            if (q0[a] < lo || q0[a] > hi) return 0;
            continue;
        }
        double t0 = (lo - q0[a]) / d, t1 = (hi - q0[a]) / d;
        *ta = fmax(*ta, fmin(t0, t1));
        *tb = fmin(*tb, fmax(t0, t1));
    }
    return *ta < *tb;
}

static int ref_inside(const ref_vol *v, const double w[3])
{
    double q[3];
    to_voxel(v, w, q);
    for (int a = 0; a < 3; a++)
        if (!(q[a] >= -0.5 && q[a] <= v->dims[a] - 0.5)) return 0;
    return 1;
}

static double ln_share(double a) { return -log(1 - a); }

/* The header's compositing in double precision: vols[0] is the base (OVER). */
static void ref_pixel(const ref_vol *vols, int n, double x, double y, double out[4])
{
    const double o[3] = {x, y, EYE_Z - NEAR};
    double t0 = 1e30, t1 = 0;
    for (int k = 0; k < n; k++) {
        double a, b;
        if (ref_span(&vols[k], o, &a, &b)) {
            t0 = fmin(t0, a);
            t1 = fmax(t1, b);
        }
    }
    double acc[4] = {0, 0, 0, 0};
    for (int i = 0; t0 < t1 && i < 100000; i++) {
        double t = t0 + i * STEP;
        if (t >= t1) break;
        const double w[3] = {o[0], o[1], o[2] - t};
        double a_over = 0, od = 0, od_rgb[3] = {0, 0, 0};
        for (int k = 0; k < n; k++) {
            if (vols[k].blend != VXL_BLEND_OVER || !ref_inside(&vols[k], w)) continue;
            double a = 1 - pow(1 - vols[k].alpha, STEP);
            a_over = 1 - (1 - a_over) * (1 - a);
            od += ln_share(a);
            for (int c = 0; c < 3; c++) od_rgb[c] += ln_share(a) * vols[k].rgb[c];
        }
        double a_step = a_over, rgb[3], e[3] = {0, 0, 0};
        for (int c = 0; c < 3; c++) rgb[c] = od > 0 ? od_rgb[c] / od : 0;
        for (int k = 0; k < n; k++) { /* MAX ones after the OVER mixture */
            if (vols[k].blend != VXL_BLEND_MAX || !ref_inside(&vols[k], w)) continue;
            double a = 1 - pow(1 - vols[k].alpha, STEP);
            if (a > a_step) {
                a_step = a;
                memcpy(rgb, vols[k].rgb, sizeof rgb);
            }
        }
        for (int k = 0; k < n; k++) {
            if (vols[k].blend != VXL_BLEND_ADD || !ref_inside(&vols[k], w)) continue;
            double a = 1 - pow(1 - vols[k].alpha, STEP);
            for (int c = 0; c < 3; c++) e[c] += a * vols[k].rgb[c];
        }
        for (int c = 0; c < 3; c++) acc[c] += (1 - acc[3]) * (a_step * rgb[c] + e[c]);
        acc[3] += (1 - acc[3]) * a_step;
        if (acc[3] >= 0.99) break;
    }
    for (int c = 0; c < 4; c++) out[c] = fmin(fmax(acc[c], 0), 1);
}

TEST(over_max_and_add_match_a_double_precision_march)
{
    /* constant volumes: every sample is its volume's colour and opacity, so
     * the reference needs no interpolation, only boxes and the blends */
    ref_vol vols[4];
    memset(vols, 0, sizeof vols);
    const double bval = 0.3;
    REQUIRE(set_base(field_const, &bval) == 0);
    double a[16];
    base_affine(a);
    invert_affine(a, vols[0].inv);
    vols[0].dims[0] = vols[0].dims[1] = vols[0].dims[2] = N;
    const double base_rgb[3] = {0.2, 0.4, 0.9};
    memcpy(vols[0].rgb, base_rgb, sizeof base_rgb);
    vols[0].alpha = 0.04;
    vols[0].blend = VXL_BLEND_OVER;
    /* three overlays on other grids, faces off the sample lattice, partly
     * overlapping each other and the base, one reaching out of it */
    const uint32_t dims[3][3] = {{8, 8, 8}, {10, 6, 7}, {5, 9, 6}};
    const double scale[3] = {0.8, 1.1, 1.3}, rz[3] = {0, 25, -15};
    const double ctr[3][3] = {{3.5, 3.5, 3.5}, {4.5, 2.5, 3}, {2, 4, 2.5}};
    const double pos[3][3] = {{-2.07, -1.13, 0.37}, {1.9, 2.2, -2.6}, {6.2, -3.1, 1.45}};
    const double rgb[3][3] = {{0.1, 0.9, 0.2}, {0.95, 0.1, 0.1}, {0.2, 0.3, 1.0}};
    const double alpha[3] = {0.6, 0.2, 0.1}; /* a dense OVER one: its ln share differs from its opacity share by 25% */
    const uint32_t blend[3] = {VXL_BLEND_OVER, VXL_BLEND_MAX, VXL_BLEND_ADD};
    static float tf0[2 * 4], tfk[3][2 * 4];
    const_tf(tf0, 2, (float)base_rgb[0], (float)base_rgb[1], (float)base_rgb[2], 0.04f);
    vxl_overlay_style s[3];
    for (int k = 0; k < 3; k++) {
        double ak[16], val = 0.5 + 0.1 * k;
        affine_srt(ak, scale[k], rz[k], 0, ctr[k], pos[k]);
        REQUIRE(set_overlay((uint32_t)k, dims[k], field_const, &val, ak) == VXL_OK);
        ref_vol *v = &vols[k + 1];
        invert_affine(ak, v->inv);
        memcpy(v->dims, dims[k], sizeof v->dims);
        memcpy(v->rgb, rgb[k], sizeof v->rgb);
        v->alpha = alpha[k];
        v->blend = blend[k];
        const_tf(tfk[k], 2, (float)rgb[k][0], (float)rgb[k][1], (float)rgb[k][2], (float)alpha[k]);
        s[k] = style((uint32_t)k, blend[k], tfk[k], 2);
    }
    /* one blend at a time, then all three (listed out of order: the
     * program combines OVER, then MAX, then ADD whatever the list says) */
    const int sets[4][3] = {{0, -1, -1}, {1, -1, -1}, {2, -1, -1}, {2, 0, 1}};
    for (int c = 0; c < 4; c++) {
        vxl_overlay_style list[3];
        ref_vol rv[4];
        int n = 0;
        rv[0] = vols[0];
        for (int m = 0; m < 3 && sets[c][m] >= 0; m++) {
            list[n] = s[sets[c][m]];
            rv[++n] = vols[sets[c][m] + 1];
        }
        vxl_render_params p = scene();
        p.tf_rgba = tf0;
        p.tf_size = 2;
        p.overlay_count = (uint32_t)n;
        p.overlays = list;
        REQUIRE(vxl_render(R, &p, IMG, NULL) == VXL_OK);
        double worst = 0, covered = 0;
        for (int j = 0; j < W; j++)
            for (int i = 0; i < W; i++) {
                double ref[4];
                ref_pixel(rv, n + 1, px_c(i), px_c(j), ref);
                for (int ch = 0; ch < 4; ch++) worst = fmax(worst, fabs(ref[ch] - IMG[4 * (i + W * j) + ch]));
                covered += ref[3];
            }
        CHECK(covered > 100);
        CHECKF(worst < 2e-3, "case %d (%d overlays): largest difference %g from the double-precision march", c, n, worst);
    }
    for (uint32_t k = 0; k < 3; k++) REQUIRE(vxl_renderer_set_overlay(R, k, NULL) == VXL_OK);
}

TEST(skipping_on_and_off_give_the_same_image)
{
    const double ball[4] = {4, 4, 5, 2.5};
    REQUIRE(set_base(field_ball, ball) == 0);
    /* two sparse overlays on rotated grids, one cubic, far from the base's ball */
    const uint32_t dims[3] = {40, 40, 40};
    const double b1[4] = {26, 20, 20, 5}, c1[3] = {20, 20, 20}, t1[3] = {1, 1, -1};
    const double b2[4] = {12, 26, 20, 5}, c2[3] = {20, 20, 20}, t2[3] = {-1, -0.5, 1};
    double a1[16], a2[16];
    affine_srt(a1, 0.4, 40, 10, c1, t1);
    affine_srt(a2, 0.35, -20, 30, c2, t2);
    REQUIRE(set_overlay(0, dims, field_ball, b1, a1) == VXL_OK);
    REQUIRE(set_overlay(2, dims, field_ball, b2, a2) == VXL_OK);
    static float tf[256 * 4], tf1[256 * 4], tf2[256 * 4];
    step_tf(tf, 256, 1, 1, 1, 0.1f);
    step_tf(tf1, 256, 1, 0.2f, 0.2f, 0.12f);
    step_tf(tf2, 256, 0.2f, 0.2f, 1, 0.15f);
    vxl_overlay_style s[2] = {style(0, VXL_BLEND_OVER, tf1, 256), style(2, VXL_BLEND_ADD, tf2, 256)};
    s[1].interpolation = VXL_INTERP_CUBIC;
    s[1].interpolation_set = 1;
    for (int k = 0; k < 2; k++) {
        s[k].has_window = 1;
        s[k].window_low = 0;
        s[k].window_high = 1;
    }
    for (int shaded = 0; shaded < 2; shaded++) {
        vxl_render_params p = scene();
        p.shading_off = (uint32_t)!shaded;
        p.tf_rgba = tf;
        p.tf_size = 256;
        p.has_window = 1;
        p.window_low = 0;
        p.window_high = 1;
        p.overlay_count = 2;
        p.overlays = s;
        /* no ray reaches 0.99 (no_skip also turns early termination off) */
        REQUIRE(vxl_render(R, &p, IMG, NULL) == VXL_OK);
        vxl_render_stats st1 = {.struct_size = sizeof st1}, st2 = {.struct_size = sizeof st2};
        REQUIRE(vxl_renderer_get_stats(R, &st1) == VXL_OK);
        p.no_skip = 1;
        REQUIRE(vxl_render(R, &p, IMG2, NULL) == VXL_OK);
        REQUIRE(vxl_renderer_get_stats(R, &st2) == VXL_OK);
        REQUIRE(alpha_sum(IMG2, W * W) > 20);
        double d = max_diff(IMG, IMG2, (size_t)W * W * 4);
        CHECKF(d < 1e-6, "shaded %d: skipping changed the image by %g", shaded, d);
        if (getenv("OVERLAYS_VERBOSE"))
            fprintf(stderr, "    shaded %d: difference %g, samples %llu with skipping, %llu without\n", shaded, d,
                    (unsigned long long)st1.samples, (unsigned long long)st2.samples);
        CHECKF(st1.samples * 10 < st2.samples * 7, "shaded %d: %llu samples with skipping, %llu without", shaded,
               (unsigned long long)st1.samples, (unsigned long long)st2.samples);
    }
    REQUIRE(vxl_renderer_set_overlay(R, 0, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_set_overlay(R, 2, NULL) == VXL_OK);
}

TEST(frames_without_overlays_are_unchanged_by_an_overlay_volume)
{
    REQUIRE(set_base(field_blob, BLOB) == 0);
    vxl_render_params p = default_params(W, W);
    p.azimuth_deg = 30;
    p.elevation_deg = 20;
    REQUIRE(vxl_render(R, &p, IMG, NULL) == VXL_OK);
    const uint32_t dims[3] = {8, 8, 8};
    double a[16];
    base_affine(a);
    REQUIRE(set_overlay(0, dims, field_blob, BLOB, a) == VXL_OK);
    REQUIRE(vxl_render(R, &p, IMG2, NULL) == VXL_OK);
    CHECK(memcmp(IMG, IMG2, sizeof IMG) == 0);
    REQUIRE(vxl_renderer_set_overlay(R, 0, NULL) == VXL_OK);
}

/* One render of p with overlays list[0..n) expected to fail with code and a
 * message naming `what`. */
static int fails_with(vxl_render_params p, const vxl_overlay_style *list, uint32_t n, int code, const char *what)
{
    p.overlays = list;
    p.overlay_count = n;
    int rc = vxl_render(R, &p, IMG, NULL);
    if (rc != code || !strstr(vxl_renderer_error(R), what)) {
        fprintf(stderr, "    expected %d naming \"%s\", got %d: %s\n", code, what, rc, vxl_renderer_error(R));
        return 0;
    }
    return 1;
}

TEST(bad_overlays_fail_with_a_message)
{
    REQUIRE(set_base(field_blob, BLOB) == 0);
    const uint32_t dims[3] = {8, 8, 8};
    double a[16];
    base_affine(a);
    vxl_volume *v = make_field(dims, field_blob, BLOB, a);
    REQUIRE(v);
    CHECK(vxl_renderer_set_overlay(R, VXL_MAX_OVERLAYS, v) == VXL_ERR_INVALID_ARGUMENT &&
          strstr(vxl_last_error(), "out of range"));
    REQUIRE(vxl_renderer_set_overlay(R, 0, v) == VXL_OK);
    vxl_volume_destroy(v);
    vxl_render_params p = scene();
    const vxl_overlay_style s = style(0, VXL_BLEND_OVER, NULL, 0);
    /* one bad field per row: the style s with that field spoiled */
    enum { SLOT, UNSET, BLEND, INTERP, RESERVED, STRIDE, SINGULAR, NAN_MODEL, TF_SIZE, BAD_COUNT };
    static const struct {
        int code;
        const char *what;
    } bad[BAD_COUNT] = {{VXL_ERR_INVALID_ARGUMENT, "slot 3"}, {VXL_ERR_STATE, "vxl_renderer_set_overlay"},
                        {VXL_ERR_INVALID_ARGUMENT, "blend"},  {VXL_ERR_INVALID_ARGUMENT, "interpolation"},
                        {VXL_ERR_INVALID_ARGUMENT, "reserved"}, {VXL_ERR_INVALID_ARGUMENT, "struct_size"},
                        {VXL_ERR_INVALID_ARGUMENT, "model"},  {VXL_ERR_INVALID_ARGUMENT, "model"},
                        {VXL_ERR_INVALID_ARGUMENT, "tf_size"}};
    for (int k = 0; k < BAD_COUNT; k++) {
        vxl_overlay_style b = s;
        switch (k) {
        case SLOT: b.slot = 3; break;
        case UNSET: b.slot = 1; break;
        case BLEND: b.blend = 7; break;
        case INTERP: b.interpolation = 9, b.interpolation_set = 1; break;
        case RESERVED: b.reserved = 1; break;
        case STRIDE: b.struct_size = 8; break;
        case SINGULAR: b.has_model = 1; break; /* all zeros */
        case NAN_MODEL:
            b.has_model = 1;
            b.model[0] = b.model[5] = b.model[10] = b.model[15] = 1;
            b.model[12] = NAN;
            break;
        default: b.tf_rgba = IMG2, b.tf_size = 1; break; /* a table of one entry */
        }
        CHECKF(fails_with(p, &b, 1, bad[k].code, bad[k].what), "bad style %d", k);
    }
    vxl_overlay_style two[2] = {s, s};
    CHECK(fails_with(p, two, 2, VXL_ERR_INVALID_ARGUMENT, "twice"));
    vxl_overlay_style four[4] = {s, s, s, s};
    CHECK(fails_with(p, four, 4, VXL_ERR_INVALID_ARGUMENT, "overlay_count"));
    CHECK(fails_with(p, NULL, 1, VXL_ERR_INVALID_ARGUMENT, "NULL"));
    vxl_render_params q = p;
    q.mode = VXL_MODE_MIP;
    CHECK(fails_with(q, &s, 1, VXL_ERR_INVALID_ARGUMENT, "DVR"));
    q = p;
    q.technique = VXL_TECHNIQUE_SLICES2D;
    CHECK(fails_with(q, &s, 1, VXL_ERR_INVALID_ARGUMENT, "technique"));
    q = p;
    q.classify = VXL_CLASSIFY_PREINT;
    CHECK(fails_with(q, &s, 1, VXL_ERR_INVALID_ARGUMENT, "pre-integrated"));
    q = p;
    q.gradient_opacity = VXL_GOPACITY_BOUNDARY;
    CHECK(fails_with(q, &s, 1, VXL_ERR_INVALID_ARGUMENT, "gradient_opacity"));
    /* SURFACE labels with overlays, on a renderer of their own: labels.c
     * leaves GL_UNPACK_ALIGNMENT at 4 after its upload, which makes the base
     * skipping map's upload read past its rows here (2 bricks a row; ASan) */
    vxl_renderer *const keep = R;
    R = make_renderer(software_backend());
    REQUIRE(R);
    REQUIRE(set_base(field_blob, BLOB) == 0);
    v = make_field(dims, field_blob, BLOB, a);
    REQUIRE(v && vxl_renderer_set_overlay(R, 0, v) == VXL_OK);
    vxl_volume_destroy(v);
    static uint8_t ids[8 * 8 * 8];
    vxl_volume_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = sizeof d;
    d.dtype = VXL_DTYPE_U8;
    d.dims[0] = d.dims[1] = d.dims[2] = 8;
    d.data = ids;
    vxl_volume *lv = NULL;
    REQUIRE(vxl_volume_create(&d, NULL, &lv) == VXL_OK);
    REQUIRE(vxl_renderer_set_labels(R, lv) == VXL_OK);
    vxl_volume_destroy(lv);
    vxl_label_style ls = {.struct_size = sizeof ls, .mode = VXL_LABEL_MODE_SURFACE};
    q = p;
    q.labels = &ls;
    CHECK(fails_with(q, &s, 1, VXL_ERR_INVALID_ARGUMENT, "SURFACE"));
    vxl_renderer_destroy(R);
    R = keep;
    /* after all that, the overlay still renders */
    p.overlays = &s;
    p.overlay_count = 1;
    CHECK(vxl_render(R, &p, IMG, NULL) == VXL_OK && image_is_sane(IMG, NULL, W * W));
    REQUIRE(vxl_renderer_set_overlay(R, 0, NULL) == VXL_OK);
    p.overlays = &s;
    CHECK(fails_with(p, &s, 1, VXL_ERR_STATE, "empty"));
}

TEST(over_the_budget_an_overlay_is_refused_and_the_slot_keeps_its_volume)
{
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.backend = software_backend();
    o.memory_budget_bytes = 96 * 1024; /* the 16^3 float base (16 KiB) and an 8^3 overlay fit, a 32^3 one (128 KiB) not */
    vxl_renderer *r = NULL;
    REQUIRE(vxl_renderer_create(&o, &r) == VXL_OK);
    double a[16];
    base_affine(a);
    const uint32_t bd[3] = {N, N, N}, small[3] = {8, 8, 8}, big[3] = {32, 32, 32};
    vxl_volume *base = make_field(bd, field_blob, BLOB, a), *ov = make_field(small, field_blob, BLOB, a),
               *huge = make_field(big, field_blob, BLOB, a);
    REQUIRE(base && ov && huge);
    REQUIRE(vxl_renderer_set_volume(r, base) == VXL_OK);
    REQUIRE(vxl_renderer_set_overlay(r, 0, ov) == VXL_OK);
    static float tf[256 * 4];
    step_tf(tf, 256, 1, 0.5f, 0, 0.3f);
    vxl_render_params p = scene();
    vxl_overlay_style s = style(0, VXL_BLEND_ADD, tf, 256);
    s.has_window = 1;
    s.window_low = 0;
    s.window_high = 1;
    p.overlays = &s;
    p.overlay_count = 1;
    CHECK(vxl_render(r, &p, IMG, NULL) == VXL_OK);
    CHECK(vxl_renderer_set_overlay(r, 0, huge) == VXL_ERR_LIMIT && strstr(vxl_renderer_error(r), "overlay slot 0"));
    CHECK(vxl_render(r, &p, IMG2, NULL) == VXL_OK);
    CHECK(memcmp(IMG, IMG2, sizeof IMG) == 0);
    vxl_volume_destroy(base);
    vxl_volume_destroy(ov);
    vxl_volume_destroy(huge);
    vxl_renderer_destroy(r);
}

int main(void)
{
    R = make_renderer(software_backend());
    if (!R) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    RUN(an_overlay_on_another_grid_lands_where_its_affine_says);
    RUN(a_clip_plane_cuts_the_overlays_too);
    RUN(every_shading_model_lights_the_overlays);
    RUN(mask_labels_mask_the_base_volume_only);
    RUN(an_identical_copy_as_over_doubles_the_extinction);
    RUN(over_max_and_add_match_a_double_precision_march);
    RUN(skipping_on_and_off_give_the_same_image);
    RUN(frames_without_overlays_are_unchanged_by_an_overlay_volume);
    RUN(bad_overlays_fail_with_a_message);
    RUN(over_the_budget_an_overlay_is_refused_and_the_slot_keeps_its_volume);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
