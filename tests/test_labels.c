/* test_labels.c - label maps (csrc/labels/, csrc/frame/frame_labels.c,
 * shaders/lib/labels.glsl): hiding a label removes exactly its pixels, two
 * labels touching along a plane meet on a straight line, a sphere labelled
 * on a 32^3 grid renders round (silhouette and depth against the analytic
 * sphere), a label volume on another grid lands where its affine says,
 * recolouring re-uploads only the table, 256 labels with ids across the
 * whole id range, MASK and TINT, bad input, and no NaN in odd cameras;
 * smooth boundaries shade a labelled sphere without the raw voxels' stairs.
 *
 * The scene: world coordinates are voxels of the 32^3 intensity grid
 * shifted by -15.5 (the grid spans [-16, 16]), seen by an orthographic
 * camera on world +z looking down -z, so pixel (i, j) looks along x = X(i),
 * y = Y(j) and the depth output is EYE_Z - z. */
#include <stddef.h>
#include <stdio.h>

#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h"

#define N 32
#define EYE_Z 40.0
#define MAXW 256

static vxl_renderer *R;
static float IMG[MAXW * MAXW * 4], IMG2[MAXW * MAXW * 4], DEP[MAXW * MAXW];
static uint16_t LAB[N * N * N];

static double px_c(int i, int w, double half) { return -half + (i + 0.5) * 2 * half / w; }

/* Unshaded orthographic view of half-width `half` (world units) at w x w. */
static vxl_render_params scene(int w, double half)
{
    vxl_render_params p = default_params((uint32_t)w, (uint32_t)w);
    p.jitter_off = 1;
    p.shading_off = 1;
    p.has_camera = 1;
    memset(p.view, 0, sizeof p.view);
    memset(p.proj, 0, sizeof p.proj);
    p.view[0] = p.view[5] = p.view[10] = p.view[15] = 1;
    p.view[14] = (float)-EYE_Z;
    const double n = 1, f = 100;
    p.proj[0] = p.proj[5] = (float)(1 / half);
    p.proj[10] = (float)(-2 / (f - n));
    p.proj[14] = (float)(-(f + n) / (f - n));
    p.proj[15] = 1;
    return p;
}

/* voxel -> world: scale s, then shifted so voxel c lands on world 0 + shift. */
static void grid_affine(double a[16], double s, double c, const double shift[3])
{
    memset(a, 0, 16 * sizeof *a);
    for (int k = 0; k < 3; k++) {
        a[k * 5] = s;
        a[12 + k] = -c * s + (shift ? shift[k] : 0);
    }
    a[15] = 1;
}

static vxl_volume *make_volume(uint32_t dtype, const void *data, uint32_t n, const double affine[16])
{
    vxl_volume_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = sizeof d;
    d.dtype = dtype;
    d.dims[0] = d.dims[1] = d.dims[2] = n;
    d.data = data;
    d.has_affine = 1;
    memcpy(d.affine, affine, sizeof d.affine);
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, NULL, &v) == VXL_OK ? v : NULL;
}

/* Sets LAB (N^3 u16, already filled) as the renderer's label volume on the
 * intensity grid. */
static int set_lab(void)
{
    double a[16];
    grid_affine(a, 1, 15.5, NULL);
    vxl_volume *v = make_volume(VXL_DTYPE_U16, LAB, N, a);
    if (!v) return VXL_ERR_INVALID_ARGUMENT;
    int rc = vxl_renderer_set_labels(R, v);
    vxl_volume_destroy(v);
    return rc;
}

static vxl_label_entry entry(int id, float r, float g, float b, float a, int visible)
{
    vxl_label_entry e;
    memset(&e, 0, sizeof e);
    e.struct_size = sizeof e;
    e.id = id;
    e.color[0] = r;
    e.color[1] = g;
    e.color[2] = b;
    e.color[3] = a;
    e.visible = (uint32_t)visible;
    return e;
}

static vxl_label_style style(uint32_t mode, const vxl_label_entry *e, uint32_t n)
{
    vxl_label_style s = {.struct_size = sizeof s, .mode = mode, .entry_count = n, .entries = e};
    return s;
}

static int render(const vxl_render_params *p, float *img, float *dep)
{
    return vxl_render(R, p, img, dep);
}

/* The label id a pixel shows, from its colour (colour_of below): -1 none. */
static int colour_id(const float *px)
{
    if (px[3] < 0.5f) return -1;
    return (int)lround(px[0] * 15) + 16 * (int)lround(px[1] * 15);
}

static vxl_label_entry colour_entry(int id, int k)
{
    return entry(id, (float)(k % 16) / 15.0f, (float)(k / 16) / 15.0f, 0.5f, 1, 1);
}

/* Three overlapping boxes at different depths: id 1 in front, 2, 3 behind. */
static void three_boxes(void)
{
    memset(LAB, 0, sizeof LAB);
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) {
                uint16_t id = 0;
                if (z >= 20 && z < 26 && x >= 4 && x < 16 && y >= 6 && y < 20) id = 1;
                else if (z >= 12 && z < 18 && x >= 10 && x < 24 && y >= 10 && y < 26) id = 2;
                else if (z >= 4 && z < 10 && x >= 6 && x < 28 && y >= 4 && y < 28) id = 3;
                LAB[x + N * (y + N * z)] = id;
            }
}

