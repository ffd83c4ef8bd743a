/* test_shadows.c - the GL side of the shadowed and scatter shading models
 * (csrc/light/illumination.c, shaders/compute/illumination.comp,
 * lib/shading.glsl's shade_lit): shadows fall where the light is blocked
 * and only there, every storage mode gives the same shadows, nothing goes
 * NaN at the parameters' extremes, the illumination volumes are rebuilt
 * only when what they depend on changes and shrink to fit the budget, and
 * the image converges to the double-precision reference as they grow.
 *
 * The scene: the two-blobs phantom (blobs at world x = +0.45 and -0.45)
 * seen by the default camera from +Y, so the +x blob fills the image's left
 * half and the -x blob its right half. */
#include <stdio.h>

#include "harness.h"
#include "test_util.h"
#include "voxlight_dev.h"

#define W 64
#define H 32
#define N 40 /* voxels per axis */

static vxl_renderer *R;
static float IMG[W * H * 4], IMG2[W * H * 4];

static vxl_volume *blobs_volume(void)
{
    vxl_phantom_desc d = {.struct_size = sizeof d, .kind = VXL_PHANTOM_TWO_BLOBS, .dims = {N, N, N}};
    vxl_volume *v = NULL;
    return vxl_phantom_create(&d, &v) == VXL_OK ? v : NULL;
}

/* White blobs, opacity ramping to `opacity` per voxel over their edge. */
static vxl_render_params scene(uint32_t model, float opacity)
{
    static float tf[8];
    const float t[8] = {1, 1, 1, 0, 1, 1, 1, 0};
    memcpy(tf, t, sizeof tf);
    tf[7] = opacity;
    vxl_render_params p = {.struct_size = sizeof p, .width = W, .height = H, .tf_rgba = tf, .tf_size = 2,
                           .has_window = 1, .window_low = 0.3f, .window_high = 0.6f, .shading_model = model,
                           .jitter_off = 1};
    return p;
}

static void light(vxl_render_params *p, uint32_t i, float x, float y, float z, float w)
{
    vxl_light l = {.position = {x, y, z, w}};
    p->lights[i] = l;
    p->light_count = p->light_count > i + 1 ? p->light_count : i + 1;
}

/* Brightness of the blob on one half of the image (0 left, 1 right): its
 * straight colour, the premultiplied sum over the alpha sum of the pixels
 * it covers nearly opaquely. */
static double blob_brightness(const float *img, int right)
{
    double colour = 0, cover = 0;
    for (uint32_t i = 0; i < W * H; i++) {
        const float *px = img + 4 * i;
        if ((i % W >= W / 2) != right || px[3] < 0.5f) continue;
        colour += px[0] + px[1] + px[2];
        cover += 3 * px[3];
    }
    return cover > 0 ? colour / cover : -1;
}

static int render(vxl_renderer *r, const vxl_render_params *p, float *img)
{
    int rc = vxl_render(r, p, img, NULL);
    if (rc) fprintf(stderr, "    render failed: %s\n", vxl_renderer_error(r));
    return rc;
}

/* The light a blob gets beyond the ambient term (0.3 of white; no occlusion). */
static double direct(double brightness) { return brightness - 0.3; }

/* Both blobs' brightness with p's lights in Phong (b[0] left, b[1] right),
 * then shadowed (b[2], b[3], the image left in IMG2); 0 on success. */
static int phong_then_shadowed(vxl_render_params *p, double b[4])
{
    p->shading_model = VXL_SHADING_PHONG;
    int rc = render(R, p, IMG);
    p->shading_model = VXL_SHADING_SHADOWED;
    if (!rc) rc = render(R, p, IMG2);
    b[0] = blob_brightness(IMG, 0);
    b[1] = blob_brightness(IMG, 1);
    b[2] = blob_brightness(IMG2, 0);
    b[3] = blob_brightness(IMG2, 1);
    fprintf(stderr, "    phong %.3f | %.3f, shadowed %.3f | %.3f\n", b[0], b[1], b[2], b[3]);
    return rc || !(b[0] > 0 && b[1] > 0 && b[2] > 0 && b[3] > 0);
}

