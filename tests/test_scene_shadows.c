/* test_scene_shadows.c - the volume in the scene's light
 * (csrc/frame/frame_scene.c, csrc/light/shadow_maps.c, transmittance.c):
 * meshes between a light and the volume shadow the volume where the
 * geometry says and nowhere else; the volume's shadow on a floor
 * (vxl_scene_transmittance) covers exactly the analytic footprint of the
 * sphere it holds, follows the sun and a point light, and is cut by the
 * meshes too; only a change of the meshes or a light rebuilds anything;
 * bad occluder arrays give an error naming the field.
 *
 * The scene: a 48^3 opaque ball of radius 0.5 at the origin in a volume
 * placed on the world box [-1, 1]^3. Sun from +Z unless said otherwise. */
#include <stdio.h>

#include "harness.h"
#include "test_util.h"

#define N 48
#define W 64
#define H 64
#define RADIUS 0.5     /* the ball's, world units */
#define FLOOR_Z (-1.5) /* the floor plane under the volume */
#define EYE_Z 5.0      /* the transmittance camera looks straight down from here */
#define HALF_VIEW 2.0  /* ... and sees the floor over [-2, 2]^2 */
/* The shadow's edge is as sharp as the illumination volume's cells (1/24
 * world units here) and the ball's own smooth edge: two cells either side
 * are left out of the comparisons with the analytic footprint. A light
 * whose travel is oblique to the cells softens it more: each slice of the
 * sweep reads the one before between cells, a diffusion of about
 * sqrt(slices * f (1 - f)) cells (f: the fraction of a cell the light moves
 * sideways per slice), measured here as below 5 cells for a sun 30 degrees
 * off the axis and 8 for the point light's cone 12 cells outside it. */
#define EDGE 0.09
#define OBLIQUE_EDGE 0.21
#define CONE_EDGE 0.34

static vxl_renderer *R;
static float IMG[W * H * 4], IMG2[W * H * 4], TRANS[W * H], DEPTH[W * H];

/* ---- the scene ---- */

static vxl_render_params scene(uint32_t model)
{
    static const float tf[8] = {1, 1, 1, 0, 1, 1, 1, 1};
    vxl_render_params p = default_params(W, H);
    p.tf_rgba = tf;
    p.tf_size = 2;
    p.has_window = 1;
    p.window_low = 0.3f;
    p.window_high = 0.7f;
    p.shading_model = model;
    p.illumination_size = N;
    p.jitter_off = 1;
    p.has_model = 1;
    const float s = 2.0f / N; /* voxel box [-0.5, N - 0.5] -> world [-1, 1] */
    for (int a = 0; a < 3; a++) {
        p.model[5 * a] = s;
        p.model[12 + a] = -1 + 0.5f * s;
    }
    p.model[15] = 1;
    p.light_count = 1;
    p.lights[0].position[2] = 1; /* the sun overhead */
    return p;
}

static void set_light(vxl_render_params *p, float x, float y, float z, float w)
{
    vxl_light l = {.position = {x, y, z, w}};
    p->lights[0] = l;
}

/* A quad of two triangles at height z over [x0, x1] x [y0, y1]. */
typedef struct plate {
    float v[12];
    uint32_t idx[6];
    vxl_scene_shadows s;
} plate;

static void plate_at(plate *q, float x0, float x1, float y0, float y1, float z, uint64_t key)
{
    const float v[12] = {x0, y0, z, x1, y0, z, x1, y1, z, x0, y1, z};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    memcpy(q->v, v, sizeof v);
    memcpy(q->idx, idx, sizeof idx);
    vxl_scene_shadows s = {.struct_size = sizeof s, .occluder_vertex_count = 4, .occluder_vertices = q->v,
                           .occluder_indices = q->idx, .occluder_triangle_count = 2, .shadow_map_size = 512,
                           .occluder_key = key};
    q->s = s;
}

/* The camera straight down on the floor: column-major view and projection. */
static void floor_camera(vxl_render_params *p)
{
    memset(p->view, 0, sizeof p->view);
    p->view[0] = p->view[5] = p->view[10] = p->view[15] = 1;
    p->view[14] = (float)-EYE_Z; /* world -> view: translate the eye to the origin, looking down -Z */
    const double t = HALF_VIEW / (EYE_Z - FLOOR_Z), n = 0.1, f = 20;
    memset(p->proj, 0, sizeof p->proj);
    p->proj[0] = p->proj[5] = (float)(1 / t);
    p->proj[10] = (float)(-(f + n) / (f - n));
    p->proj[11] = -1;
    p->proj[14] = (float)(-2 * f * n / (f - n));
    p->has_camera = 1;
    for (int i = 0; i < W * H; i++) DEPTH[i] = (float)(EYE_Z - FLOOR_Z); /* planar distance to the floor */
    p->scene_depth = DEPTH;
}

