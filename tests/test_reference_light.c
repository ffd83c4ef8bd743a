/* test_reference_light.c - the reference renderer's shadows, spot cones,
 * soft shadows, ambient occlusion and scattering (voxlight.h's
 * VXL_SHADING_*), and the validation of the lighting fields. No
 * GL: the reference is the ground truth the fast path is measured against,
 * so these tests pin it down on its own.
 *
 * The scene: the two-blobs phantom (blobs at world x = +0.45 and -0.45)
 * seen from (0, 4, 0) towards the origin, up +Z, framing x in [-1, 1]: the
 * +x blob is on the image's left half, the -x blob on its right half. */
#include <stdio.h>

#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h"

/* Small, as the reference is slow: soft shadows and occlusion cast 32 to 64
 * rays from every sample. */
#define W 32
#define H 16
#define N 16 /* voxels per axis */

static vxl_phantom_desc blobs_desc(void)
{
    vxl_phantom_desc d = {.struct_size = sizeof d, .kind = VXL_PHANTOM_TWO_BLOBS, .dims = {N, N, N}};
    return d;
}

/* White, opacity ramping over the blobs' edge to `opacity` per voxel. */
static const float *tf_white(float opacity)
{
    static float tf[8];
    const float t[8] = {1, 1, 1, 0, 1, 1, 1, opacity};
    memcpy(tf, t, sizeof tf);
    return tf;
}

/* opacity 1: a sharp surface at the value 0.45 (fast: the rays stop there);
 * below 1: a soft edge over [0.3, 0.6] that light passes through. */
static vxl_render_params blobs_params(uint32_t model, float opacity)
{
    vxl_render_params p = default_params(W, H);
    p.tf_rgba = tf_white(opacity);
    p.tf_size = 2;
    p.has_window = 1;
    p.window_low = opacity < 1 ? 0.3f : 0.44f;
    p.window_high = opacity < 1 ? 0.6f : 0.46f;
    p.shading_model = model;
    /* look_at((0, 4, 0), origin, +Z): view x = -world x, y = z, z = y - 4 */
    const float view[16] = {-1, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, -4, 1};
    /* perspective: tan(fovy / 2) = 1/8, aspect 2, near 2, far 6 */
    const float n = 2, f = 6, proj[16] = {4, 0, 0, 0, 0, 8, 0, 0, 0, 0, (f + n) / (n - f), -1, 0, 0, 2 * f * n / (n - f), 0};
    p.has_camera = 1;
    memcpy(p.view, view, sizeof view);
    memcpy(p.proj, proj, sizeof proj);
    return p;
}

static void set_light(vxl_render_params *p, uint32_t i, float x, float y, float z, float w)
{
    memset(&p->lights[i], 0, sizeof p->lights[i]);
    p->lights[i].position[0] = x;
    p->lights[i].position[1] = y;
    p->lights[i].position[2] = z;
    p->lights[i].position[3] = w;
    if (p->light_count < i + 1) p->light_count = i + 1;
}

typedef struct {
    double left, right; /* mean straight brightness of the blob on each half */
} halves;

/* Mean straight colour (premultiplied sum over alpha sum) of each half's
 * pixels where the blobs are nearly opaque. */
static halves measure(const float *img)
{
    double c[2] = {0, 0}, a[2] = {0, 0};
    for (uint32_t y = 0; y < H; y++)
        for (uint32_t x = 0; x < W; x++) {
            const float *px = img + 4 * (y * W + x);
            if (px[3] < 0.5f) continue;
            int side = x >= W / 2;
            c[side] += (px[0] + px[1] + px[2]) / 3.0;
            a[side] += px[3];
        }
    halves h = {a[0] > 0 ? c[0] / a[0] : -1, a[1] > 0 ? c[1] / a[1] : -1};
    return h;
}

/* Renders the reference of the blobs; returns its halves (-1 on failure). */
static halves render(const vxl_render_params *p, float *img)
{
    vxl_phantom_desc d = blobs_desc();
    vxl_volume *v = NULL;
    halves bad = {-1, -1};
    if (vxl_phantom_create(&d, &v)) return bad;
    int rc = vxl_reference_render(&d, v, p, img, NULL);
    vxl_volume_destroy(v);
    if (rc) {
        fprintf(stderr, "    reference failed: %s\n", vxl_last_error());
        return bad;
    }
    return measure(img);
}