TEST(the_blob_behind_a_directional_light_is_darker_only_when_shadowed)
{
    vxl_render_params p = scene(VXL_SHADING_PHONG, 0.8f);
    light(&p, 0, 1, 0, 0, 0); /* from +x: the -x blob (right half) is behind */
    double b[4];
    REQUIRE(phong_then_shadowed(&p, b) == 0);
    const double phong_l = b[0], phong_r = b[1], lit = b[2], behind = b[3];
    CHECKF(fabs(phong_l - phong_r) < 0.05 * phong_l, "phong %.3f vs %.3f", phong_l, phong_r);
    /* the blob behind keeps the ambient term and little else; the front one
     * keeps much of its light (its own soft edge shadows some of it: the
     * reference test below pins how much) */
    CHECKF(direct(behind) < 0.1 * direct(phong_r), "behind %.3f of phong %.3f", behind, phong_r);
    CHECKF(direct(lit) > 0.4 * direct(phong_l), "front %.3f of phong %.3f", lit, phong_l);
    /* Phong after a shadowed frame is the Phong frame of before, bit for bit */
    p.shading_model = VXL_SHADING_PHONG;
    REQUIRE(render(R, &p, IMG2) == VXL_OK);
    CHECK(memcmp(IMG, IMG2, sizeof IMG) == 0);
    vxl_render_stats st = {.struct_size = sizeof st};
    REQUIRE(vxl_renderer_get_stats(R, &st) == VXL_OK);
    CHECK(st.illumination_size == 0);

    /* the other side: the roles swap, a mirror image */
    p.shading_model = VXL_SHADING_SHADOWED;
    light(&p, 0, -1, 0, 0, 0);
    REQUIRE(render(R, &p, IMG2) == VXL_OK);
    double s_l = blob_brightness(IMG2, 0), s_r = blob_brightness(IMG2, 1);
    fprintf(stderr, "    light from -x: shadowed %.3f | %.3f\n", s_l, s_r);
    CHECKF(direct(s_l) < 0.1 * direct(phong_l), "behind %.3f of phong %.3f", s_l, phong_l);
    CHECKF(fabs(s_l - behind) < 0.02 && fabs(s_r - lit) < 0.02, "mirror: %.3f | %.3f vs %.3f | %.3f", s_l, s_r,
           lit, behind);
}

TEST(a_point_light_between_the_blobs_shadows_neither)
{
    vxl_render_params p = scene(VXL_SHADING_PHONG, 0.8f);
    light(&p, 0, 0, 0, 0, 1);
    double b[4];
    REQUIRE(phong_then_shadowed(&p, b) == 0);
    const double phong_l = b[0], phong_r = b[1], l = b[2], r = b[3];
    CHECKF(direct(l) > 0.4 * direct(phong_l) && direct(r) > 0.4 * direct(phong_r), "%.3f | %.3f of %.3f | %.3f", l,
           r, phong_l, phong_r);
    CHECKF(fabs(l - r) < 0.01, "%.3f vs %.3f", l, r);
    /* just beyond the +x blob it shadows the -x one */
    light(&p, 0, 0.95f, 0, 0, 1);
    REQUIRE(render(R, &p, IMG) == VXL_OK);
    double l2 = blob_brightness(IMG, 0), r2 = blob_brightness(IMG, 1);
    fprintf(stderr, "    point light at x = 0.95: shadowed %.3f | %.3f\n", l2, r2);
    CHECKF(direct(r2) < 0.2 * direct(r), "behind %.3f, unshadowed %.3f", r2, r);
    CHECKF(direct(l2) > 0.01, "in front %.3f", l2);
}