/* The floor point pixel i shows. */
static void floor_point(int i, double *x, double *y)
{
    *x = ((i % W + 0.5) / W * 2 - 1) * HALF_VIEW;
    *y = ((i / W + 0.5) / H * 2 - 1) * HALF_VIEW;
}

static int render(const vxl_render_params *p, float *img)
{
    int rc = vxl_render(R, p, img, NULL);
    if (rc) fprintf(stderr, "    render failed: %s\n", vxl_renderer_error(R));
    return rc;
}

static int transmittance(const vxl_render_params *p, float *out)
{
    int rc = vxl_scene_transmittance(R, p, 0, out);
    if (rc) fprintf(stderr, "    transmittance failed: %s\n", vxl_renderer_error(R));
    return rc;
}

static uint32_t rebuilt(void)
{
    vxl_render_stats st = {.struct_size = sizeof st};
    vxl_renderer_get_stats(R, &st);
    return st.illumination_rebuilt;
}

/* The ball's mean straight colour over the opaque pixels of columns
 * [c0, c1) of the image (the default camera looks from +Y: the left half
 * shows world +x). */
static double brightness(const float *img, int c0, int c1)
{
    double colour = 0, cover = 0;
    for (int i = 0; i < W * H; i++) {
        const float *px = img + 4 * i;
        if (i % W < c0 || i % W >= c1 || px[3] < 0.5f) continue;
        colour += px[0] + px[1] + px[2];
        cover += 3 * px[3];
    }
    return cover > 0 ? colour / cover : -1;
}

/* Pixels whose transmittance disagrees with the footprint inside(x, y)
 * returns: 1 in the shadow, 0 in the light, -1 on its edge (not judged).
 * In the shadow: below 0.2; in the light: above 0.98. */
typedef int (*footprint_fn)(double x, double y, const double *prm);

static int disagreements(const float *t, footprint_fn inside, const double *prm, int *shadowed, int *lit)
{
    int bad = 0;
    *shadowed = *lit = 0;
    for (int i = 0; i < W * H; i++) {
        double x, y;
        floor_point(i, &x, &y);
        int where = inside(x, y, prm);
        if (where < 0) continue;
        if (where) (*shadowed)++;
        else (*lit)++;
        if (where ? !(t[i] < 0.2f) : !(t[i] > 0.98f)) {
            if (bad < 4) fprintf(stderr, "    floor (%.2f, %.2f): transmittance %g, %s expected\n", x, y, t[i], where ? "shadow" : "light");
            bad++;
        }
    }
    return bad;
}

/* An ellipse centred at (prm[0], 0), semi-axes prm[1] along x and prm[2]
 * along y; world units left unjudged inside its edge: EDGE, outside it: prm[3]. */
static int ellipse(double x, double y, const double *prm)
{
    double u = (x - prm[0]) / prm[1], v = y / prm[2];
    double r = sqrt(u * u + v * v), m = fmin(prm[1], prm[2]);
    return r < 1 - EDGE / m ? 1 : r > 1 + prm[3] / m ? 0 : -1;
}

/* The shadow's area on the floor, the integral of 1 - T (unchanged by a
 * symmetric blur of its edge), and its centroid along x. */
static double shadow_area(const float *t, double *centroid_x)
{
    double area = 0, mx = 0, pixel = (2 * HALF_VIEW / W) * (2 * HALF_VIEW / H);
    for (int i = 0; i < W * H; i++) {
        double x, y;
        floor_point(i, &x, &y);
        area += (1 - t[i]) * pixel;
        mx += (1 - t[i]) * pixel * x;
    }
    *centroid_x = area > 0 ? mx / area : NAN;
    return area;
}

/* ---- tests ---- */