static float IMG[W * H * 4];

/* What the lights add to each blob: the image minus its ambient part (the
 * same frame with diffuse and specular 0). */
static halves light_added(const vxl_render_params *p)
{
    vxl_render_params amb = *p;
    amb.has_material = 1;
    amb.ambient = 0.3f;
    amb.diffuse = amb.specular = 0;
    amb.shininess = 24;
    halves all = render(p, IMG), base = render(&amb, IMG);
    halves h = {all.left - base.left, all.right - base.right};
    return h;
}

TEST(a_directional_light_shadows_the_blob_behind_only_when_shadowed)
{
    vxl_render_params p = blobs_params(VXL_SHADING_PHONG, 1);
    set_light(&p, 0, 1, 0, 0, 0); /* from +x: the -x blob (right half) is behind */
    halves phong = light_added(&p);
    p.shading_model = VXL_SHADING_SHADOWED;
    halves shadowed = light_added(&p);
    fprintf(stderr, "    light from +x adds: phong %.3f | %.3f, shadowed %.3f | %.3f\n", phong.left, phong.right,
            shadowed.left, shadowed.right);
    REQUIRE(phong.left > 0.05 && phong.right > 0.05);
    /* the blob behind loses its light; the front one keeps most of it (the
     * rest goes to its own soft edge, between its lit samples and the sun) */
    CHECKF(shadowed.right < 0.1 * phong.right, "behind: %.3f of %.3f", shadowed.right, phong.right);
    CHECKF(shadowed.left > 0.3 * phong.left, "in front: %.3f of %.3f", shadowed.left, phong.left);

    set_light(&p, 0, -1, 0, 0, 0); /* the other side: the roles swap, a mirror image */
    halves swapped = light_added(&p);
    fprintf(stderr, "    light from -x adds: shadowed %.3f | %.3f\n", swapped.left, swapped.right);
    CHECKF(swapped.left < 0.1 * phong.right, "behind: %.3f", swapped.left);
    CHECKF(fabs(swapped.left - shadowed.right) < 0.01 && fabs(swapped.right - shadowed.left) < 0.01,
           "mirror image: %.3f | %.3f vs %.3f | %.3f", swapped.left, swapped.right, shadowed.left, shadowed.right);
}

TEST(a_point_light_between_the_blobs_shadows_neither)
{
    vxl_render_params p = blobs_params(VXL_SHADING_PHONG, 1);
    set_light(&p, 0, 0, 0, 0, 1);
    halves phong = light_added(&p);
    p.shading_model = VXL_SHADING_SHADOWED;
    halves shadowed = light_added(&p);
    fprintf(stderr, "    point light at the centre adds: phong %.3f | %.3f, shadowed %.3f | %.3f\n", phong.left,
            phong.right, shadowed.left, shadowed.right);
    REQUIRE(phong.left > 0.05 && phong.right > 0.05);
    CHECKF(shadowed.left > 0.25 * phong.left && shadowed.right > 0.25 * phong.right, "%.3f | %.3f of %.3f | %.3f",
           shadowed.left, shadowed.right, phong.left, phong.right);
    CHECKF(fabs(shadowed.left - shadowed.right) < 0.01, "%.3f vs %.3f", shadowed.left, shadowed.right);
    /* the same light just beyond the +x blob puts the -x blob in its shadow */
    set_light(&p, 0, 0.95f, 0, 0, 1);
    halves beyond = light_added(&p);
    fprintf(stderr, "    point light at x = 0.95 adds: shadowed %.3f | %.3f\n", beyond.left, beyond.right);
    CHECKF(beyond.right < 0.2 * shadowed.right, "%.3f vs %.3f", beyond.right, shadowed.right);
}