TEST(only_what_changed_is_rebuilt)
{
    vxl_render_params p = scene(VXL_SHADING_SHADOWED, 0.8f);
    light(&p, 0, 1, 0, 0.3f, 0);
    light(&p, 1, 0, 0, 0.9f, 1);
    p.ambient_occlusion = 4;
    vxl_render_stats st = {.struct_size = sizeof st};
    REQUIRE(render(R, &p, IMG) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &st) == VXL_OK);
    CHECKF(st.illumination_rebuilt == 3, "first frame rebuilt %u", st.illumination_rebuilt); /* 2 lights + AO */
    CHECK(st.illumination_size > 0);
    /* the camera moves: nothing is rebuilt, and the image changes */
    p.azimuth_deg = 30;
    REQUIRE(render(R, &p, IMG2) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &st) == VXL_OK);
    CHECKF(st.illumination_rebuilt == 0, "camera move rebuilt %u", st.illumination_rebuilt);
    CHECK(memcmp(IMG, IMG2, sizeof IMG) != 0);
    /* one light moves: only it */
    light(&p, 1, 0, 0.2f, 0.9f, 1);
    REQUIRE(render(R, &p, IMG2) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &st) == VXL_OK);
    CHECKF(st.illumination_rebuilt == 1, "light move rebuilt %u", st.illumination_rebuilt);
    /* the occlusion radius: only the occlusion */
    p.ambient_occlusion = 6;
    REQUIRE(render(R, &p, IMG2) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &st) == VXL_OK);
    CHECKF(st.illumination_rebuilt == 1, "occlusion radius rebuilt %u", st.illumination_rebuilt);
    /* the window (the classification): everything */
    p.window_high = 0.7f;
    REQUIRE(render(R, &p, IMG2) == VXL_OK);
    REQUIRE(vxl_renderer_get_stats(R, &st) == VXL_OK);
    CHECKF(st.illumination_rebuilt == 3, "window change rebuilt %u", st.illumination_rebuilt);
}

static vxl_renderer *renderer_with(uint32_t storage, uint64_t budget)
{
    vxl_renderer_options o = {.struct_size = sizeof o, .backend = software_backend(), .storage = storage,
                              .page_brick = 16, .memory_budget_bytes = budget};
    vxl_renderer *r = NULL;
    return vxl_renderer_create(&o, &r) == VXL_OK ? r : NULL;
}

/* The extinction pass samples through the storage's own GLSL, so bricked
 * and sparse storage (pool, page table, constant bricks) light the blobs as
 * dense storage does, and compressed storage within its palettes' loss. */
TEST(every_storage_mode_gives_the_same_shadows)
{
    vxl_render_params p = scene(VXL_SHADING_SHADOWED, 0.8f);
    light(&p, 0, 1, 0.3f, 0.2f, 0);
    light(&p, 1, 0, 0.5f, 0.9f, 1);
    p.ambient_occlusion = 3;
    p.azimuth_deg = 20;
    REQUIRE(render(R, &p, IMG) == VXL_OK); /* R is dense */
    const uint32_t modes[3] = {VXL_STORAGE_BRICKED, VXL_STORAGE_SPARSE, VXL_STORAGE_COMPRESSED};
    for (int m = 0; m < 3; m++) {
        vxl_renderer *r = renderer_with(modes[m], 0);
        vxl_volume *v = blobs_volume();
        REQUIRE(r && v);
        int rc = vxl_renderer_set_volume(r, v);
        vxl_volume_destroy(v);
        if (!rc) rc = render(r, &p, IMG2);
        vxl_render_stats st = {.struct_size = sizeof st};
        if (!rc) rc = vxl_renderer_get_stats(r, &st);
        vxl_renderer_destroy(r);
        REQUIRE(rc == VXL_OK);
        CHECK(st.storage == modes[m]);
        double q = image_psnr(IMG, IMG2, sizeof IMG / sizeof *IMG);
        fprintf(stderr, "    %s vs dense: %.1f dB\n", vxl_storage_name(modes[m]), q);
        CHECKF(q > 45, "%s: %.1f dB", vxl_storage_name(modes[m]), q);
    }
}

/* A coarser light grid after a finer one (Blender's dragged light) keeps
 * the finer extinction grid and reads it through its sampler: the light's
 * shadow falls where a fresh renderer at the coarser size puts it (rmse
 * 0.002 here; the coarse cells sample a sharper field, so not 0). */