TEST(a_plate_between_the_sun_and_the_ball_darkens_only_the_side_it_covers)
{
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    REQUIRE(render(&p, IMG) == VXL_OK);
    plate q;
    plate_at(&q, 0, 3, -3, 3, 1.5f, 0); /* over world x > 0: the image's left half */
    p.scene_shadows = &q.s;
    REQUIRE(render(&p, IMG2) == VXL_OK);
    double lit0 = brightness(IMG, W / 2 + 4, W), lit1 = brightness(IMG2, W / 2 + 4, W);
    double cov0 = brightness(IMG, 0, W / 2 - 4), cov1 = brightness(IMG2, 0, W / 2 - 4);
    fprintf(stderr, "    uncovered side %.4f -> %.4f, covered side %.4f -> %.4f\n", lit0, lit1, cov0, cov1);
    CHECK(lit0 > 0.35 && cov0 > 0.35); /* the sun lights both sides without the plate */
    CHECKF(fabs(lit1 - lit0) < 0.01, "the uncovered side changed by %g", lit1 - lit0);
    /* the covered side keeps only its ambient light (0.3 of white) */
    CHECKF(cov1 - 0.3 < 0.1 * (cov0 - 0.3), "the covered side kept %g of its direct light", (cov1 - 0.3) / (cov0 - 0.3));
    /* the scatter model reads the same cut volume */
    vxl_render_params sc = scene(VXL_SHADING_SCATTER);
    REQUIRE(render(&sc, IMG) == VXL_OK);
    sc.scene_shadows = &q.s;
    REQUIRE(render(&sc, IMG2) == VXL_OK);
    double s_lit0 = brightness(IMG, W / 2 + 4, W), s_lit1 = brightness(IMG2, W / 2 + 4, W);
    double s_cov0 = brightness(IMG, 0, W / 2 - 4), s_cov1 = brightness(IMG2, 0, W / 2 - 4);
    CHECKF(fabs(s_lit1 - s_lit0) < 0.01 && s_cov1 - 0.3 < 0.1 * (s_cov0 - 0.3) && s_cov0 > 0.35,
           "scatter: uncovered %g -> %g, covered %g -> %g", s_lit0, s_lit1, s_cov0, s_cov1);
    /* Phong has no transmittance to cut: the plate changes nothing */
    vxl_render_params ph = scene(VXL_SHADING_PHONG);
    REQUIRE(render(&ph, IMG) == VXL_OK);
    ph.scene_shadows = &q.s;
    REQUIRE(render(&ph, IMG2) == VXL_OK);
    CHECK(memcmp(IMG, IMG2, sizeof IMG) == 0);
}

/* The image column where the default camera of p sees world point w. */
static double column_of(const vxl_render_params *p, const double w[3])
{
    float view[16], proj[16];
    if (vxl_default_camera(R, p, view, proj)) return NAN;
    double v[4], c[4];
    for (int r = 0; r < 4; r++) v[r] = view[r] * w[0] + view[4 + r] * w[1] + view[8 + r] * w[2] + view[12 + r];
    for (int r = 0; r < 4; r++) c[r] = proj[r] * v[0] + proj[4 + r] * v[1] + proj[8 + r] * v[2] + proj[12 + r] * v[3];
    return (c[0] / c[3] * 0.5 + 0.5) * W;
}

TEST(the_shadow_edge_on_the_volume_follows_the_plate_edge)
{
    /* the plate's edge at x = 0.25: under the overhead sun the plane x =
     * 0.25 bounds its shadow in the ball, seen from +Y at columns where
     * the ball's front (y ~ 0.3) is at that x */
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    REQUIRE(render(&p, IMG) == VXL_OK);
    plate q;
    plate_at(&q, 0.25f, 3, -3, 3, 1.5f, 0);
    p.scene_shadows = &q.s;
    REQUIRE(render(&p, IMG2) == VXL_OK);
    const double in[3] = {0.25 + 3 * EDGE / 2, 0.3, 0}, out[3] = {0.25 - 3 * EDGE / 2, 0.3, 0};
    const int covered = (int)floor(column_of(&p, in)), open = (int)ceil(column_of(&p, out));
    REQUIRE(covered > 4 && open < W - 4 && covered < open);
    double lit0 = brightness(IMG, open, W), lit1 = brightness(IMG2, open, W);
    double cov0 = brightness(IMG, 0, covered), cov1 = brightness(IMG2, 0, covered);
    fprintf(stderr, "    columns >= %d: %.4f -> %.4f, columns < %d: %.4f -> %.4f\n", open, lit0, lit1, covered, cov0, cov1);
    CHECKF(fabs(lit1 - lit0) < 0.005, "the uncovered part changed by %g", lit1 - lit0);
    CHECKF(cov1 - 0.3 < 0.1 * (cov0 - 0.3), "the covered part kept %g of its direct light", (cov1 - 0.3) / (cov0 - 0.3));
}