TEST(a_spot_cone_lights_only_what_it_points_at)
{
    vxl_light_shape shape[1] = {{.struct_size = sizeof shape[0], .spot_direction = {1, 0, 0}, .spot_angle = 1.6f}};
    for (uint32_t model = 0; model < VXL_SHADING_COUNT; model++) {
        vxl_render_params p = blobs_params(model, 1);
        set_light(&p, 0, 0, 0, 0, 1);
        halves plain = light_added(&p);
        p.light_shapes = shape;
        halves spot = light_added(&p);
        fprintf(stderr, "    %s: a point light adds %.3f | %.3f, a spot towards +x %.3f | %.3f\n",
                vxl_shading_model_name(model), plain.left, plain.right, spot.left, spot.right);
        REQUIRE(plain.left > 0.02 && plain.right > 0.02);
        CHECKF(fabs(spot.left - plain.left) < 0.02 * plain.left, "lit blob %.3f vs %.3f", spot.left, plain.left);
        if (model == VXL_SHADING_PHONG) /* today's shading: shapes ignored (voxlight.h) */
            CHECKF(spot.right == plain.right, "phong: %.3g vs %.3g", spot.right, plain.right);
        else
            CHECKF(fabs(spot.right) < 1e-6, "blob outside the cone: %.3g", spot.right);
    }
    /* a soft edge (blend) lights less than the hard cone of the same angle */
    vxl_render_params p = blobs_params(VXL_SHADING_SHADOWED, 1);
    set_light(&p, 0, 0, 0, 0, 1);
    p.light_shapes = shape;
    halves hard = light_added(&p);
    shape[0].spot_blend = 1;
    halves soft = light_added(&p);
    fprintf(stderr, "    spot blend 0 / 1 adds %.3f / %.3f\n", hard.left, soft.left);
    CHECKF(soft.left < 0.9 * hard.left && soft.left > 0, "%.3f vs %.3f", soft.left, hard.left);
}

TEST(a_large_light_softens_the_shadow)
{
    vxl_render_params p = blobs_params(VXL_SHADING_SHADOWED, 1);
    set_light(&p, 0, 1, 0, 0, 0);
    halves hard = render(&p, IMG);
    vxl_light_shape shape[1] = {{.struct_size = sizeof shape[0], .size = 0.6f}}; /* sun angle, radians */
    p.light_shapes = shape;
    halves soft = render(&p, IMG);
    fprintf(stderr, "    sun angle 0 / 0.6: behind %.3f / %.3f, front %.3f / %.3f\n", hard.right, soft.right,
            hard.left, soft.left);
    CHECKF(soft.right > hard.right + 0.02, "penumbra: %.3f vs hard %.3f", soft.right, hard.right);
    CHECKF(soft.right < soft.left, "still a shadow: %.3f vs %.3f", soft.right, soft.left);
    /* a point light's radius, too */
    set_light(&p, 0, 1.2f, 0, 0, 1);
    p.light_shapes = NULL;
    halves hard_point = render(&p, IMG);
    shape[0].size = 0.6f;
    p.light_shapes = shape;
    halves soft_point = render(&p, IMG);
    fprintf(stderr, "    point radius 0 / 0.6: behind %.3f / %.3f\n", hard_point.right, soft_point.right);
    CHECKF(soft_point.right > hard_point.right + 0.02, "%.3f vs %.3f", soft_point.right, hard_point.right);
}

/* Ambient light only: the image is the occlusion factor times the colour.
 * At a low window the blobs merge into a peanut: its waist is a concave
 * crevice between the lobes, its ends are convex. Occlusion darkens the
 * waist more. */
TEST(occlusion_darkens_the_crevice_more_than_the_convex_ends)
{
    static float plain[W * H * 4], occluded[W * H * 4];
    vxl_render_params p = blobs_params(VXL_SHADING_SHADOWED, 1);
    p.window_low = 0.15f;
    p.window_high = 0.16f;
    p.has_material = 1;
    p.ambient = 1;
    p.shininess = 1;
    halves lit = render(&p, plain);
    p.ambient_occlusion = 6;
    halves dark = render(&p, occluded);
    REQUIRE(lit.left > 0 && dark.left > 0);
    /* the occlusion factor on the middle row, where the surface faces the
     * camera: at the waist (the centre columns) and on the lobes' caps
     * (the columns of the blobs' centres) */
    const uint32_t row = H / 2;
    double waist = 0, ends = 0;
    for (int k = -1; k <= 1; k++) {
        size_t mid = 4 * (row * W + W / 2 - (k < 0)), left = 4 * (row * W + W / 4 + k),
               right = 4 * (row * W + 3 * W / 4 + k);
        REQUIRE(plain[mid + 3] > 0.9f && plain[left + 3] > 0.9f && plain[right + 3] > 0.9f);
        /* the two centre columns, the first counted twice: weights 1/3 */
        waist += occluded[mid] / plain[mid] / 3;
        ends += (occluded[left] / plain[left] + occluded[right] / plain[right]) / 6;
    }
    fprintf(stderr, "    occlusion factor: waist %.3f, caps %.3f\n", waist, ends);
    CHECKF(ends < 0.95, "occlusion darkens: %.3f", ends);
    CHECKF(waist < ends - 0.1, "waist %.3f vs caps %.3f", waist, ends);
    /* strength scales it: half strength, half the darkening */
    p.occlusion_strength = 0.5f;
    halves half = render(&p, occluded);
    CHECKF(fabs((lit.left - half.left) - 0.5 * (lit.left - dark.left)) < 0.01, "full %.3f, half %.3f, none %.3f",
           dark.left, half.left, lit.left);
}