TEST(hiding_a_label_removes_exactly_its_pixels)
{
    three_boxes();
    REQUIRE(set_lab() == VXL_OK);
    const int w = 64;
    vxl_label_entry e[3] = {colour_entry(1, 1), colour_entry(2, 2), colour_entry(3, 3)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 3);
    vxl_render_params p = scene(w, 17);
    p.labels = &s;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    int seen[4] = {0};
    for (int i = 0; i < w * w; i++) {
        int id = colour_id(IMG + 4 * i);
        if (id >= 1 && id <= 3) seen[id]++;
    }
    CHECKF(seen[1] > 50 && seen[2] > 50 && seen[3] > 50, "pixels per label %d %d %d", seen[1], seen[2], seen[3]);
    e[1].visible = 0;
    REQUIRE(render(&p, IMG2, NULL) == VXL_OK);
    int wrong = 0, changed = 0;
    for (int i = 0; i < w * w; i++) {
        int was = colour_id(IMG + 4 * i), now = colour_id(IMG2 + 4 * i);
        int differs = memcmp(IMG + 4 * i, IMG2 + 4 * i, 4 * sizeof(float)) != 0;
        changed += differs;
        if (differs != (was == 2) || now == 2) wrong++;
    }
    CHECKF(wrong == 0 && changed == seen[2], "%d pixels wrong, %d changed, label 2 had %d", wrong, changed, seen[2]);
}

TEST(two_labels_touching_along_a_plane_meet_on_a_straight_line)
{
    /* the plane 0.8 x + 0.6 y = 0 through the centre, seen edge-on along z */
    memset(LAB, 0, sizeof LAB);
    for (int z = 8; z < 24; z++)
        for (int y = 2; y < 30; y++)
            for (int x = 2; x < 30; x++) LAB[x + N * (y + N * z)] = 0.8 * (x - 15.5) + 0.6 * (y - 15.5) < 0 ? 1 : 2;
    REQUIRE(set_lab() == VXL_OK);
    const int w = 96;
    const double half = 12;
    vxl_label_entry e[2] = {colour_entry(1, 15), colour_entry(2, 16 * 15)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 2);
    vxl_render_params p = scene(w, half);
    p.labels = &s;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    /* per row, where label 1 (red) turns into label 2 (green) along x */
    double xs[MAXW], ys[MAXW];
    int n = 0;
    for (int j = 8; j < w - 8; j++) {
        int first2 = -1;
        for (int i = 0; i < w; i++)
            if (colour_id(IMG + 4 * (j * w + i)) == 16 * 15 && i > 0 && colour_id(IMG + 4 * (j * w + i - 1)) == 15) {
                first2 = i;
                break;
            }
        if (first2 < 0) continue;
        xs[n] = first2 - 0.5; /* the edge between the two pixels */
        ys[n++] = j;
    }
    REQUIRE(n > 40);
    double sy = 0, sx = 0, syy = 0, sxy = 0;
    for (int k = 0; k < n; k++) {
        sy += ys[k];
        sx += xs[k];
        syy += ys[k] * ys[k];
        sxy += xs[k] * ys[k];
    }
    double m = (n * sxy - sx * sy) / (n * syy - sy * sy), q = (sx - m * sy) / n, worst = 0;
    for (int k = 0; k < n; k++) worst = fmax(worst, fabs(xs[k] - (m * ys[k] + q)));
    /* the boundary is x = -0.75 y: that slope in pixels too */
    CHECKF(fabs(m + 0.75) < 0.03, "slope %g, expected -0.75", m);
    /* in voxels (a pixel is 0.25 voxel here): the boundary between voxel
     * centres is resolved to a fraction of a voxel, stairs would zigzag by
     * a whole one. Measured: rms 0.17, largest 0.32 voxel. */
    const double vox = w / (2 * half);
    CHECKF(worst / vox < 0.5, "largest residual %g voxels", worst / vox);
    double rms = 0;
    for (int k = 0; k < n; k++) rms += (xs[k] - (m * ys[k] + q)) * (xs[k] - (m * ys[k] + q));
    rms = sqrt(rms / n);
    CHECKF(rms / vox < 0.25, "rms residual %g voxels", rms / vox);
}

/* The sphere of radius RS around CS (world units = voxels) labelled on the grid. */
#define RS 10.0
static const double CS[3] = {0, 0, 0};

static void sphere_labels(void)
{
    memset(LAB, 0, sizeof LAB);
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) {
                double dx = x - 15.5 - CS[0], dy = y - 15.5 - CS[1], dz = z - 15.5 - CS[2];
                LAB[x + N * (y + N * z)] = dx * dx + dy * dy + dz * dz <= RS * RS ? 7 : 0;
            }
}

/* The image's alpha at fractional pixel (u, v), bilinear. */
static double alpha_at(const float *img, int w, double u, double v)
{
    int i = (int)floor(u), j = (int)floor(v);
    double fu = u - i, fv = v - j, s = 0;
    for (int b = 0; b < 2; b++)
        for (int a = 0; a < 2; a++) {
            int ii = i + a, jj = j + b;
            double px = (ii < 0 || jj < 0 || ii >= w || jj >= w) ? 0 : img[4 * (jj * w + ii) + 3];
            s += px * (a ? fu : 1 - fu) * (b ? fv : 1 - fv);
        }
    return s;
}

