/* test_slice_plane.c - vxl_render_slice (csrc/render/slice_plane.c):
 * the volume resampled on a plane. Against double-precision references of
 * the same voxels: nearest returns the voxel itself, linear the trilinear
 * blend within float rounding, cubic the interpolating B-spline (prefilter
 * and evaluation in double), and on a smooth field the cubic slice is far
 * closer to the field than the linear one. Pixels outside the volume's box
 * have alpha 0. Oblique planes through a rotated, non-uniformly scaled
 * volume; every storage mode gives the same image; bad input is refused
 * with a message and loses nothing. Compressed storage has no cubic slice
 * (it has no spline coefficients, as for the cubic filter) and says so.
 *
 * The colour map is a black-to-white ramp over the data's range, so a
 * pixel's colour is the normalised value the slice sampled. */
#include <stdio.h>
#include <string.h>

#include "harness.h"
#include "test_util.h"

#define W 40
#define H 32
#define NX 13
#define NY 11
#define NZ 9

static vxl_renderer *R;

/* voxel -> world: rotated about z by 30 degrees, spacing (1.5, 1, 2), moved */
static const float MODEL[16] = {1.2990381f, 0.75f, 0, 0, -0.5f, 0.8660254f, 0, 0, 0, 0, 2.0f, 0, 3.0f, -2.0f, 1.0f, 1};

/* An oblique plane through the volume's middle, larger than the volume, so
 * part of the slice lies outside the box. */
static void oblique_plane(float m[16], double tilt)
{
    const double c = cos(tilt), s = sin(tilt);
    /* x axis along (c, 0, s) * 14, y axis along (0, 1, 0) * 12 rotated about x by tilt/2 */
    const double c2 = cos(tilt / 2), s2 = sin(tilt / 2);
    const double mm[16] = {14 * c, 0, 14 * s, 0, 0, 12 * c2, 12 * s2, 0, -s, 0, c, 0, 6.3, 3.1, 9.7, 1};
    for (int i = 0; i < 16; i++) m[i] = (float)mm[i];
}

static vxl_render_params ramp_params(const float tf[8], double lo, double hi)
{
    vxl_render_params p;
    memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.width = W;
    p.height = H;
    p.has_model = 1;
    memcpy(p.model, MODEL, sizeof p.model);
    p.tf_size = 2;
    p.tf_rgba = tf;
    p.has_window = 1;
    p.window_low = (float)lo;
    p.window_high = (float)hi;
    return p;
}

static const float RAMP[8] = {0, 0, 0, 1, 1, 1, 1, 1};

/* u8 voxels with structure and noise: random codes in most bricks, a constant block, a gradient. */
static uint8_t CODES[NX * NY * NZ];

/* affine: voxel -> world for the volume itself (NULL: none, spacing 1) */
static vxl_volume *make_u8(const float *affine)
{
    uint32_t s = 12345;
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++) {
                s = s * 1664525u + 1013904223u;
                uint8_t v = (uint8_t)(s >> 24);
                if (i < 8 && j < 8 && k < 8 && i >= 4) v = 77; /* constant region */
                CODES[i + NX * (j + NY * k)] = v;
            }
    CODES[0] = 0;
    CODES[1] = 255; /* the data range is 0..255, so the ramp's window is the code / 255 */
    vxl_volume_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = sizeof d;
    d.dtype = VXL_DTYPE_U8;
    d.dims[0] = NX;
    d.dims[1] = NY;
    d.dims[2] = NZ;
    d.data = CODES;
    d.has_affine = affine != NULL;
    for (int i = 0; affine && i < 16; i++) d.affine[i] = affine[i];
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, NULL, &v) == VXL_OK ? v : NULL;
}

/* ------------------------------------------------------ double references */