TEST(a_point_light_inside_the_box_is_shadowed_through_a_cube_of_maps)
{
    /* the light inside the volume's box, above the ball; a plate just under
     * it over x > 0: the plane x = 0 through the light bounds its shadow */
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    set_light(&p, 0, 0, 0.9f, 1);
    p.elevation_deg = 70; /* it lights a cap of the ball: seen from above */
    REQUIRE(render(&p, IMG) == VXL_OK);
    plate q;
    plate_at(&q, 0, 0.8f, -0.8f, 0.8f, 0.75f, 0);
    p.scene_shadows = &q.s;
    REQUIRE(render(&p, IMG2) == VXL_OK);
    double lit0 = brightness(IMG, W / 2 + 4, W), lit1 = brightness(IMG2, W / 2 + 4, W);
    double cov0 = brightness(IMG, 0, W / 2 - 4), cov1 = brightness(IMG2, 0, W / 2 - 4);
    fprintf(stderr, "    uncovered side %.4f -> %.4f, covered side %.4f -> %.4f\n", lit0, lit1, cov0, cov1);
    CHECK(cov0 > 0.315);
    CHECKF(fabs(lit1 - lit0) < 0.01, "the uncovered side changed by %g", lit1 - lit0);
    CHECKF(cov1 - 0.3 < 0.1 * (cov0 - 0.3), "the covered side kept %g of its direct light", (cov1 - 0.3) / (cov0 - 0.3));
}

TEST(only_moving_a_mesh_or_a_light_rebuilds)
{
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    plate q;
    plate_at(&q, 0, 3, -3, 3, 1.5f, 0);
    p.scene_shadows = &q.s;
    REQUIRE(render(&p, IMG) == VXL_OK);
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECKF(rebuilt() == 0, "the same frame rebuilt %u", rebuilt());
    p.azimuth_deg = 40; /* the camera moves */
    p.elevation_deg = 20;
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECKF(rebuilt() == 0, "a camera move rebuilt %u", rebuilt());
    plate_at(&q, 0.2f, 3, -3, 3, 1.5f, 0); /* the plate moves (the library hashes it) */
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECKF(rebuilt() == 1, "a plate move rebuilt %u", rebuilt());
    plate_at(&q, 0.2f, 3, -3, 3, 1.5f, 7); /* the caller names its version */
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECK(rebuilt() == 1);
    plate_at(&q, 0.4f, 3, -3, 3, 1.5f, 7); /* same key: the caller says nothing changed */
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECK(rebuilt() == 0);
    q.s.shadow_map_size = 256; /* the map's size is in the key */
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECK(rebuilt() == 1);
    set_light(&p, 0.2f, 0, 1, 0); /* the sun turns */
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECK(rebuilt() == 1);
    /* the transmittance of the frame just rendered rebuilds nothing */
    floor_camera(&p);
    REQUIRE(render(&p, IMG) == VXL_OK);
    REQUIRE(transmittance(&p, TRANS) == VXL_OK);
    vxl_render_stats st = {.struct_size = sizeof st};
    CHECK(vxl_renderer_get_stats(R, &st) == VXL_OK && st.illumination_rebuilt == 0);
}

TEST(the_floor_is_shadowed_exactly_under_the_ball)
{
    vxl_render_params p = scene(VXL_SHADING_PHONG); /* a Phong frame: the transmittance builds the sun's volume */
    floor_camera(&p);
    REQUIRE(transmittance(&p, TRANS) == VXL_OK);
    const double disc[4] = {0, RADIUS, RADIUS, EDGE};
    int shadowed, lit;
    CHECK(disagreements(TRANS, ellipse, disc, &shadowed, &lit) == 0);
    double cx, area = shadow_area(TRANS, &cx);
    CHECKF(fabs(area / (M_PI * RADIUS * RADIUS) - 1) < 0.1 && fabs(cx) < 0.01, "area %g, centre %g", area, cx);
    fprintf(stderr, "    %d shadowed, %d lit\n", shadowed, lit);
    CHECK(shadowed > 100 && lit > 2000);
    /* +inf depth (no geometry) gives 1, as does a floor point whose path misses the box */
    for (int i = 0; i < W * H; i += 2) DEPTH[i] = INFINITY;
    REQUIRE(transmittance(&p, TRANS) == VXL_OK);
    int ones = 0;
    for (int i = 0; i < W * H; i += 2) ones += TRANS[i] == 1.0f;
    CHECK(ones == W * H / 2);
    CHECK(TRANS[W * 0 + 1] == 1.0f); /* floor (-1.97, -1.97): outside the box's footprint */
}