TEST(a_labelled_sphere_renders_round)
{
    sphere_labels();
    REQUIRE(set_lab() == VXL_OK);
    const int w = 192;
    const double half = 12, px = 2 * half / w; /* 0.125 voxel a pixel */
    vxl_label_entry e[1] = {entry(7, 1, 1, 1, 1, 1)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 1);
    vxl_render_params p = scene(w, half);
    p.labels = &s;
    REQUIRE(render(&p, IMG, DEP) == VXL_OK);
    /* silhouette: along 90 directions, where the bilinear alpha falls to 0.5 */
    double uc = (CS[0] + half) / px - 0.5, vc = (CS[1] + half) / px - 0.5, lo = 1e9, hi = -1e9, rms = 0;
    for (int k = 0; k < 90; k++) {
        double th = 2 * M_PI * k / 90, rr = 0;
        for (double rp = 0.5 * RS / px; rp < 1.5 * RS / px; rp += 0.02)
            if (alpha_at(IMG, w, uc + rp * cos(th), vc + rp * sin(th)) < 0.5) {
                rr = rp * px;
                break;
            }
        lo = fmin(lo, rr);
        hi = fmax(hi, rr);
        rms += (rr - RS) * (rr - RS) / 90;
    }
    /* The labels place each boundary only between two voxel centres; the
     * filtered indicator's 0.5 level keeps within a quarter voxel of the
     * sphere (rms well under it); stairs would put it up to half a voxel off
     * everywhere. Measured: rms 0.155, extremes [9.74, 10.26]. */
    rms = sqrt(rms);
    CHECKF(rms < 0.2 && RS - lo < 0.3 && hi - RS < 0.3, "silhouette radius over [%g, %g] voxels, rms off the sphere %g", lo,
           hi, rms);
    CHECKF(fabs(0.5 * (lo + hi) - RS) < 0.5, "silhouette radius %g, sphere %g", 0.5 * (lo + hi), RS);
    /* depth: against the analytic sphere within 0.8 of the radius (the rim is steep) */
    double worst = 0, drms = 0;
    int n = 0;
    for (int j = 0; j < w; j++)
        for (int i = 0; i < w; i++) {
            double x = px_c(i, w, half) - CS[0], y = px_c(j, w, half) - CS[1], r2 = x * x + y * y;
            if (r2 > 0.64 * RS * RS) continue;
            double z = CS[2] + sqrt(RS * RS - r2), d = DEP[j * w + i];
            REQUIRE(isfinite(d));
            worst = fmax(worst, fabs(d - (EYE_Z - z)));
            drms += (d - (EYE_Z - z)) * (d - (EYE_Z - z));
            n++;
        }
    drms = sqrt(drms / (n ? n : 1));
    CHECKF(n > 1000 && drms < 0.2 && worst < 0.4, "depth off the analytic sphere by up to %g voxels, rms %g, over %d pixels",
           worst, drms, n);
}

/* The box of label 5 seen from +z: the pixels it covers (alpha > 0.5), their
 * span and centroid in world units, and how many of the pixels at least
 * `rim` inside the expected face [x0, x1] x [y0, y1] are off its depth by
 * more than `tol`. */
typedef struct {
    double x0, x1, y0, y1, cx, cy, worst; /* worst: the largest depth error inside the rim */
    int covered, bad_depth;
} box_view;

static box_view view_box(int w, double half, const double face[4], double depth, double rim, double tol)
{
    box_view b = {1e9, -1e9, 1e9, -1e9, 0, 0, 0, 0, 0};
    for (int j = 0; j < w; j++)
        for (int i = 0; i < w; i++) {
            if (IMG[4 * (j * w + i) + 3] <= 0.5f) continue;
            double x = px_c(i, w, half), y = px_c(j, w, half);
            b.x0 = fmin(b.x0, x);
            b.x1 = fmax(b.x1, x);
            b.y0 = fmin(b.y0, y);
            b.y1 = fmax(b.y1, y);
            b.cx += x;
            b.cy += y;
            b.covered++;
            if (x > face[0] + rim && x < face[1] - rim && y > face[2] + rim && y < face[3] - rim) {
                b.worst = fmax(b.worst, fabs(DEP[j * w + i] - depth));
                b.bad_depth += fabs(DEP[j * w + i] - depth) > tol;
            }
        }
    b.cx /= b.covered ? b.covered : 1;
    b.cy /= b.covered ? b.covered : 1;
    return b;
}