/* The sum of the image's premultiplied colour (-1 on failure). */
static double brightness(const vxl_render_params *p)
{
    if (render(p, IMG).left == -1 && IMG[3] == 0 && alpha_sum(IMG, W * H) == 0) return -1;
    double s = 0;
    for (size_t i = 0; i < W * H; i++) s += IMG[4 * i] + IMG[4 * i + 1] + IMG[4 * i + 2];
    return s;
}

/* Light from behind the blobs travels towards the camera: with g > 0 the
 * phase function sends it on to the eye; light from behind the camera
 * travels away and scatters back only weakly. Faint blobs, so light gets
 * through, and a high gradient_ref, so the phase term dominates. */
TEST(forward_scattering_is_brighter_looking_into_the_light)
{
    double into[3], away[3];
    const float gs[3] = {0.8f, 0.0f, -0.8f};
    for (int k = 0; k < 3; k++) {
        vxl_render_params p = blobs_params(VXL_SHADING_SCATTER, 0.15f);
        p.gradient_ref = 10;
        p.anisotropy = gs[k];
        set_light(&p, 0, 0, -1, 0, 0); /* camera at +Y: the light is behind the blobs */
        into[k] = brightness(&p);
        set_light(&p, 0, 0, 1, 0, 0);
        away[k] = brightness(&p);
        fprintf(stderr, "    g %+.1f: into the light %.3f, away %.3f\n", gs[k], into[k], away[k]);
    }
    REQUIRE(away[1] > 0);
    CHECKF(into[0] > 1.5 * away[0], "forward: %.3f vs %.3f", into[0], away[0]);
    CHECKF(away[2] > 1.5 * into[2], "backward: %.3f vs %.3f", away[2], into[2]);
    CHECKF(into[0] > into[1] && into[1] > into[2], "more forward, brighter into the light: %.3f %.3f %.3f", into[0],
           into[1], into[2]);
}

/* SHADOWED with nothing between the samples and the light and no occlusion
 * is PHONG: a headlight on one blob seen from the front. */
TEST(shadowed_without_occluders_is_phong)
{
    static float phong[W * H * 4];
    vxl_render_params p = blobs_params(VXL_SHADING_PHONG, 1);
    p.opacity_scale = 1e-4f; /* nearly transparent: transmittance 1 to 1e-3 */
    render(&p, phong);
    p.shading_model = VXL_SHADING_SHADOWED;
    render(&p, IMG);
    /* straight colours: the premultiplied ones are as faint as the blobs */
    double worst = 0;
    int drawn = 0;
    for (size_t i = 0; i < W * H; i++) {
        if (!(phong[4 * i + 3] > 1e-6f)) continue;
        drawn++;
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(IMG[4 * i + c] / IMG[4 * i + 3] - phong[4 * i + c] / phong[4 * i + 3]));
    }
    CHECKF(worst < 0.005, "largest difference %.3g", worst);
    CHECKF(drawn > W * H / 8, "%d pixels drawn", drawn);
}