TEST(a_coarser_light_grid_reads_the_kept_extinction)
{
    vxl_render_params p = scene(VXL_SHADING_SHADOWED, 0.8f);
    light(&p, 0, 1, 0, 0, 0);
    vxl_renderer *fresh = renderer_with(VXL_STORAGE_DENSE, 0);
    vxl_volume *v = blobs_volume();
    REQUIRE(fresh && v);
    int rc = vxl_renderer_set_volume(fresh, v);
    vxl_volume_destroy(v);
    p.illumination_size = 16;
    if (!rc) rc = render(fresh, &p, IMG2);
    vxl_renderer_destroy(fresh);
    REQUIRE(rc == VXL_OK);
    p.illumination_size = 40;
    REQUIRE(render(R, &p, IMG) == VXL_OK);
    fprintf(stderr, "    40 vs fresh 16: rmse %.5f\n", image_rmse(IMG, IMG2, W * H * 4));
    p.illumination_size = 16;
    REQUIRE(render(R, &p, IMG) == VXL_OK);
    vxl_render_stats st = {.struct_size = sizeof st};
    REQUIRE(vxl_renderer_get_stats(R, &st) == VXL_OK);
    CHECK(st.illumination_size == 16);
    double e = image_rmse(IMG, IMG2, W * H * 4);
    fprintf(stderr, "    16 after 40 vs fresh 16: rmse %.5f\n", e);
    CHECKF(e < 0.01, "rmse %.5f", e);
    CHECK(direct(blob_brightness(IMG, 1)) < 0.3 * direct(blob_brightness(IMG, 0)));
}

/* Over the budget the volumes go coarser, and the stats say so; when not
 * even the coarsest fits, the frame fails with the budget's message. */
TEST(the_illumination_volumes_fit_the_memory_budget)
{
    const uint64_t volume = (uint64_t)N * N * N * 4; /* the phantom is float32 */
    vxl_render_params p = scene(VXL_SHADING_SHADOWED, 0.8f);
    light(&p, 0, 1, 0, 0, 0);
    p.illumination_size = 40; /* 40^3 cells, 2 blocks: 512 KiB */
    vxl_renderer *r = renderer_with(VXL_STORAGE_DENSE, volume + 200 * 1024);
    vxl_volume *v = blobs_volume();
    REQUIRE(r && v);
    int rc = vxl_renderer_set_volume(r, v);
    vxl_volume_destroy(v);
    vxl_render_stats st = {.struct_size = sizeof st};
    if (!rc) rc = render(r, &p, IMG2);
    if (!rc) rc = vxl_renderer_get_stats(r, &st);
    CHECK(rc == VXL_OK);
    CHECKF(st.illumination_size == 20, "size %u under the budget", st.illumination_size);
    /* and it still shadows the blob behind */
    CHECK(direct(blob_brightness(IMG2, 1)) < 0.3 * direct(blob_brightness(IMG2, 0)));
    vxl_renderer_destroy(r);

    r = renderer_with(VXL_STORAGE_DENSE, volume + 1024);
    v = blobs_volume();
    REQUIRE(r && v);
    rc = vxl_renderer_set_volume(r, v);
    vxl_volume_destroy(v);
    CHECK(rc == VXL_OK);
    CHECK(vxl_render(r, &p, IMG2, NULL) == VXL_ERR_LIMIT);
    CHECKF(strstr(vxl_renderer_error(r), "illumination") != NULL, "%s", vxl_renderer_error(r));
    p.shading_model = VXL_SHADING_PHONG; /* Phong needs none */
    CHECK(vxl_render(r, &p, IMG2, NULL) == VXL_OK);
    vxl_renderer_destroy(r);
}

/* Every lighting parameter at its extremes, in every shading model and
 * classification: finite, premultiplied images. */
TEST(no_nan_at_the_extremes)
{
    vxl_light_shape shapes[3] = {{.struct_size = sizeof(vxl_light_shape), .size = 3.14159f},
                                 {.struct_size = sizeof(vxl_light_shape), .size = 1e6f, .spot_angle = 0.3f,
                                  .spot_direction = {-1, 0, 0}},
                                 {.struct_size = sizeof(vxl_light_shape), .spot_angle = 3.14159f,
                                  .spot_blend = 1, .spot_direction = {0, 0, 1}}};
    const float anis[3] = {-0.99f, 0, 0.99f}, ao[3] = {0, 1e-3f, 64};
    const uint32_t sizes[3] = {8, 0, 1024};
    int frames = 0;
    for (uint32_t model = VXL_SHADING_SHADOWED; model <= VXL_SHADING_SCATTER; model++)
        for (int k = 0; k < 3; k++)
            for (uint32_t mode = 0; mode < VXL_CLASSIFY_COUNT; mode++) {
                vxl_render_params p = scene(model, k == 2 ? 1.0f : 0.8f);
                light(&p, 0, 1, 1, 1, 0);
                light(&p, 1, 1, 0, 0, 1);                     /* in the box, a huge disc */
                light(&p, 2, 0, 0, -0.45f, 1);                /* on the voxels' own grid */
                p.light_shapes = shapes;
                p.anisotropy = anis[k];
                p.ambient_occlusion = ao[k];
                p.occlusion_strength = k == 1 ? 1e-6f : 1;
                p.illumination_size = sizes[k];
                p.classify = mode;
                p.gradient_ref = k == 0 ? 1e-6f : 0;
                p.jitter_off = 0;
                if (render(R, &p, IMG)) {
                    CHECKF(0, "model %u, case %d, classify %u: %s", model, k, mode, vxl_renderer_error(R));
                    continue;
                }
                frames++;
                CHECKF(image_is_sane(IMG, NULL, W * H), "model %u, case %d, classify %u", model, k, mode);
                CHECK(alpha_sum(IMG, W * H) > 0);
            }
    CHECK(frames == 2 * 3 * VXL_CLASSIFY_COUNT);
}