TEST(a_label_volume_on_another_grid_lands_where_its_affine_says)
{
    /* 16^3 voxels of 2 world units, shifted by (3, -2, 1): a box of label 5 at voxels [4, 9]^2 x [5, 10] */
    static uint8_t lab[16 * 16 * 16];
    memset(lab, 0, sizeof lab);
    for (int z = 5; z <= 10; z++)
        for (int y = 4; y <= 9; y++)
            for (int x = 4; x <= 9; x++) lab[x + 16 * (y + 16 * z)] = 5;
    double a[16];
    const double shift[3] = {3, -2, 1};
    grid_affine(a, 2, 7.5, shift);
    vxl_volume *v = make_volume(VXL_DTYPE_U8, lab, 16, a);
    REQUIRE(v);
    REQUIRE(vxl_renderer_set_labels(R, v) == VXL_OK);
    vxl_volume_destroy(v);
    const int w = 128;
    const double half = 16, px = 2 * half / w;
    vxl_label_entry e[1] = {entry(5, 0, 1, 0, 1, 1)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 1);
    vxl_render_params p = scene(w, half);
    p.labels = &s;
    /* the box's faces lie half a voxel beyond its outer centres */
    const double face[4] = {(4 - 0.5 - 7.5) * 2 + 3, (9 + 0.5 - 7.5) * 2 + 3, (4 - 0.5 - 7.5) * 2 - 2,
                            (9 + 0.5 - 7.5) * 2 - 2};
    const double top = EYE_Z - ((10 + 0.5 - 7.5) * 2 + 1);
    /* Placement is what this test is about, so it is checked exactly on the
     * raw voxels, whose faces are the box's own: span to a pixel, the flat
     * top at its depth everywhere but one label voxel's rim. */
    s.boundary = VXL_LABEL_BOUNDARY_VOXELS;
    REQUIRE(render(&p, IMG, DEP) == VXL_OK);
    box_view b = view_box(w, half, face, top, 2, 0.1);
    CHECKF(fabs(b.x0 - face[0]) <= px && fabs(b.x1 - face[1]) <= px, "voxels: x span [%g, %g], expected [%g, %g]", b.x0,
           b.x1, face[0], face[1]);
    CHECKF(fabs(b.y0 - face[2]) <= px && fabs(b.y1 - face[3]) <= px, "voxels: y span [%g, %g], expected [%g, %g]", b.y0,
           b.y1, face[2], face[3]);
    CHECKF(b.bad_depth == 0, "voxels: %d pixels off the top face at depth %g", b.bad_depth, top);
    /* Smooth boundaries (the default) turn a box only 6 voxels wide into a
     * dome: the Gaussian (sigma 1.2 voxels) rounds its rim over about two
     * voxels and its top sags by up to half a voxel there (measured: 0.06
     * voxel in the middle, 0.47 at the rim). So they are checked for
     * placement where smoothing cannot move it: the smoothing is symmetric,
     * so the silhouette's centroid stays on the box's centre (within a
     * quarter pixel), its span within a pixel (the sides' level stays half a
     * voxel out at their middles), and the top's middle (one label voxel
     * across) within 0.1 label voxel of the face. Exact faces are what the
     * voxels boundary is for. */
    s.boundary = VXL_LABEL_BOUNDARY_SMOOTH;
    REQUIRE(render(&p, IMG, DEP) == VXL_OK);
    b = view_box(w, half, face, top, 5, 0.2);
    CHECKF(fabs(b.cx - 0.5 * (face[0] + face[1])) <= 0.25 * px && fabs(b.cy - 0.5 * (face[2] + face[3])) <= 0.25 * px,
           "smooth: centroid (%g, %g), box centre (%g, %g)", b.cx, b.cy, 0.5 * (face[0] + face[1]), 0.5 * (face[2] + face[3]));
    CHECKF(fabs(b.x0 - face[0]) <= px && fabs(b.x1 - face[1]) <= px, "smooth: x span [%g, %g], expected [%g, %g]", b.x0,
           b.x1, face[0], face[1]);
    CHECKF(fabs(b.y0 - face[2]) <= px && fabs(b.y1 - face[3]) <= px, "smooth: y span [%g, %g], expected [%g, %g]", b.y0,
           b.y1, face[2], face[3]);
    CHECKF(b.bad_depth == 0, "smooth: %d pixels of the face's middle off its depth %g by > 0.2 (worst %g)", b.bad_depth,
           top, b.worst);
}

/* The largest and the mean |second difference| of the shading (the red
 * channel of a white label) along the middle row and column of the image,
 * over the pixels within 0.8 of the sphere's radius of its centre. */
static void shading_second_differences(int w, double half, double *worst, double *mean)
{
    *worst = *mean = 0;
    int n = 0;
    for (int axis = 0; axis < 2; axis++)
        for (int k = 1; k < w - 1; k++) {
            int i = axis ? w / 2 : k, j = axis ? k : w / 2, di = axis ? 0 : 1, dj = axis ? 1 : 0;
            double x = px_c(i, w, half) - CS[0], y = px_c(j, w, half) - CS[1];
            if (x * x + y * y > 0.64 * RS * RS) continue;
            const float *c = IMG + 4 * (j * w + i), *a = IMG + 4 * ((j - dj) * w + i - di),
                        *b = IMG + 4 * ((j + dj) * w + i + di);
            double d2 = fabs((double)a[0] - 2.0 * c[0] + b[0]);
            *worst = fmax(*worst, d2);
            *mean += d2;
            n++;
        }
    *mean /= n ? n : 1;
}

TEST(smooth_boundaries_shade_a_labelled_sphere_without_stairs)
{
    /* The sphere labelled on a grid turned 30 degrees about x and 20 about
     * y, so its voxels' faces are oblique to the view and the headlight:
     * raw voxels then shade as facets, one step every few pixels. */
    sphere_labels();
    double a[16], r[16];
    grid_affine(a, 1, 15.5, NULL);
    const double ax = 30 * M_PI / 180, ay = 20 * M_PI / 180;
    const double rx[9] = {1, 0, 0, 0, cos(ax), sin(ax), 0, -sin(ax), cos(ax)}; /* column-major 3x3 */
    const double ry[9] = {cos(ay), 0, -sin(ay), 0, 1, 0, sin(ay), 0, cos(ay)};
    memset(r, 0, sizeof r);
    r[15] = 1;
    for (int c = 0; c < 3; c++) /* r = ry rx a: the grid turned about the sphere's centre (world 0) */
        for (int k = 0; k < 4; k++) {
            double v[3] = {a[4 * k], a[4 * k + 1], a[4 * k + 2]}, t[3], u = 0;
            for (int m = 0; m < 3; m++) t[m] = rx[m] * v[0] + rx[3 + m] * v[1] + rx[6 + m] * v[2];
            u = ry[c] * t[0] + ry[3 + c] * t[1] + ry[6 + c] * t[2];
            r[4 * k + c] = u;
        }
    vxl_volume *v = make_volume(VXL_DTYPE_U16, LAB, N, r);
    REQUIRE(v);
    REQUIRE(vxl_renderer_set_labels(R, v) == VXL_OK);
    vxl_volume_destroy(v);
    const int w = 192;
    const double half = 12;
    vxl_label_entry e[1] = {entry(7, 1, 1, 1, 1, 1)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 1);
    vxl_render_params p = scene(w, half);
    p.shading_off = 0;
    p.labels = &s;
    double smooth_worst, smooth_mean, voxels_worst, voxels_mean;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    shading_second_differences(w, half, &smooth_worst, &smooth_mean);
    s.boundary = VXL_LABEL_BOUNDARY_VOXELS;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    shading_second_differences(w, half, &voxels_worst, &voxels_mean);
    /* Measured: smooth worst 0.0155, mean 0.00103; voxels worst 0.42, mean
     * 0.055 (27 and 53 times as much). Smooth shading turns slowly: every
     * |second difference| under 0.03 (twice what was measured); the raw
     * voxels' facets are at least 10 times as steep at worst and 20 times
     * on average, so a smoothing that stops smoothing fails both. */
    CHECKF(smooth_worst < 0.03, "smooth: shading second difference up to %g (mean %g)", smooth_worst, smooth_mean);
    CHECKF(voxels_worst > 10 * smooth_worst && voxels_mean > 20 * smooth_mean,
           "voxels: second differences worst %g, mean %g against smooth %g, %g", voxels_worst, voxels_mean, smooth_worst,
           smooth_mean);
}