TEST(no_nan_at_the_extremes)
{
    enum { w = 12, h = 8 };
    float img[w * h * 4], depth[w * h];
    vxl_phantom_desc d = blobs_desc();
    vxl_volume *v = NULL;
    REQUIRE(vxl_phantom_create(&d, &v) == VXL_OK);
    vxl_light_shape shapes[3] = {
        {.struct_size = sizeof shapes[0], .size = (float)M_PI},
        {.struct_size = sizeof shapes[0], .spot_direction = {0, 0, -1}, .spot_angle = (float)M_PI, .spot_blend = 1, .size = 1e6f},
        {.struct_size = sizeof shapes[0], .spot_direction = {1, 1, 1}, .spot_angle = 1e-6f, .size = 0}};
    const float gs[2] = {-0.99f, 0.99f};
    for (uint32_t model = 0; model < VXL_SHADING_COUNT; model++)
        for (int k = 0; k < 2; k++) {
            vxl_render_params p = default_params(w, h);
            p.shading_model = model;
            p.anisotropy = gs[k];
            p.ambient_occlusion = k ? 64 : 1e-3f;
            p.occlusion_strength = 1;
            p.opacity_scale = k ? 1e6f : 1e-6f;
            p.gradient_ref = k ? 1e-5f : 1e5f;
            p.illumination_size = k ? 1024 : 8;
            p.light_shapes = shapes;
            set_light(&p, 0, 0, 1, 1, 0);
            set_light(&p, 1, 0.45f, 0, 0, 1); /* inside a blob */
            set_light(&p, 2, 1e6f, 0, 0, 1);
            p.lights[2].intensity = 1e6f;
            int rc = vxl_reference_render(&d, v, &p, img, depth);
            CHECKF(rc == VXL_OK, "%s g %g: %s", vxl_shading_model_name(model), gs[k], vxl_last_error());
            CHECKF(image_is_sane(img, depth, w * h), "%s g %g", vxl_shading_model_name(model), gs[k]);
        }
    vxl_volume_destroy(v);
}

/* Each bad lighting field fails with VXL_ERR_INVALID_ARGUMENT naming it. */
TEST(lighting_fields_are_validated)
{
    float img[4 * 4];
    vxl_phantom_desc d = {.struct_size = sizeof d, .kind = VXL_PHANTOM_TWO_BLOBS, .dims = {4, 4, 4}};
    vxl_volume *v = NULL;
    REQUIRE(vxl_phantom_create(&d, &v) == VXL_OK);
    vxl_light_shape good = {.struct_size = sizeof good};
    struct {
        const char *field;
        uint32_t model, ill_size;
        float ao, strength, g;
        vxl_light_shape shape;
        float light_w;
    } cases[] = {
        {"shading_model", VXL_SHADING_COUNT, 0, 0, 0, 0, {0}, 0},
        {"ambient_occlusion", 0, 0, -1, 0, 0, {0}, 0},
        {"ambient_occlusion", 0, 0, 65, 0, 0, {0}, 0},
        {"ambient_occlusion", 0, 0, NAN, 0, 0, {0}, 0},
        {"occlusion_strength", 0, 0, 0, 1.5f, 0, {0}, 0},
        {"occlusion_strength", 0, 0, 0, -0.1f, 0, {0}, 0},
        {"anisotropy", 0, 0, 0, 0, 0.995f, {0}, 0},
        {"anisotropy", 0, 0, 0, 0, -1, {0}, 0},
        {"anisotropy", 0, 0, 0, 0, INFINITY, {0}, 0},
        {"illumination_size", 0, 7, 0, 0, 0, {0}, 0},
        {"illumination_size", 0, 1025, 0, 0, 0, {0}, 0},
        {"struct_size", 0, 0, 0, 0, 0, {.struct_size = 2}, 0},
        {"spot_angle", 0, 0, 0, 0, 0, {.struct_size = sizeof good, .spot_angle = 3.2f, .spot_direction = {1, 0, 0}}, 1},
        {"spot_angle", 0, 0, 0, 0, 0, {.struct_size = sizeof good, .spot_angle = -0.1f}, 1},
        {"spot_angle", 0, 0, 0, 0, 0, {.struct_size = sizeof good, .spot_angle = 0.5f, .spot_direction = {1, 0, 0}}, 0},
        {"spot_direction", 0, 0, 0, 0, 0, {.struct_size = sizeof good, .spot_angle = 0.5f}, 1},
        {"spot_direction", 0, 0, 0, 0, 0, {.struct_size = sizeof good, .spot_angle = 0.5f, .spot_direction = {NAN, 0, 0}}, 1},
        {"spot_blend", 0, 0, 0, 0, 0, {.struct_size = sizeof good, .spot_blend = 1.5f}, 1},
        {"size", 0, 0, 0, 0, 0, {.struct_size = sizeof good, .size = -1}, 1},
        {"size", 0, 0, 0, 0, 0, {.struct_size = sizeof good, .size = INFINITY}, 1},
        {"size", 0, 0, 0, 0, 0, {.struct_size = sizeof good, .size = 4}, 0}, /* a sun's angle beyond pi */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        vxl_render_params p = default_params(2, 2);
        p.shading_model = cases[i].model;
        p.illumination_size = cases[i].ill_size;
        p.ambient_occlusion = cases[i].ao;
        p.occlusion_strength = cases[i].strength;
        p.anisotropy = cases[i].g;
        vxl_light_shape shape = cases[i].shape;
        if (shape.struct_size || cases[i].light_w) p.light_shapes = &shape;
        set_light(&p, 0, 1, 2, 3, cases[i].light_w);
        int rc = vxl_reference_render(&d, v, &p, img, NULL);
        CHECKF(rc == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_last_error(), cases[i].field),
               "case %zu (%s): rc %d, '%s'", i, cases[i].field, rc, vxl_last_error());
    }
    /* the good values pass, among them the limits, a shorter (older)
     * shape struct and the headlight, which has no shape entries */
    vxl_light_shape shapes[2] = {good, {.struct_size = sizeof good, .spot_angle = (float)M_PI, .spot_blend = 1,
                                        .spot_direction = {0, 1, 0}, .size = 100}};
    vxl_render_params p = default_params(2, 2);
    p.shading_model = VXL_SHADING_SCATTER;
    p.ambient_occlusion = 64;
    p.occlusion_strength = 1;
    p.anisotropy = -0.99f;
    p.illumination_size = 8;
    p.light_shapes = shapes;
    set_light(&p, 0, 0, 0, 1, 0);
    set_light(&p, 1, 0, -2, 0, 1);
    CHECKF(vxl_reference_render(&d, v, &p, img, NULL) == VXL_OK, "%s", vxl_last_error());
    uint32_t shorter = 4; /* struct_size only: every shape field 0 */
    p.light_shapes = (const vxl_light_shape *)(const void *)&shorter;
    p.light_count = 1;
    CHECKF(vxl_reference_render(&d, v, &p, img, NULL) == VXL_OK, "%s", vxl_last_error());
    p.light_count = 0;
    CHECKF(vxl_reference_render(&d, v, &p, img, NULL) == VXL_OK, "%s", vxl_last_error());
    /* two entries with different struct sizes are one array misread */
    shapes[1].struct_size = 8;
    p.light_shapes = shapes;
    p.light_count = 2;
    CHECKF(vxl_reference_render(&d, v, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT &&
               strstr(vxl_last_error(), "light_shapes[1].struct_size"),
           "%s", vxl_last_error());
    vxl_volume_destroy(v);
}