/* Pixel (x, y)'s position in voxel space, in double from the same floats. */
static void pixel_voxel(const float plane[16], int x, int y, double q[3])
{
    double mdl[16], pl[16], u[4] = {(x + 0.5) / W * 2 - 1, (y + 0.5) / H * 2 - 1, 0, 1}, w[4];
    for (int i = 0; i < 16; i++) mdl[i] = MODEL[i], pl[i] = plane[i];
    /* inverse of the affine model: 3x3 inverse by cofactors, then the translation */
    const double *m = mdl;
    double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6], k = m[10];
    double det = a * (e * k - f * h) - b * (d * k - f * g) + c * (d * h - e * g);
    double r[9] = {(e * k - f * h) / det, (c * h - b * k) / det, (b * f - c * e) / det,
                   (f * g - d * k) / det, (a * k - c * g) / det, (c * d - a * f) / det,
                   (d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det};
    for (int i = 0; i < 4; i++) w[i] = pl[i] * u[0] + pl[4 + i] * u[1] + pl[12 + i];
    double t[3] = {w[0] - m[12], w[1] - m[13], w[2] - m[14]};
    for (int i = 0; i < 3; i++) q[i] = r[3 * i] * t[0] + r[3 * i + 1] * t[1] + r[3 * i + 2] * t[2];
}

static int inside_box(const double q[3])
{
    const int n[3] = {NX, NY, NZ};
    for (int i = 0; i < 3; i++)
        if (q[i] < -0.5 || q[i] > n[i] - 0.5) return 0;
    return 1;
}

static int clampi(int v, int n) { return v < 0 ? 0 : v >= n ? n - 1 : v; }

static double vox(const double *vol, int i, int j, int k)
{
    return vol[clampi(i, NX) + NX * (clampi(j, NY) + NY * clampi(k, NZ))];
}

static double trilinear(const double *vol, const double q[3])
{
    int i = (int)floor(q[0]), j = (int)floor(q[1]), k = (int)floor(q[2]);
    double a = q[0] - i, b = q[1] - j, c = q[2] - k, s = 0;
    for (int dz = 0; dz < 2; dz++)
        for (int dy = 0; dy < 2; dy++)
            for (int dx = 0; dx < 2; dx++)
                s += vox(vol, i + dx, j + dy, k + dz) * (dx ? a : 1 - a) * (dy ? b : 1 - b) * (dz ? c : 1 - c);
    return s;
}

/* Interpolating B-spline coefficients along one line (Unser, mirror boundary), in double. */
static void prefilter_line(double *c, int n, int stride)
{
    const double z = sqrt(3.0) - 2, gain = 6;
    double sum = 0, zk = 1;
    for (int k = 0; k < n; k++, zk *= z) sum += zk * gain * c[k * stride];
    c[0] = sum;
    for (int k = 1; k < n; k++) c[k * stride] = gain * c[k * stride] + z * c[(k - 1) * stride];
    c[(n - 1) * stride] = z / (z * z - 1) * (c[(n - 1) * stride] + z * c[(n - 2) * stride]);
    for (int k = n - 2; k >= 0; k--) c[k * stride] = z * (c[(k + 1) * stride] - c[k * stride]);
}

static void bspline_coefficients(double *c)
{
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++) prefilter_line(c + NX * (j + NY * k), NX, 1);
    for (int k = 0; k < NZ; k++)
        for (int i = 0; i < NX; i++) prefilter_line(c + i + NX * NY * k, NY, NX);
    for (int j = 0; j < NY; j++)
        for (int i = 0; i < NX; i++) prefilter_line(c + i + NX * j, NZ, NX * NY);
}

static void bspline_weights(double a, double w[4])
{
    double b = 1 - a;
    w[0] = b * b * b / 6;
    w[1] = (3 * a * a * a - 6 * a * a + 4) / 6;
    w[2] = (-3 * a * a * a + 3 * a * a + 3 * a + 1) / 6;
    w[3] = a * a * a / 6;
}

/* The spline at q, coefficients beyond the edge clamped (as FILTER_CUBIC reads them). */
static double bspline(const double *coef, const double q[3])
{
    int b[3];
    double w[3][4];
    for (int i = 0; i < 3; i++) {
        double f = floor(q[i]);
        b[i] = (int)f - 1;
        bspline_weights(q[i] - f, w[i]);
    }
    double s = 0;
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) s += vox(coef, b[0] + i, b[1] + j, b[2] + k) * w[0][i] * w[1][j] * w[2][k];
    return s;
}

static double NORM[NX * NY * NZ];

static void normalise_codes(void)
{
    for (int i = 0; i < NX * NY * NZ; i++) NORM[i] = CODES[i] / 255.0;
}

/* Largest |slice - reference| over pixels inside the box (within `margin`
 * voxels of its faces excluded when margin > 0); checks alpha 1 inside and
 * RGBA 0 outside. *bad counts alpha mistakes. */