TEST(recolouring_and_hiding_re_upload_only_the_table)
{
    three_boxes();
    REQUIRE(set_lab() == VXL_OK);
    uint64_t v0, t0, v1, t1;
    vxl_label_entry e[3] = {colour_entry(1, 1), colour_entry(2, 2), colour_entry(3, 3)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 3);
    vxl_render_params p = scene(32, 17);
    p.labels = &s;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_label_uploads(R, &v0, &t0) == VXL_OK);
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_label_uploads(R, &v1, &t1) == VXL_OK);
    CHECKF(v1 == v0 && t1 == t0, "an unchanged frame uploaded %llu volumes, %llu tables", (unsigned long long)(v1 - v0),
           (unsigned long long)(t1 - t0));
    e[0].color[0] = 0.25f;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    e[2].visible = 0;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_label_uploads(R, &v1, &t1) == VXL_OK);
    CHECKF(v1 == v0 && t1 == t0 + 2, "recolour + hide uploaded %llu volumes, %llu tables", (unsigned long long)(v1 - v0),
           (unsigned long long)(t1 - t0));
    REQUIRE(set_lab() == VXL_OK);
    REQUIRE(vxl_renderer_label_uploads(R, &v1, NULL) == VXL_OK);
    CHECK(v1 == v0 + 1);
}

TEST(two_hundred_fifty_six_labels_across_the_id_range)
{
    /* 16 x 16 columns of 2 voxels along z, id k * 256 + 1 (1 .. 65281) */
    memset(LAB, 0, sizeof LAB);
    for (int z = 4; z < 28; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) LAB[x + N * (y + N * z)] = (uint16_t)(((y / 2) * 16 + x / 2) * 256 + 1);
    REQUIRE(set_lab() == VXL_OK);
    static vxl_label_entry e[256];
    for (int k = 0; k < 256; k++) e[k] = colour_entry(k * 256 + 1, k);
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 256);
    const int w = 128;
    vxl_render_params p = scene(w, 16); /* 4 pixels a voxel */
    p.labels = &s;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    int wrong = 0;
    for (int k = 0; k < 256; k++) {
        int i = (k % 16) * 8 + 4, j = (k / 16) * 8 + 4; /* the column's centre pixel */
        if (colour_id(IMG + 4 * (j * w + i)) != k) wrong++;
    }
    CHECKF(wrong == 0, "%d of 256 labels show the wrong colour", wrong);
    e[100].visible = 0;
    REQUIRE(render(&p, IMG2, NULL) == VXL_OK);
    CHECK(IMG2[4 * ((6 * 8 + 4) * w + 4 * 8 + 4) + 3] == 0.0f); /* label 100 (column 4, 6) is gone */
    CHECK(colour_id(IMG2 + 4 * ((6 * 8 + 4) * w + 5 * 8 + 4)) == 101);
}

TEST(mask_and_tint_apply_the_transfer_function_inside_visible_labels)
{
    three_boxes();
    REQUIRE(set_lab() == VXL_OK);
    static const float tf[8] = {1, 1, 1, 1, 1, 1, 1, 1}; /* white, opaque everywhere */
    vxl_label_entry e[3] = {entry(1, 1, 0, 0, 1, 1), entry(2, 0, 1, 0, 1, 0), entry(3, 0, 0, 1, 1, 1)};
    vxl_label_style s = style(VXL_LABEL_MODE_MASK, e, 3);
    const int w = 64;
    vxl_render_params p = scene(w, 17);
    p.tf_rgba = tf;
    p.tf_size = 2;
    p.labels = &s;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    s.mode = VXL_LABEL_MODE_TINT;
    REQUIRE(render(&p, IMG2, NULL) == VXL_OK);
    int bad = 0, inside = 0;
    for (int j = 0; j < w; j++)
        for (int i = 0; i < w; i++) {
            /* voxel column of the pixel (world = voxel - 15.5) */
            int x = (int)floor(px_c(i, w, 17) + 16), y = (int)floor(px_c(j, w, 17) + 16);
            int in1 = x >= 4 && x < 16 && y >= 6 && y < 20, in3 = x >= 6 && x < 28 && y >= 4 && y < 28;
            int edge = (x <= 4 || x >= 27 || y <= 4 || y >= 27) || ((x == 4 || x == 15) && y >= 6 && y < 20) ||
                       ((y == 6 || y == 19) && x >= 4 && x < 16);
            const float *m = IMG + 4 * (j * w + i), *t = IMG2 + 4 * (j * w + i);
            if (edge || (x == 6 || x == 27 || y == 4 || y == 27)) continue;
            if (!in1 && !in3) {
                bad += m[3] != 0.0f || t[3] != 0.0f; /* outside every visible label: nothing (2 is hidden) */
                continue;
            }
            inside++;
            bad += !(m[3] > 0.99f && m[0] > 0.99f && m[2] > 0.99f); /* mask: the white TF */
            if (in1) bad += !(t[0] > 0.99f && t[2] < 0.01f); /* tint: red in front */
            else bad += !(t[2] > 0.99f && t[0] < 0.01f);     /* blue behind */
        }
    CHECKF(bad == 0 && inside > 200, "%d bad of %d inside", bad, inside);
}