/* Comparisons with the double-precision reference: the two-blobs phantom
 * at n^3 voxels in a dense renderer, images of RW x RH. */
#define RW 48
#define RH 24
static float REF[RW * RH * 4], OUT[RW * RH * 4];

typedef struct {
    vxl_phantom_desc d;
    vxl_volume *v;
    vxl_renderer *r;
} ref_scene;

static void ref_scene_close(ref_scene *s)
{
    vxl_volume_destroy(s->v);
    vxl_renderer_destroy(s->r);
}

static int ref_scene_open(ref_scene *s, uint32_t n)
{
    s->d = (vxl_phantom_desc){.struct_size = sizeof s->d, .kind = VXL_PHANTOM_TWO_BLOBS, .dims = {n, n, n}};
    s->v = NULL;
    s->r = renderer_with(VXL_STORAGE_DENSE, 0);
    if (s->r && vxl_phantom_create(&s->d, &s->v) == VXL_OK && vxl_renderer_set_volume(s->r, s->v) == VXL_OK) return 0;
    ref_scene_close(s);
    return 1;
}

/* Renders p (at RW x RH) with the reference into REF (unless keep_ref) and
 * on the GL side into OUT; the RMSE between them, -1 on failure. */
static double against_reference(ref_scene *s, vxl_render_params *p, int keep_ref)
{
    p->width = RW;
    p->height = RH;
    if (!keep_ref && vxl_reference_render(&s->d, s->v, p, REF, NULL)) return -1;
    if (render(s->r, p, OUT)) return -1;
    return image_rmse(OUT, REF, RW * RH * 4);
}

/* The GL image against the double-precision reference on a phantom: the
 * error falls as the illumination volumes grow (directional and point
 * light, soft shadows, occlusion). */
TEST(the_image_converges_to_the_reference)
{
    ref_scene sc;
    REQUIRE(ref_scene_open(&sc, 64) == 0);
    vxl_light_shape shapes[2] = {{.struct_size = sizeof(vxl_light_shape), .size = 0.1f},
                                 {.struct_size = sizeof(vxl_light_shape), .size = 0.1f}};
    vxl_render_params p = scene(VXL_SHADING_SHADOWED, 0.8f);
    light(&p, 0, 1, 0.2f, 0.4f, 0);
    light(&p, 1, -0.9f, 0.5f, 0, 1);
    p.light_shapes = shapes;
    p.ambient_occlusion = 4;
    p.occlusion_strength = 0.5f;
    const uint32_t sizes[4] = {8, 16, 32, 64};
    double err[4];
    for (int s = 0; s < 4; s++) {
        p.illumination_size = sizes[s];
        err[s] = against_reference(&sc, &p, s > 0);
        fprintf(stderr, "    illumination size %u: rmse %.5f\n", sizes[s], err[s]);
    }
    ref_scene_close(&sc);
    for (int s = 0; s < 4; s++) REQUIRE(err[s] >= 0);
    CHECKF(err[3] < 0.7 * err[0], "%.5f at 64 vs %.5f at 8", err[3], err[0]);
    for (int s = 1; s < 4; s++) CHECKF(err[s] < err[s - 1] * 1.05, "size %u: %.5f after %.5f", sizes[s], err[s], err[s - 1]);
    CHECKF(err[3] < 0.01, "%.5f", err[3]);
}

/* Scattering and spot cones against the reference: a spot on the +x blob
 * only, and a sun behind the blobs (travelling towards the eye) seen
 * through forward scattering (g > 0) with the surface term faded out by a
 * large gradient_ref; backward scattering (g < 0) is darker. */