static double compare(const float *img, const float plane[16], double (*ref)(const double q[3]), double margin, int *bad,
                      int *inside_count)
{
    double worst = 0;
    *bad = 0;
    *inside_count = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const float *px = img + 4 * (y * W + x);
            double q[3];
            pixel_voxel(plane, x, y, q);
            /* positions within float rounding of the box's faces may go either way */
            double edge = 1e9;
            const int n[3] = {NX, NY, NZ};
            for (int i = 0; i < 3; i++) edge = fmin(edge, fmin(fabs(q[i] + 0.5), fabs(q[i] - (n[i] - 0.5))));
            if (edge < 1e-4) continue;
            if (!inside_box(q)) {
                if (px[0] != 0 || px[1] != 0 || px[2] != 0 || px[3] != 0) ++*bad;
                continue;
            }
            if (px[3] != 1.0f) ++*bad;
            ++*inside_count;
            int near_face = 0;
            for (int i = 0; i < 3; i++) near_face |= q[i] < margin - 0.5 || q[i] > n[i] - 0.5 - margin;
            if (margin > 0 && near_face) continue;
            double want = fmin(1, fmax(0, ref(q))); /* the ramp's window clamps (the cubic overshoots) */
            for (int c = 0; c < 3; c++) worst = fmax(worst, fabs(px[c] - want));
        }
    return worst;
}

static double ref_nearest(const double q[3])
{
    return vox(NORM, (int)floor(q[0] + 0.5), (int)floor(q[1] + 0.5), (int)floor(q[2] + 0.5));
}
static double ref_linear(const double q[3]) { return trilinear(NORM, q); }
static double COEF[NX * NY * NZ];
static double ref_cubic(const double q[3]) { return bspline(COEF, q); }

static int render_slice(vxl_renderer *r, const vxl_render_params *p, uint32_t interp, const float plane[16], float *img)
{
    vxl_slice_params s = {.struct_size = sizeof s, .interpolation = interp};
    memcpy(s.plane_to_world, plane, sizeof s.plane_to_world);
    return vxl_render_slice(r, p, &s, img);
}

/* ------------------------------------------------------------------ tests */

TEST(nearest_linear_and_cubic_match_double_references)
{
    vxl_volume *v = make_u8(NULL);
    REQUIRE(v && vxl_renderer_set_volume(R, v) == VXL_OK);
    normalise_codes();
    memcpy(COEF, NORM, sizeof COEF);
    bspline_coefficients(COEF);
    static float img[W * H * 4];
    vxl_render_params p = ramp_params(RAMP, 0, 255);
    const double tilts[3] = {0.0, 0.4, 1.1};
    for (int t = 0; t < 3; t++) {
        float plane[16];
        oblique_plane(plane, tilts[t]);
        int bad, n;
        /* nearest: the voxel itself (positions within 1e-4 of a voxel boundary could round either way) */
        REQUIRE(render_slice(R, &p, VXL_INTERP_NEAREST, plane, img) == VXL_OK);
        double worst = 0;
        int bad_n = 0, n_n = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                double q[3];
                pixel_voxel(plane, x, y, q);
                int ambiguous = 0;
                for (int i = 0; i < 3; i++) ambiguous |= fabs(q[i] - floor(q[i]) - 0.5) < 1e-4;
                if (ambiguous || !inside_box(q)) continue;
                n_n++;
                const float *px = img + 4 * (y * W + x);
                worst = fmax(worst, fabs(px[0] - ref_nearest(q)));
                bad_n += px[3] != 1.0f;
            }
        CHECKF(worst <= 1e-7 && bad_n == 0 && n_n > 100, "tilt %.1f nearest: worst %g, %d bad alphas, %d pixels",
               tilts[t], worst, bad_n, n_n);
        compare(img, plane, ref_nearest, 0, &bad, &n);
        CHECKF(bad == 0, "tilt %.1f nearest: %d pixels with the wrong alpha", tilts[t], bad);
        CHECKF(n > 100 && n < W * H - 50, "tilt %.1f: %d pixels inside: the plane should leave the box", tilts[t], n);

        REQUIRE(render_slice(R, &p, VXL_INTERP_LINEAR, plane, img) == VXL_OK);
        worst = compare(img, plane, ref_linear, 0, &bad, &n);
        fprintf(stderr, "    tilt %.1f: linear worst %.2g", tilts[t], worst);
        CHECKF(worst < 1e-5 && bad == 0, "tilt %.1f linear: worst %g, %d bad alphas", tilts[t], worst, bad);

        REQUIRE(render_slice(R, &p, VXL_INTERP_CUBIC, plane, img) == VXL_OK);
        worst = compare(img, plane, ref_cubic, 0, &bad, &n);
        fprintf(stderr, ", cubic worst %.2g\n", worst);
        CHECKF(worst < 1e-5 && bad == 0, "tilt %.1f cubic: worst %g, %d bad alphas", tilts[t], worst, bad);
    }
    vxl_volume_destroy(v);
}