/* Each label's own material: on the shaded sphere, a label whose material
 * is pure ambient (1, 0, 0, 1) renders flat at its colour, while the same
 * label without one is lit by the frame's material (its pixels vary); in
 * MASK mode too; an old entry struct (without the fields) and a bad material
 * behave as documented. */
TEST(each_label_lit_with_its_own_material)
{
    sphere_labels();
    REQUIRE(set_lab() == VXL_OK);
    const int w = 64;
    vxl_label_entry e[1] = {entry(7, 0.8f, 0.4f, 0.2f, 1, 1)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 1);
    vxl_render_params p = scene(w, 12);
    p.shading_off = 0;
    p.labels = &s;
    static const float tf[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    for (int mode = 0; mode < 2; mode++) {
        s.mode = mode ? VXL_LABEL_MODE_MASK : VXL_LABEL_MODE_SURFACE;
        static uint8_t ramp[N * N * N]; /* MASK lights the intensity volume's gradient: give it one */
        if (mode) {
            p.tf_rgba = tf;
            p.tf_size = 2;
            for (int i = 0; i < N * N * N; i++) ramp[i] = (uint8_t)(4 * (i % N));
            double a[16];
            grid_affine(a, 1, 15.5, NULL);
            vxl_volume *v = make_volume(VXL_DTYPE_U8, ramp, N, a);
            REQUIRE(v && vxl_renderer_set_volume(R, v) == VXL_OK);
            vxl_volume_destroy(v);
        }
        e[0].has_material = 0;
        REQUIRE(render(&p, IMG, NULL) == VXL_OK);
        e[0].has_material = 1;
        e[0].material[0] = 1;
        e[0].material[1] = e[0].material[2] = 0;
        e[0].material[3] = 1;
        REQUIRE(render(&p, IMG2, NULL) == VXL_OK);
        const float want[3] = {mode ? 1.0f : 0.8f, mode ? 1.0f : 0.4f, mode ? 1.0f : 0.2f};
        double lit_lo = 1e9, lit_hi = -1e9, flat_err = 0;
        int n = 0;
        for (int i = 0; i < w * w; i++) {
            const float *a = IMG + 4 * i, *b = IMG2 + 4 * i;
            if (a[3] < 0.999f || b[3] < 0.999f) continue; /* the sphere's inside, away from its edge */
            n++;
            lit_lo = fmin(lit_lo, a[0]);
            lit_hi = fmax(lit_hi, a[0]);
            for (int c = 0; c < 3; c++) flat_err = fmax(flat_err, fabs(b[c] - want[c]));
        }
        CHECKF(n > 500, "mode %d: %d covered pixels", mode, n);
        CHECKF(flat_err < 1e-5, "mode %d: the ambient-only label is off its colour by %g", mode, flat_err);
        if (mode == 0) /* the sphere's normals vary: so does its lit colour */
            CHECKF(lit_hi - lit_lo > 0.2, "surface: the frame's material lit it from %g to %g", lit_lo, lit_hi);
        else /* the ramp's normal is across the view: the frame's material leaves mostly its ambient */
            CHECKF(lit_hi < 0.8, "mask: the frame's material lit it from %g to %g", lit_lo, lit_hi);
    }
    {
        static uint8_t zero[N * N * N];
        double a[16];
        grid_affine(a, 1, 15.5, NULL);
        vxl_volume *v = make_volume(VXL_DTYPE_U8, zero, N, a);
        REQUIRE(v && vxl_renderer_set_volume(R, v) == VXL_OK);
        vxl_volume_destroy(v);
    }
    /* an entry struct from before the material fields: the frame's material */
    vxl_label_entry old[1] = {entry(7, 0.8f, 0.4f, 0.2f, 1, 1)};
    old[0].struct_size = (uint32_t)offsetof(vxl_label_entry, has_material);
    old[0].has_material = 1; /* beyond its struct_size: not read */
    s.entries = old;
    s.mode = VXL_LABEL_MODE_SURFACE;
    p.tf_rgba = NULL;
    p.tf_size = 0;
    REQUIRE(render(&p, IMG2, NULL) == VXL_OK);
    s.entries = e;
    e[0].has_material = 0;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    CHECK(memcmp(IMG, IMG2, sizeof(float) * 4 * w * w) == 0);
    /* a bad material is refused with a message naming it */
    e[0].has_material = 1;
    e[0].material[3] = 0;
    CHECK(render(&p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_renderer_error(R), "material") != NULL);
}

TEST(bad_labels_fail_with_a_message)
{
    three_boxes();
    REQUIRE(set_lab() == VXL_OK);
    vxl_label_entry e[2] = {colour_entry(1, 1), colour_entry(2, 2)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 2);
    vxl_render_params p = scene(16, 17);
    p.labels = &s;
    s.mode = 3;
    CHECK(render(&p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_last_error(), "label mode"));
    s.mode = 0;
    s.reserved = 1;
    CHECK(render(&p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_last_error(), "reserved"));
    s.reserved = 0;
    s.entries = NULL;
    CHECK(render(&p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_last_error(), "NULL"));
    s.entries = e;
    e[1].color[2] = NAN;
    CHECK(render(&p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_last_error(), "color[2]"));
    e[1].color[2] = 0.5f;
    e[1].id = 70000;
    CHECK(render(&p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_last_error(), "70000"));
    e[1].id = -1;
    CHECK(render(&p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_last_error(), "-1"));
    e[1].id = 1;
    CHECK(render(&p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_last_error(), "twice"));
    e[1].id = 2;
    p.mode = VXL_MODE_MIP;
    CHECK(render(&p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_last_error(), "DVR"));
    p.mode = VXL_MODE_DVR;
    CHECK(render(&p, IMG, NULL) == VXL_OK);
    /* the label volume: types and values */
    double a[16];
    grid_affine(a, 1, 15.5, NULL);
    static float fl[N * N * N];
    vxl_volume *v = make_volume(VXL_DTYPE_F32, fl, N, a);
    REQUIRE(v);
    CHECK(vxl_renderer_set_labels(R, v) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(R), "integers"));
    vxl_volume_destroy(v);
    static int32_t big[N * N * N];
    big[5] = 70000;
    v = make_volume(VXL_DTYPE_I32, big, N, a);
    REQUIRE(v);
    CHECK(vxl_renderer_set_labels(R, v) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(R), "(5, 0, 0)"));
    vxl_volume_destroy(v);
    big[5] = -3;
    v = make_volume(VXL_DTYPE_I32, big, N, a);
    REQUIRE(v);
    CHECK(vxl_renderer_set_labels(R, v) == VXL_ERR_INVALID_ARGUMENT);
    vxl_volume_destroy(v);
    /* a refused volume keeps the previous one */
    CHECK(render(&p, IMG, NULL) == VXL_OK);
    /* no label volume: a state error; frames without labels still render */
    REQUIRE(vxl_renderer_set_labels(R, NULL) == VXL_OK);
    CHECK(render(&p, IMG, NULL) == VXL_ERR_STATE && strstr(vxl_last_error(), "vxl_renderer_set_labels"));
    p.labels = NULL;
    CHECK(render(&p, IMG, NULL) == VXL_OK);
}