TEST(rotating_the_sun_moves_the_shadow_as_the_geometry_says)
{
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    const double th = 30 * M_PI / 180;
    set_light(&p, (float)sin(th), 0, (float)cos(th), 0); /* towards the sun: tilted to +x */
    floor_camera(&p);
    REQUIRE(transmittance(&p, TRANS) == VXL_OK);
    /* the ball's shadow along -light: an ellipse at x = -1.5 tan(30), stretched 1 / cos(30) along x */
    const double e[4] = {FLOOR_Z * tan(th), RADIUS / cos(th), RADIUS, OBLIQUE_EDGE};
    int shadowed, lit;
    CHECK(disagreements(TRANS, ellipse, e, &shadowed, &lit) == 0);
    CHECK(shadowed > 150);
    double cx, area = shadow_area(TRANS, &cx);
    CHECKF(fabs(area / (M_PI * e[1] * e[2]) - 1) < 0.15 && fabs(cx - e[0]) < 0.03, "area %g of %g, centre %g of %g", area,
           M_PI * e[1] * e[2], cx, e[0]);
    /* and not where the overhead sun put it */
    double x, y;
    int centre = W / 2 + W * (H / 2);
    floor_point(centre, &x, &y);
    CHECKF(TRANS[centre] > 0.98f, "floor (%.2f, %.2f) under the ball stays shadowed: %g", x, y, TRANS[centre]);
}

TEST(a_point_light_casts_the_cone_of_the_ball_on_the_floor)
{
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    const double h = 3; /* the light, above the ball's centre */
    set_light(&p, 0, 0, (float)h, 1);
    floor_camera(&p);
    REQUIRE(transmittance(&p, TRANS) == VXL_OK);
    /* the tangent cone: tan a = r / sqrt(h^2 - r^2), on the floor h - FLOOR_Z below the light */
    const double radius = (h - FLOOR_Z) * RADIUS / sqrt(h * h - RADIUS * RADIUS);
    const double disc[4] = {0, radius, radius, CONE_EDGE};
    int shadowed, lit;
    CHECK(disagreements(TRANS, ellipse, disc, &shadowed, &lit) == 0);
    CHECK(shadowed > 250);
    double cx, area = shadow_area(TRANS, &cx);
    CHECKF(fabs(area / (M_PI * radius * radius) - 1) < 0.25 && fabs(cx) < 0.01, "area %g of %g, centre %g", area,
           M_PI * radius * radius, cx);
}

TEST(a_mesh_shadowing_the_volume_shadows_the_floor_through_it)
{
    /* a plate over world x > 0.3 above the volume: the floor whose path to
     * the sun crosses the volume's box there is in the same shadow */
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    plate q;
    plate_at(&q, 0.3f, 3, -3, 3, 1.5f, 0);
    p.scene_shadows = &q.s;
    floor_camera(&p);
    REQUIRE(transmittance(&p, TRANS) == VXL_OK);
    int bad = 0, cut = 0;
    for (int i = 0; i < W * H; i++) {
        double x, y;
        floor_point(i, &x, &y);
        double r = sqrt(x * x + y * y);
        if (fabs(y) > 1 - EDGE || r < RADIUS + EDGE) continue; /* off the box, or the ball's own shadow */
        if (x > 0.3 + EDGE && x < 1 - EDGE) {
            cut++;
            bad += !(TRANS[i] < 0.2f);
        } else if (x < 0.3 - EDGE) {
            bad += !(TRANS[i] > 0.98f);
        }
    }
    CHECKF(bad == 0, "%d floor points disagree with the plate's shadow", bad);
    CHECK(cut > 100);
}