/* The cubic spline interpolates: a plane through voxel centres returns the
 * voxels (away from the faces, where the clamped coefficients differ from
 * the mirror extension the prefilter assumes); linear does too. */
TEST(planes_through_voxel_centres_return_the_voxels)
{
    vxl_volume *v = make_u8(NULL);
    REQUIRE(v && vxl_renderer_set_volume(R, v) == VXL_OK);
    normalise_codes();
    /* world point of voxel (i, j, 4): pixel (x, y) at voxel (x * NX / W ...) is awkward, so
     * put the plane in voxel space: a W x H grid whose pixel centres are voxel centres */
    vxl_render_params p = ramp_params(RAMP, 0, 255);
    const float id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    memcpy(p.model, id, sizeof id);
    p.width = NX;
    p.height = NY;
    /* pixel x centre at u = (x + 0.5) / NX * 2 - 1 -> voxel x: scale NX / 2, offset (NX - 1) / 2 */
    const float plane[16] = {NX / 2.0f, 0, 0, 0, 0, NY / 2.0f, 0, 0, 0, 0, 1, 0, (NX - 1) / 2.0f, (NY - 1) / 2.0f, 4, 1};
    static float img[NX * NY * 4];
    for (uint32_t interp = 0; interp < VXL_INTERP_COUNT; interp++) {
        REQUIRE(render_slice(R, &p, interp, plane, img) == VXL_OK);
        double worst = 0;
        for (int j = 1; j < NY - 1; j++)
            for (int i = 1; i < NX - 1; i++) worst = fmax(worst, fabs(img[4 * (j * NX + i)] - NORM[i + NX * (j + NY * 4)]));
        CHECKF(worst < (interp == VXL_INTERP_CUBIC ? 1e-5 : 1e-6), "%s: worst %g at voxel centres",
               vxl_interpolation_name(interp), worst);
    }
    vxl_volume_destroy(v);
}

/* A smooth field: the cubic slice converges to the field much faster than
 * the linear one (fourth against second order in the spacing). */
static const double FREQ[3] = {0.35, 0.27, 0.31};
static double smooth(double x, double y, double z, const double *prm)
{
    (void)prm;
    return sin(FREQ[0] * x + 0.3) * cos(FREQ[1] * y - 0.2) * sin(FREQ[2] * z + 1.0);
}
static double FIELD_LO, FIELD_HI;
static double ref_field(const double q[3]) { return (smooth(q[0], q[1], q[2], NULL) - FIELD_LO) / (FIELD_HI - FIELD_LO); }

TEST(cubic_converges_to_a_smooth_field)
{
    vxl_volume *v = make_volume_f32(NX, NY, NZ, smooth, NULL);
    REQUIRE(v && vxl_renderer_set_volume(R, v) == VXL_OK);
    vxl_volume_info info = {.struct_size = sizeof info};
    REQUIRE(vxl_volume_get_info(v, &info) == VXL_OK);
    FIELD_LO = info.value_min;
    FIELD_HI = info.value_max;
    vxl_render_params p = ramp_params(RAMP, FIELD_LO, FIELD_HI);
    float plane[16];
    oblique_plane(plane, 0.4);
    static float img[W * H * 4];
    int bad, n;
    REQUIRE(render_slice(R, &p, VXL_INTERP_LINEAR, plane, img) == VXL_OK);
    double lin = compare(img, plane, ref_field, 3, &bad, &n);
    REQUIRE(render_slice(R, &p, VXL_INTERP_CUBIC, plane, img) == VXL_OK);
    double cub = compare(img, plane, ref_field, 3, &bad, &n);
    fprintf(stderr, "    smooth field, 3 voxels from the faces: linear %.3g, cubic %.3g\n", lin, cub);
    CHECKF(cub < lin / 4 && cub < 2e-3, "cubic %g vs linear %g", cub, lin);
    vxl_volume_destroy(v);
}