TEST(over_the_budget_a_label_volume_is_refused)
{
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.backend = software_backend();
    o.memory_budget_bytes = 40000; /* the 32^3 u16 labels need 65536 */
    vxl_renderer *r = NULL;
    REQUIRE(vxl_renderer_create(&o, &r) == VXL_OK);
    double a[16];
    grid_affine(a, 1, 15.5, NULL);
    vxl_volume *v = make_volume(VXL_DTYPE_U16, LAB, N, a);
    REQUIRE(v);
    CHECK(vxl_renderer_set_labels(r, v) == VXL_ERR_LIMIT && strstr(vxl_renderer_error(r), "label volume"));
    vxl_volume_destroy(v);
    vxl_renderer_destroy(r);
}

TEST(no_nan_with_labels_in_odd_cameras)
{
    sphere_labels();
    REQUIRE(set_lab() == VXL_OK);
    vxl_label_entry e[1] = {entry(7, 1, 0.5f, 0.2f, 0.7f, 1)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 1);
    static const float tf[8] = {1, 1, 1, 0.2f, 1, 1, 1, 1};
    int bad = 0, runs = 0;
    for (uint32_t mode = 0; mode < VXL_LABEL_MODE_COUNT; mode++)
        for (int c = 0; c < 6; c++) {
            vxl_render_params p = scene(24, 17);
            p.shading_off = (c & 1) == 0; /* shaded surfaces too */
            p.jitter_off = 0;
            p.labels = &s;
            s.mode = mode;
            p.tf_rgba = tf;
            p.tf_size = 2;
            switch (c) {
            case 0: p.view[14] = 0; break;                 /* eye inside the volume and the sphere */
            case 1: p.view[14] = (float)-1e6; break;       /* very far */
            case 2: p.proj[0] = p.proj[5] = 1e-6f; break;  /* a huge view */
            case 3: p.view[12] = 10.5f; p.view[13] = -10.5f; break; /* grazing the sphere along a voxel plane */
            case 4: p.has_camera = 0; p.azimuth_deg = 45; p.elevation_deg = 89.99f; break;
            default: p.has_camera = 0; p.elevation_deg = -90; break;
            }
            int rc = render(&p, IMG, DEP);
            runs++;
            if (rc != VXL_OK || !image_is_sane(IMG, DEP, 24 * 24)) {
                fprintf(stderr, "  mode %u case %d: rc %d %s\n", mode, c, rc, vxl_last_error());
                bad++;
            }
        }
    CHECKF(bad == 0, "%d of %d frames failed or had NaN", bad, runs);
}

TEST(frames_without_labels_are_unchanged_by_a_label_volume)
{
    vxl_render_params p = phantom_scene(48, 48, VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
    REQUIRE(vxl_renderer_set_labels(R, NULL) == VXL_OK);
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    sphere_labels();
    REQUIRE(set_lab() == VXL_OK);
    REQUIRE(render(&p, IMG2, NULL) == VXL_OK);
    CHECK(memcmp(IMG, IMG2, 48 * 48 * 4 * sizeof(float)) == 0);
}

/* Labels of several shapes and sizes (a ball, a box, a one-voxel plate, two
 * ids in columns, a lone voxel) in a pad-voxel margin: a volume of
 * N + pad + 3 voxels an edge whose voxel (pad + i) is LAB's voxel i. */
static uint16_t PADDED[(N + 6) * (N + 6) * (N + 6)];

static void mixed_shapes(void)
{
    memset(LAB, 0, sizeof LAB);
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) {
                double dx = x - 11.3, dy = y - 19.6, dz = z - 14.2;
                uint16_t id = 0;
                if (dx * dx + dy * dy + dz * dz <= 36) id = 7;
                else if (x >= 17 && x < 28 && y >= 3 && y < 12 && z >= 9 && z < 26) id = 3;
                else if (z == 6 && x >= 4 && x < 26 && y >= 4 && y < 28) id = 9;
                else if (x >= 20 && x < 30 && y >= 16 && y < 30 && z >= 16 && z < 28) id = (x / 2 + y / 3) % 2 ? 11 : 12;
                LAB[x + N * (y + N * z)] = id;
            }
    LAB[5 + N * (25 + N * 25)] = 3;
}