TEST(scattering_and_spot_cones_match_the_reference)
{
    ref_scene sc;
    REQUIRE(ref_scene_open(&sc, 48) == 0);
    vxl_light_shape shapes[2] = {{.struct_size = sizeof(vxl_light_shape)},
                                 {.struct_size = sizeof(vxl_light_shape), .spot_angle = 0.5f, .spot_blend = 0.3f,
                                  .spot_direction = {0.45f, 0, -0.9f}}};
    vxl_render_params p = scene(VXL_SHADING_SCATTER, 0.3f);
    light(&p, 0, 0, -1, 0.2f, 0); /* behind the blobs, seen from +Y */
    light(&p, 1, 0, 0, 0.9f, 1);  /* above, aimed at the +x blob */
    p.light_shapes = shapes;
    p.gradient_ref = 10; /* w ~ 0: the phase function dominates */
    p.illumination_size = 64;
    double mean[2], e = -1;
    for (int k = 0; k < 2; k++) {
        p.anisotropy = k ? -0.6f : 0.6f;
        e = against_reference(&sc, &p, 0);
        double c = 0;
        for (int i = 0; i < RW * RH; i++) c += OUT[4 * i] + OUT[4 * i + 1] + OUT[4 * i + 2];
        mean[k] = c / (3.0 * RW * RH);
        fprintf(stderr, "    g = %+.1f: rmse %.5f against the reference, mean %.4f\n", p.anisotropy, e, mean[k]);
        CHECKF(e >= 0 && e < 0.01, "g = %.1f: rmse %.5f", p.anisotropy, e);
    }
    CHECKF(mean[0] > 1.2 * mean[1], "forward %.4f, backward %.4f", mean[0], mean[1]);
    /* and the match is the cone's and the phase function's doing: without
     * either, the GL image strays from the reference several times as far */
    shapes[1].spot_angle = 0;
    double e_no_cone = against_reference(&sc, &p, 1);
    shapes[1].spot_angle = 0.5f;
    p.shading_model = VXL_SHADING_SHADOWED;
    double e_no_phase = against_reference(&sc, &p, 1);
    ref_scene_close(&sc);
    fprintf(stderr, "    rmse %.5f; without the cone %.5f, without scattering %.5f\n", e, e_no_cone, e_no_phase);
    CHECK(e_no_cone > 3 * e && e_no_phase > 3 * e);
}

/* Levoy's iso-surface opacity makes a thin shell of each blob: its shadow
 * is the shell's, not the table's whole blob (the extinction pass applies
 * the gradient-magnitude opacity as the ray caster does). Without it the
 * error against the reference is 0.0047; with it 0.0026. */
TEST(gradient_opacity_shapes_the_shadows)
{
    ref_scene sc;
    REQUIRE(ref_scene_open(&sc, 48) == 0);
    vxl_render_params p = scene(VXL_SHADING_SHADOWED, 0.8f);
    light(&p, 0, 1, 0, 0, 0);
    p.gradient_opacity = VXL_GOPACITY_ISO;
    p.iso_value = 0.5f;
    p.illumination_size = 48;
    double e = against_reference(&sc, &p, 0);
    ref_scene_close(&sc);
    fprintf(stderr, "    iso opacity: rmse %.5f against the reference\n", e);
    CHECKF(e >= 0 && e < 0.0035, "rmse %.5f", e);
}

int main(void)
{
    R = make_renderer(software_backend());
    vxl_volume *v = blobs_volume();
    if (!R || !v || vxl_renderer_set_volume(R, v) != VXL_OK) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    vxl_volume_destroy(v);
    RUN(the_blob_behind_a_directional_light_is_darker_only_when_shadowed);
    RUN(a_point_light_between_the_blobs_shadows_neither);
    RUN(only_what_changed_is_rebuilt);
    RUN(every_storage_mode_gives_the_same_shadows);
    RUN(a_coarser_light_grid_reads_the_kept_extinction);
    RUN(the_illumination_volumes_fit_the_memory_budget);
    RUN(no_nan_at_the_extremes);
    RUN(the_image_converges_to_the_reference);
    RUN(scattering_and_spot_cones_match_the_reference);
    RUN(gradient_opacity_shapes_the_shadows);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