/* has_model 0: the volume's own affine places it. */
TEST(the_volume_affine_places_the_slice)
{
    vxl_volume *v = make_u8(MODEL);
    REQUIRE(v && vxl_renderer_set_volume(R, v) == VXL_OK);
    normalise_codes();
    vxl_render_params p = ramp_params(RAMP, 0, 255);
    p.has_model = 0;
    memset(p.model, 0, sizeof p.model);
    float plane[16];
    oblique_plane(plane, 0.7);
    static float img[W * H * 4];
    REQUIRE(render_slice(R, &p, VXL_INTERP_LINEAR, plane, img) == VXL_OK);
    int bad, n;
    double worst = compare(img, plane, ref_linear, 0, &bad, &n);
    CHECKF(worst < 1e-5 && bad == 0 && n > 100, "worst %g, %d bad alphas, %d inside", worst, bad, n);
    vxl_volume_destroy(v);
}

static vxl_renderer *make_stored(uint32_t storage)
{
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.backend = software_backend();
    o.storage = storage;
    o.page_brick = 8;
    vxl_renderer *r = NULL;
    return vxl_renderer_create(&o, &r) == VXL_OK ? r : NULL;
}

/* Dense, bricked, sparse and compressed (u8: every brick's palette holds
 * all its codes, so exact) give the same slice. A preset colour map too. */
TEST(every_storage_mode_gives_the_same_image)
{
    const uint32_t modes[4] = {VXL_STORAGE_DENSE, VXL_STORAGE_BRICKED, VXL_STORAGE_SPARSE, VXL_STORAGE_COMPRESSED};
    vxl_renderer *rs[4];
    static float img[4][W * H * 4];
    vxl_volume *v = make_u8(NULL);
    REQUIRE(v);
    for (int m = 0; m < 4; m++) {
        rs[m] = make_stored(modes[m]);
        REQUIRE(rs[m] && vxl_renderer_set_volume(rs[m], v) == VXL_OK);
    }
    float plane[16];
    oblique_plane(plane, 0.9);
    for (uint32_t interp = 0; interp < VXL_INTERP_COUNT; interp++)
        for (int preset = 0; preset < 2; preset++) {
            vxl_render_params p = ramp_params(RAMP, 0, 255);
            if (preset) {
                p.tf_size = 0;
                p.tf_rgba = NULL;
                p.preset = VXL_PRESET_HOT;
                p.window_low = 20;
                p.window_high = 200;
            }
            /* compressed storage keeps its values only as codes on the GL side, so it
             * has no cubic coefficients (as for the cubic filter): it says so */
            const int n = interp == VXL_INTERP_CUBIC ? 3 : 4;
            for (int m = 0; m < n; m++) {
                int rc = render_slice(rs[m], &p, interp, plane, img[m]);
                CHECKF(rc == VXL_OK, "%s %s: %s", vxl_storage_name(modes[m]), vxl_interpolation_name(interp),
                       vxl_last_error());
            }
            if (n == 3) {
                CHECK(render_slice(rs[3], &p, interp, plane, img[3]) == VXL_ERR_STATE);
                CHECKF(strstr(vxl_last_error(), "compressed") != NULL, "%s", vxl_last_error());
            }
            for (int m = 1; m < n; m++) {
                double worst = 0;
                for (int i = 0; i < W * H * 4; i++) worst = fmax(worst, fabs(img[m][i] - img[0][i]));
                /* the cubic's coefficients are prefiltered per brick with a margin on the bricked modes */
                double tol = interp == VXL_INTERP_CUBIC ? 2e-4 : 1e-7;
                CHECKF(worst <= tol, "%s vs dense, %s%s: worst %g", vxl_storage_name(modes[m]),
                       vxl_interpolation_name(interp), preset ? " (hot preset)" : "", worst);
            }
            CHECK(alpha_sum(img[0], W * H) > 100);
        }
    for (int m = 0; m < 4; m++) vxl_renderer_destroy(rs[m]);
    vxl_volume_destroy(v);
}