static int set_padded(int pad)
{
    const int n = N + pad + 3;
    memset(PADDED, 0, sizeof PADDED);
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) PADDED[(x + pad) + n * ((y + pad) + n * (z + pad))] = LAB[x + N * (y + N * z)];
    double a[16];
    grid_affine(a, 1, 15.5 + pad, NULL);
    vxl_volume *v = make_volume(VXL_DTYPE_U16, PADDED, (uint32_t)n, a);
    if (!v) return VXL_ERR_INVALID_ARGUMENT;
    int rc = vxl_renderer_set_labels(R, v);
    vxl_volume_destroy(v);
    return rc;
}

TEST(label_bricks_change_no_pixel)
{
    /* The label bricks (labels/label_bricks.c) let rays leap over space with
     * no visible label and through bricks of one label; they must find what
     * every sample would have. The same labels shifted by 0..3 voxels in
     * their own volume (and back by the affine) are split into bricks at
     * other places, so a brick that claimed too little, or a leap too far,
     * shows as a difference between the shifts. */
    mixed_shapes();
    vxl_label_entry e[5] = {entry(7, 1, 0.2f, 0.2f, 1, 1), entry(3, 0.2f, 1, 0.2f, 0.6f, 1),
                            entry(9, 0.2f, 0.2f, 1, 1, 1), entry(11, 1, 1, 0.2f, 0.5f, 1), entry(12, 0.2f, 1, 1, 1, 0)};
    static const float tf[8] = {1, 1, 1, 0.1f, 1, 1, 1, 0.1f};
    const int w = 64;
    static float ref[3][2][64 * 64 * 4];
    int worst = 0;
    double biggest = 0;
    for (int pad = 0; pad <= 3; pad++) {
        REQUIRE(set_padded(pad) == VXL_OK);
        for (uint32_t m = 0; m < VXL_LABEL_MODE_COUNT; m++)
            for (int view = 0; view < 2; view++) {
                vxl_label_style s = style(m, e, 5);
                vxl_render_params p = scene(w, 17);
                if (view) { /* oblique: leaps end on every face */
                    p.has_camera = 0;
                    p.azimuth_deg = 37;
                    p.elevation_deg = 24;
                    p.shading_off = 0;
                }
                p.tf_rgba = tf;
                p.tf_size = 2;
                p.labels = &s;
                REQUIRE(render(&p, pad ? IMG : ref[m][view], NULL) == VXL_OK);
                if (!pad) continue;
                int differ = 0;
                for (int i = 0; i < w * w * 4; i++) {
                    double d = fabs((double)IMG[i] - ref[m][view][i]);
                    biggest = fmax(biggest, d);
                    differ += d > 1e-3;
                }
                worst = differ > worst ? differ : worst;
            }
    }
    /* measured: no channel off by more than 2e-5 (the label point's rounding) */
    CHECKF(worst == 0, "up to %d channels differ by > 1e-3 between brick splits (largest %g)", worst, biggest);
}

TEST(rays_leap_over_space_without_visible_labels)
{
    /* SURFACE reads the labels alone: where no visible label can be, a ray
     * takes no sample (work counted by the stats, not timed). */
    mixed_shapes();
    REQUIRE(set_lab() == VXL_OK);
    vxl_label_entry e[2] = {entry(7, 1, 0, 0, 1, 0), entry(9, 0, 0, 1, 1, 0)};
    vxl_label_style s = style(VXL_LABEL_MODE_SURFACE, e, 2);
    vxl_render_params p = scene(64, 17);
    p.labels = &s;
    vxl_render_stats st;
    memset(&st, 0, sizeof st);
    st.struct_size = sizeof st;
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &st) == VXL_OK);
    double empty = 0;
    for (int i = 0; i < 64 * 64; i++) empty += IMG[4 * i + 3];
    CHECKF(st.samples == 0 && empty == 0, "all hidden: %llu samples, alpha sum %g", (unsigned long long)st.samples, empty);
    e[0].visible = 1; /* the ball of radius 6 alone: rays sample only near it */
    REQUIRE(render(&p, IMG, NULL) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &st) == VXL_OK);
    const double per_ray = st.rays ? (double)st.samples / st.rays : 0;
    /* without leaps each ray would take ~32 / step samples through the box */
    CHECKF(st.samples > 0 && per_ray * st.effective_step < 4, "%.1f samples a ray of %g voxels", per_ray,
           (double)st.effective_step);
}

int main(void)
{
    R = make_renderer(software_backend());
    static uint8_t zero[N * N * N];
    double a[16];
    grid_affine(a, 1, 15.5, NULL);
    vxl_volume *v = make_volume(VXL_DTYPE_U8, zero, N, a);
    if (!R || !v || vxl_renderer_set_volume(R, v) != VXL_OK) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    vxl_volume_destroy(v);
    RUN(hiding_a_label_removes_exactly_its_pixels);
    RUN(two_labels_touching_along_a_plane_meet_on_a_straight_line);
    RUN(a_labelled_sphere_renders_round);
    RUN(a_label_volume_on_another_grid_lands_where_its_affine_says);
    RUN(smooth_boundaries_shade_a_labelled_sphere_without_stairs);
    RUN(recolouring_and_hiding_re_upload_only_the_table);
    RUN(two_hundred_fifty_six_labels_across_the_id_range);
    RUN(mask_and_tint_apply_the_transfer_function_inside_visible_labels);
    RUN(each_label_lit_with_its_own_material);
    RUN(bad_labels_fail_with_a_message);
    RUN(over_the_budget_a_label_volume_is_refused);
    RUN(no_nan_with_labels_in_odd_cameras);
    RUN(frames_without_labels_are_unchanged_by_a_label_volume);
    RUN(label_bricks_change_no_pixel);
    RUN(rays_leap_over_space_without_visible_labels);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