TEST(bad_occluders_are_refused_naming_the_field)
{
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    plate q;
    /* the field each case's message must name */
    const char *field[] = {"occluder_vertices", "occluder_indices", "occluder_indices[4]", "occluder_vertices[7]",
                           "shadow_map_size", "shadow_map_size", "struct_size"};
    for (int c = 0; c < (int)(sizeof field / sizeof field[0]); c++) {
        plate_at(&q, 0, 1, 0, 1, 1.5f, 0);
        switch (c) {
        case 0: q.s.occluder_vertices = NULL; break;
        case 1: q.s.occluder_indices = NULL; break;
        case 2: q.idx[4] = 4; break; /* one past the last vertex */
        case 3: q.v[7] = NAN; break;
        case 4: q.s.shadow_map_size = 4; break;
        case 5: q.s.shadow_map_size = 1u << 20; break;
        case 6: q.s.struct_size = 4; break;
        }
        p.scene_shadows = &q.s;
        int rc = vxl_render(R, &p, IMG, NULL);
        CHECKF(rc == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(R), field[c]),
               "case %d: rc %d, \"%s\"", c, rc, vxl_renderer_error(R));
    }
    /* nothing was lost: the next good frame renders */
    plate_at(&q, 0, 1, 0, 1, 1.5f, 0);
    REQUIRE(render(&p, IMG) == VXL_OK);
    /* the transmittance's own arguments */
    vxl_render_params t = scene(VXL_SHADING_SHADOWED);
    CHECK(vxl_scene_transmittance(R, &t, 0, TRANS) == VXL_ERR_INVALID_ARGUMENT); /* no scene depth */
    CHECK(strstr(vxl_renderer_error(R), "scene_depth") != NULL);
    floor_camera(&t);
    CHECK(vxl_scene_transmittance(R, &t, 1, TRANS) == VXL_ERR_INVALID_ARGUMENT); /* one light only */
    CHECK(vxl_scene_transmittance(R, &t, 0, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_scene_transmittance(NULL, &t, 0, TRANS) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(transmittance(&t, TRANS) == VXL_OK);
}

TEST(the_shadow_maps_obey_the_memory_budget)
{
    /* 48 MiB: the volume and its illumination fit, a 4096^2 map (64 MiB) does not */
    vxl_renderer_options o = {.struct_size = sizeof o, .backend = software_backend(), .memory_budget_bytes = 48u << 20};
    vxl_renderer *r = NULL;
    REQUIRE(vxl_renderer_create(&o, &r) == VXL_OK);
    const double ball[4] = {(N - 1) / 2.0, (N - 1) / 2.0, (N - 1) / 2.0, RADIUS * N / 2};
    vxl_volume *v = make_volume_f32(N, N, N, field_ball, ball);
    CHECK(v && vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_volume_destroy(v);
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    plate q;
    plate_at(&q, 0, 3, -3, 3, 1.5f, 0);
    q.s.shadow_map_size = 4096;
    p.scene_shadows = &q.s;
    int rc = vxl_render(r, &p, IMG, NULL);
    CHECKF(rc == VXL_ERR_LIMIT && strstr(vxl_renderer_error(r), "shadow_map_size"), "rc %d: %s", rc, vxl_renderer_error(r));
    q.s.shadow_map_size = 1024; /* 4 MiB */
    CHECKF(vxl_render(r, &p, IMG, NULL) == VXL_OK, "%s", vxl_renderer_error(r));
    vxl_renderer_destroy(r);
}

int main(void)
{
    R = make_renderer(software_backend());
    const double ball[4] = {(N - 1) / 2.0, (N - 1) / 2.0, (N - 1) / 2.0, RADIUS * N / 2};
    vxl_volume *v = make_volume_f32(N, N, N, field_ball, ball);
    if (!R || !v || vxl_renderer_set_volume(R, v) != VXL_OK) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    vxl_volume_destroy(v);
    RUN(a_plate_between_the_sun_and_the_ball_darkens_only_the_side_it_covers);
    RUN(the_shadow_edge_on_the_volume_follows_the_plate_edge);
    RUN(a_point_light_inside_the_box_is_shadowed_through_a_cube_of_maps);
    RUN(only_moving_a_mesh_or_a_light_rebuilds);
    RUN(the_floor_is_shadowed_exactly_under_the_ball);
    RUN(rotating_the_sun_moves_the_shadow_as_the_geometry_says);
    RUN(a_point_light_casts_the_cone_of_the_ball_on_the_floor);
    RUN(a_mesh_shadowing_the_volume_shadows_the_floor_through_it);
    RUN(bad_occluders_are_refused_naming_the_field);
    RUN(the_shadow_maps_obey_the_memory_budget);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