TEST(bad_input_is_refused_and_loses_nothing)
{
    vxl_volume *v = make_u8(NULL);
    REQUIRE(v);
    vxl_renderer *fresh = make_renderer(software_backend());
    REQUIRE(fresh);
    static float img[W * H * 4];
    vxl_render_params p = ramp_params(RAMP, 0, 255);
    float plane[16];
    oblique_plane(plane, 0.3);
    /* no volume yet */
    CHECK(render_slice(fresh, &p, VXL_INTERP_LINEAR, plane, img) == VXL_ERR_STATE);
    REQUIRE(vxl_renderer_set_volume(fresh, v) == VXL_OK);
    static float good[W * H * 4];
    REQUIRE(render_slice(fresh, &p, VXL_INTERP_LINEAR, plane, good) == VXL_OK);

    CHECK(render_slice(fresh, &p, 3, plane, img) == VXL_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(vxl_last_error(), "interpolation") != NULL, "%s", vxl_last_error());
    float sing[16];
    memcpy(sing, plane, sizeof sing);
    for (int i = 0; i < 3; i++) sing[4 + i] = 2 * sing[i]; /* y axis parallel to x */
    CHECK(render_slice(fresh, &p, VXL_INTERP_LINEAR, sing, img) == VXL_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(vxl_last_error(), "singular") != NULL, "%s", vxl_last_error());
    memcpy(sing, plane, sizeof sing);
    sing[13] = NAN;
    CHECK(render_slice(fresh, &p, VXL_INTERP_LINEAR, sing, img) == VXL_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(vxl_last_error(), "not finite") != NULL, "%s", vxl_last_error());
    memcpy(sing, plane, sizeof sing);
    sing[3] = 0.5f; /* projective */
    CHECK(render_slice(fresh, &p, VXL_INTERP_LINEAR, sing, img) == VXL_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(vxl_last_error(), "affine") != NULL, "%s", vxl_last_error());
    /* a singular placement of the volume */
    vxl_render_params q = p;
    memset(q.model, 0, sizeof q.model);
    CHECK(render_slice(fresh, &q, VXL_INTERP_LINEAR, plane, img) == VXL_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(vxl_last_error(), "singular") != NULL, "%s", vxl_last_error());
    /* a bad window or table is the frame's error as in vxl_render */
    q = p;
    q.window_low = NAN;
    CHECK(render_slice(fresh, &q, VXL_INTERP_LINEAR, plane, img) == VXL_ERR_INVALID_ARGUMENT);
    q = p;
    q.width = 20000;
    CHECK(render_slice(fresh, &q, VXL_INTERP_LINEAR, plane, img) == VXL_ERR_LIMIT);
    vxl_slice_params s = {.struct_size = 4};
    CHECK(vxl_render_slice(fresh, &p, &s, img) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_render_slice(fresh, &p, NULL, img) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_render_slice(NULL, &p, &s, img) == VXL_ERR_INVALID_ARGUMENT);
    /* what the slice does not read is not checked: a bad mode or camera does not fail it */
    q = p;
    q.mode = 99;
    q.has_camera = 1; /* a zero camera */
    CHECKF(render_slice(fresh, &q, VXL_INTERP_LINEAR, plane, img) == VXL_OK, "%s", vxl_last_error());
    CHECK(memcmp(img, good, sizeof img) == 0);
    /* nothing lost: the same slice again */
    REQUIRE(render_slice(fresh, &p, VXL_INTERP_LINEAR, plane, img) == VXL_OK);
    CHECK(memcmp(img, good, sizeof img) == 0);
    vxl_renderer_destroy(fresh);
    vxl_volume_destroy(v);
}

int main(void)
{
    if (!(R = make_renderer(software_backend()))) return printf("0 passed, 1 failed (no renderer)\n"), 1;
    RUN(nearest_linear_and_cubic_match_double_references);
    RUN(planes_through_voxel_centres_return_the_voxels);
    RUN(cubic_converges_to_a_smooth_field);
    RUN(the_volume_affine_places_the_slice);
    RUN(every_storage_mode_gives_the_same_image);
    RUN(bad_input_is_refused_and_loses_nothing);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