TEST(shading_model_names)
{
    for (uint32_t i = 0; i < VXL_SHADING_COUNT; i++) {
        uint32_t back = 99;
        CHECK(vxl_shading_model_name(i) != NULL);
        CHECK(vxl_shading_model_from_name(vxl_shading_model_name(i), &back) == VXL_OK && back == i);
    }
    CHECK(vxl_shading_model_name(VXL_SHADING_COUNT) == NULL);
    CHECK(strcmp(vxl_shading_model_name(VXL_SHADING_SHADOWED), "shadowed") == 0);
    uint32_t m = 99;
    CHECK(vxl_shading_model_from_name("SCATTER", &m) == VXL_OK && m == VXL_SHADING_SCATTER);
    CHECK(vxl_shading_model_from_name("ray-traced", &m) == VXL_ERR_INVALID_ARGUMENT);
}

int main(void)
{
    RUN(lighting_fields_are_validated);
    RUN(shading_model_names);
    RUN(a_directional_light_shadows_the_blob_behind_only_when_shadowed);
    RUN(a_point_light_between_the_blobs_shadows_neither);
    RUN(a_spot_cone_lights_only_what_it_points_at);
    RUN(a_large_light_softens_the_shadow);
    RUN(occlusion_darkens_the_crevice_more_than_the_convex_ends);
    RUN(forward_scattering_is_brighter_looking_into_the_light);
    RUN(shadowed_without_occluders_is_phong);
    RUN(no_nan_at_the_extremes);
    return TEST_SUMMARY();
}
