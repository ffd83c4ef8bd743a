/* test_environment.c - the World's light (voxlight.h's vxl_environment;
 * csrc/light/environment_map.c, the environment pass of
 * shaders/compute/illumination.comp, lib/shading.glsl) and its file reader
 * (csrc/io/hdr_read.c, vxl_environment_image_load):
 *  - the map's reduction to direction cells: uniform maps, solid-angle
 *    weights, Blender's equirectangular convention and rotation;
 *  - rendered through the public API: a sphere lit by an environment bright
 *    on one side is brighter on that side, rotating the map by 180 degrees
 *    swaps the sides and by -90 / +90 turns the bright side towards / away
 *    from the camera; an environment-only scene is not dark; no environment
 *    is today's image bit for bit; Phong's term is the map's mean; the
 *    irradiance volume is rebuilt only when what it depends on changes;
 *    bad maps are refused with a message;
 *  - the Radiance reader: flat and run-length scanlines, both row orders,
 *    and corrupt or truncated files refused cleanly.
 *
 * The scene: the sphere phantom seen by the default camera from +Y, so
 * world +x is the image's left half. */
#include <stddef.h>
#include <stdio.h>
#include <unistd.h>

#include "environment_map.h"
#include "harness.h"
#include "hdr_read.h"
#include "hdr_writer.h"
#include "test_util.h"
#include "voxlight_dev.h"

#define W 64
#define H 64
#define N 40

static vxl_renderer *R;
static float IMG[W * H * 4], IMG2[W * H * 4], IMG3[W * H * 4];

/* ------------------------------------------------------------ the reduction */

/* A map bright (value) where the map direction's x exceeds 0.7, 0 elsewhere. */
static void bright_towards_x(float *rgb, uint32_t w, uint32_t h, float value)
{
    for (uint32_t j = 0; j < h; j++)
        for (uint32_t i = 0; i < w; i++) {
            double az = M_PI * (1.0 - 2.0 * (i + 0.5) / w), el = M_PI * ((j + 0.5) / h - 0.5);
            float v = cos(el) * cos(az) > 0.7 ? value : 0.0f;
            for (int c = 0; c < 3; c++) rgb[3 * (j * w + i) + c] = v;
        }
}

static int brightest_cell(float cells[VXL_ENV_CELLS][3])
{
    int best = 0;
    for (int k = 1; k < VXL_ENV_CELLS; k++)
        if (cells[k][0] > cells[best][0]) best = k;
    return best;
}

TEST(a_uniform_map_fills_every_cell_with_its_colour)
{
    const float one[3] = {0.25f, 0.5f, 2.0f};
    float cells[VXL_ENV_CELLS][3];
    vxl_environment_reduce(one, 1, 1, 3.0f, 37.0f, cells);
    for (int k = 0; k < VXL_ENV_CELLS; k++)
        for (int c = 0; c < 3; c++) CHECKF(fabsf(cells[k][c] - 3.0f * one[c]) < 1e-5f, "cell %d: %g", k, cells[k][c]);
    /* a 2x1 map: its halves are the sky around -X... and +X (u = 0.5 is +X) */
    const float halves[6] = {1, 1, 1, 0, 0, 0};
    vxl_environment_reduce(halves, 2, 1, 1.0f, 0.0f, cells);
    for (int k = 0; k < VXL_ENV_CELLS; k++) {
        double d[3];
        vxl_environment_cell_direction(k, d);
        /* pixel 0 (u < 0.5) holds azimuths (0, pi): +Y */
        CHECKF(fabs(cells[k][0] - (d[1] > 0 ? 1.0 : 0.0)) < 1e-6, "cell %d (y %.2f): %g", k, d[1], cells[k][0]);
    }
}

TEST(the_cells_are_weighted_by_solid_angle)
{
    /* the top half of the rows (elevation > 0) 1, the bottom 0: the upper two bands exactly 1 */
    enum { MW = 16, MH = 8 };
    float map[MW * MH * 3];
    for (int j = 0; j < MH; j++)
        for (int i = 0; i < MW * 3; i++) map[j * MW * 3 + i] = j >= MH / 2 ? 1.0f : 0.0f;
    float cells[VXL_ENV_CELLS][3];
    vxl_environment_reduce(map, MW, MH, 1.0f, 0.0f, cells);
    double mean = 0;
    for (int k = 0; k < VXL_ENV_CELLS; k++) {
        double d[3];
        vxl_environment_cell_direction(k, d);
        CHECKF(fabs(cells[k][1] - (d[2] > 0 ? 1.0 : 0.0)) < 1e-6, "cell %d (z %.2f): %g", k, d[2], cells[k][1]);
        mean += cells[k][1] / VXL_ENV_CELLS;
    }
    CHECKF(fabs(mean - 0.5) < 1e-6, "mean %g", mean); /* half the sphere */
    /* one bright row at the zenith: only the top band sees it */
    memset(map, 0, sizeof map);
    for (int i = 0; i < MW * 3; i++) map[(MH - 1) * MW * 3 + i] = 1.0f;
    vxl_environment_reduce(map, MW, MH, 1.0f, 0.0f, cells);
    for (int k = 0; k < VXL_ENV_CELLS; k++)
        CHECKF((cells[k][0] > 0) == (k / VXL_ENV_SECTORS == VXL_ENV_BANDS - 1), "cell %d: %g", k, cells[k][0]);
}

TEST(the_map_follows_blenders_equirectangular_convention_and_rotation)
{
    enum { MW = 64, MH = 32 };
    static float map[MW * MH * 3];
    bright_towards_x(map, MW, MH, 1.0f);
    float cells[VXL_ENV_CELLS][3];
    const struct {
        float rotation;
        double towards[3];
    } cases[] = {{0, {1, 0, 0}}, {180, {-1, 0, 0}}, {90, {0, -1, 0}}, {-90, {0, 1, 0}}, {450, {0, -1, 0}}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        vxl_environment_reduce(map, MW, MH, 1.0f, cases[c].rotation, cells);
        /* the bright cells' mean direction */
        double d[3], m[3] = {0, 0, 0};
        for (int k = 0; k < VXL_ENV_CELLS; k++) {
            vxl_environment_cell_direction(k, d);
            for (int a = 0; a < 3; a++) m[a] += cells[k][0] * d[a];
        }
        double n = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        double dot = (m[0] * cases[c].towards[0] + m[1] * cases[c].towards[1]) / n;
        CHECKF(dot > 0.95, "rotation %g: bright towards (%.2f %.2f %.2f)", cases[c].rotation, m[0] / n, m[1] / n,
               m[2] / n);
    }
    /* a small sun in a large map lands in its cell whole (splatted, not point-sampled) */
    enum { BW = 512, BH = 256 };
    float *big = calloc((size_t)BW * BH * 3, sizeof(float));
    REQUIRE(big);
    big[3 * (200 * BW + 300)] = 1000.0f; /* one pixel */
    vxl_environment_reduce(big, BW, BH, 1.0f, 0.0f, cells);
    double total = 0;
    for (int k = 0; k < VXL_ENV_CELLS; k++) total += cells[k][0];
    CHECKF(total > 0 && cells[brightest_cell(cells)][0] == total, "total %g", total);
    free(big);
}

/* ------------------------------------------------------------ rendering */

static vxl_render_params scene(uint32_t model)
{
    static const float tf[8] = {1, 1, 1, 0, 1, 1, 1, 0.9f};
    vxl_render_params p = {.struct_size = sizeof p, .width = W, .height = H, .tf_rgba = tf, .tf_size = 2,
                           .has_window = 1, .window_low = 0.45f, .window_high = 0.6f, .shading_model = model,
                           .jitter_off = 1, .illumination_size = 32};
    return p;
}

/* Straight brightness of the covered pixels of one half (0 left, 1 right, 2 both). */
static double brightness(const float *img, int half)
{
    double colour = 0, cover = 0;
    for (uint32_t i = 0; i < W * H; i++) {
        const float *px = img + 4 * i;
        if ((half < 2 && (i % W >= W / 2) != half) || px[3] < 0.5f) continue;
        colour += px[0] + px[1] + px[2];
        cover += 3 * px[3];
    }
    return cover > 0 ? colour / cover : -1;
}

static int render(const vxl_render_params *p, float *img)
{
    int rc = vxl_render(R, p, img, NULL);
    if (rc) fprintf(stderr, "    render failed: %s\n", vxl_renderer_error(R));
    return rc;
}

enum { MW = 64, MH = 32 };
static float SIDE_MAP[MW * MH * 3];

static vxl_environment side_env(float rotation)
{
    vxl_environment env = {.struct_size = sizeof env, .width = MW, .height = MH, .rgb = SIDE_MAP, .strength = 1,
                           .rotation_deg = rotation};
    return env;
}

TEST(an_environment_bright_on_one_side_lights_that_side_and_turns_with_its_rotation)
{
    bright_towards_x(SIDE_MAP, MW, MH, 4.0f);
    for (uint32_t model = VXL_SHADING_SHADOWED; model <= VXL_SHADING_SCATTER; model++) {
        vxl_render_params p = scene(model); /* no lamps: the environment alone */
        vxl_environment env = side_env(0);
        p.environment = &env;
        REQUIRE(render(&p, IMG) == VXL_OK);
        env.rotation_deg = 180;
        REQUIRE(render(&p, IMG2) == VXL_OK);
        double l0 = brightness(IMG, 0), r0 = brightness(IMG, 1), l1 = brightness(IMG2, 0), r1 = brightness(IMG2, 1);
        fprintf(stderr, "    %s: rotation 0: %.3f | %.3f, rotation 180: %.3f | %.3f\n",
                vxl_shading_model_name(model), l0, r0, l1, r1);
        CHECKF(l0 > 1.5 * r0 + 0.02, "+x side %.3f, -x side %.3f", l0, r0);
        CHECKF(r1 > 1.5 * l1 + 0.02, "rotated: +x side %.3f, -x side %.3f", l1, r1);
        /* a mirror image: the sides swap, nearly exactly */
        CHECKF(fabs(l0 - r1) < 0.1 * l0 && fabs(r0 - l1) < 0.1 * l0 + 0.01, "%.3f vs %.3f, %.3f vs %.3f", l0, r1,
               r0, l1);
        /* -90 brings the map's +X to world +Y, the camera's side; +90 to the back */
        env.rotation_deg = -90;
        REQUIRE(render(&p, IMG) == VXL_OK);
        env.rotation_deg = 90;
        REQUIRE(render(&p, IMG2) == VXL_OK);
        double front = brightness(IMG, 2), back = brightness(IMG2, 2);
        fprintf(stderr, "    %s: rotation -90 %.3f, +90 %.3f\n", vxl_shading_model_name(model), front, back);
        CHECKF(front > 1.5 * back + 0.02, "-90: %.3f, +90: %.3f", front, back);
        CHECK(image_is_sane(IMG, NULL, W * H) && image_is_sane(IMG2, NULL, W * H));
    }
}

TEST(an_environment_only_scene_is_not_dark)
{
    const float white[3] = {1, 1, 1};
    vxl_environment env = {.struct_size = sizeof env, .width = 1, .height = 1, .rgb = white, .strength = 1};
    for (uint32_t model = 0; model < VXL_SHADING_COUNT; model++) {
        vxl_render_params p = scene(model);
        p.environment = &env;
        REQUIRE(render(&p, IMG) == VXL_OK);
        double b = brightness(IMG, 2);
        fprintf(stderr, "    %s, a white World, no lamps: %.3f\n", vxl_shading_model_name(model), b);
        CHECKF(b > 0.2, "%s: %.3f", vxl_shading_model_name(model), b);
        /* a black World and no lamps: no headlight stands in, only the colour's own lack of light */
        const float black[3] = {0, 0, 0};
        vxl_environment dark = env;
        dark.rgb = black;
        p.environment = &dark;
        REQUIRE(render(&p, IMG2) == VXL_OK);
        CHECKF(brightness(IMG2, 2) < 0.5 * b, "black World %.3f", brightness(IMG2, 2));
    }
}

TEST(no_environment_is_todays_image_bit_for_bit)
{
    const float white[3] = {1, 1, 1};
    for (uint32_t model = 0; model < VXL_SHADING_COUNT; model++) {
        vxl_render_params p = scene(model);
        p.ambient_occlusion = 4;
        REQUIRE(render(&p, IMG) == VXL_OK);
        vxl_environment env = {.struct_size = sizeof env, .width = 1, .height = 1, .rgb = white, .strength = 1};
        p.environment = &env;
        REQUIRE(render(&p, IMG2) == VXL_OK);
        CHECK(memcmp(IMG, IMG2, sizeof IMG) != 0);
        /* an older caller's struct ends before the field: whatever lies there is not read */
        p.struct_size = offsetof(vxl_render_params, environment);
        p.environment = (const vxl_environment *)(uintptr_t)1;
        REQUIRE(render(&p, IMG3) == VXL_OK);
        CHECKF(memcmp(IMG, IMG3, sizeof IMG) == 0, "%s: older struct", vxl_shading_model_name(model));
        p.struct_size = sizeof p;
        p.environment = NULL;
        REQUIRE(render(&p, IMG3) == VXL_OK);
        CHECKF(memcmp(IMG, IMG3, sizeof IMG) == 0, "%s: NULL after an environment frame", vxl_shading_model_name(model));
    }
}

TEST(phongs_term_is_the_maps_mean_radiance)
{
    /* Phong with a uniform grey World g is Phong with ambient = diffuse * g */
    const float grey[3] = {0.4f, 0.4f, 0.4f};
    vxl_render_params p = scene(VXL_SHADING_PHONG);
    p.light_count = 1;
    p.lights[0].position[0] = 1;
    p.lights[0].position[1] = 1;
    vxl_environment env = {.struct_size = sizeof env, .width = 1, .height = 1, .rgb = grey, .strength = 1.5f};
    p.environment = &env;
    REQUIRE(render(&p, IMG) == VXL_OK);
    p.environment = NULL;
    p.has_material = 1;
    p.ambient = 0.7f * 0.4f * 1.5f;
    p.diffuse = 0.7f;
    p.specular = 0.3f;
    p.shininess = 24;
    REQUIRE(render(&p, IMG2) == VXL_OK);
    double e = image_rmse(IMG, IMG2, W * H);
    fprintf(stderr, "    rmse %.2g\n", e);
    CHECKF(e < 1e-5, "rmse %g", e);
}

TEST(the_irradiance_volume_is_rebuilt_only_when_what_it_depends_on_changes)
{
    bright_towards_x(SIDE_MAP, MW, MH, 4.0f);
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    vxl_environment env = side_env(0);
    p.environment = &env;
    REQUIRE(render(&p, IMG) == VXL_OK);
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECKF(renderer_stats(R).illumination_rebuilt == 0, "%u", renderer_stats(R).illumination_rebuilt);
    p.azimuth_deg = 40; /* the camera: nothing */
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECK(renderer_stats(R).illumination_rebuilt == 0);
    env.rotation_deg = 30; /* the map turns: the environment alone */
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECKF(renderer_stats(R).illumination_rebuilt == 1, "%u", renderer_stats(R).illumination_rebuilt);
    env.key = 77; /* the caller names the pixels: a new name is a new map */
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECK(renderer_stats(R).illumination_rebuilt == 1);
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECK(renderer_stats(R).illumination_rebuilt == 0);
    p.opacity_scale = 0.5f; /* the classification: everything (here the environment and a lamp) */
    p.light_count = 1;
    p.lights[0].position[0] = 1;
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECKF(renderer_stats(R).illumination_rebuilt == 2, "%u", renderer_stats(R).illumination_rebuilt);
    p.lights[0].position[1] = 1; /* a lamp moves: that lamp alone */
    REQUIRE(render(&p, IMG) == VXL_OK);
    CHECKF(renderer_stats(R).illumination_rebuilt == 1, "%u", renderer_stats(R).illumination_rebuilt);
}

TEST(bad_environments_are_refused_with_a_message)
{
    float px[6] = {1, 1, 1, 1, 1, 1};
    vxl_render_params p = scene(VXL_SHADING_SHADOWED);
    struct {
        const char *what;
        vxl_environment env;
    } cases[] = {
        {"width 0", {.struct_size = sizeof(vxl_environment), .width = 0, .height = 1, .rgb = px, .strength = 1}},
        {"no pixels", {.struct_size = sizeof(vxl_environment), .width = 1, .height = 1, .strength = 1}},
        {"reserved", {.struct_size = sizeof(vxl_environment), .width = 1, .height = 1, .rgb = px, .reserved = 1}},
        {"small struct", {.struct_size = 8, .width = 1, .height = 1, .rgb = px}},
        {"strength nan", {.struct_size = sizeof(vxl_environment), .width = 1, .height = 1, .rgb = px, .strength = NAN}},
        {"strength < 0", {.struct_size = sizeof(vxl_environment), .width = 1, .height = 1, .rgb = px, .strength = -1}},
        {"rotation inf", {.struct_size = sizeof(vxl_environment), .width = 1, .height = 1, .rgb = px,
                          .rotation_deg = INFINITY}},
        {"huge", {.struct_size = sizeof(vxl_environment), .width = 1u << 16, .height = 1u << 16, .rgb = px}},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        p.environment = &cases[i].env;
        int rc = vxl_render(R, &p, IMG, NULL);
        CHECKF(rc == VXL_ERR_INVALID_ARGUMENT && *vxl_renderer_error(R), "%s: %s", cases[i].what, vxl_error_name(rc));
    }
    const float values[] = {NAN, -1.0f, INFINITY};
    for (size_t i = 0; i < 3; i++) {
        px[4] = values[i];
        vxl_environment env = {.struct_size = sizeof env, .width = 2, .height = 1, .rgb = px, .strength = 1};
        p.environment = &env;
        int rc = vxl_render(R, &p, IMG, NULL);
        CHECKF(rc == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(R), "pixel 1"), "%g: %s", values[i],
               vxl_renderer_error(R));
    }
    /* the renderer still works */
    p.environment = NULL;
    CHECK(render(&p, IMG) == VXL_OK);
}

/* ------------------------------------------------------------ the .hdr reader */

static void test_map(float *rgb, uint32_t w, uint32_t h)
{
    for (uint32_t i = 0; i < w * h; i++) {
        uint32_t x = i % w, y = i / w;
        rgb[3 * i] = x < w / 2 ? 0.5f : 4.0f; /* runs */
        rgb[3 * i + 1] = (float)y / h + 0.01f * (x % 3);
        rgb[3 * i + 2] = y == 0 ? 1000.0f : 0.0f; /* the bottom row, and zeros */
    }
}

TEST(radiance_files_decode_flat_and_run_length_in_both_row_orders)
{
    const uint32_t sizes[][2] = {{1, 1}, {5, 3}, {8, 2}, {300, 7}};
    for (size_t s = 0; s < 4; s++)
        for (int rle = 0; rle < 2; rle++)
            for (int top = 0; top < 2; top++) {
                uint32_t w = sizes[s][0], h = sizes[s][1];
                float *in = malloc((size_t)w * h * 3 * sizeof(float)), *out = malloc((size_t)w * h * 3 * sizeof(float));
                REQUIRE(in && out);
                test_map(in, w, h);
                size_t n = 0;
                uint8_t *file = hdr_encode(in, w, h, rle, top, &n);
                REQUIRE(file);
                uint32_t gw = 0, gh = 0;
                vxl_err e = {0};
                int rc = vxl_hdr_decode(file, n, 1u << 20, out, &gw, &gh, &e);
                CHECKF(rc == VXL_OK && gw == w && gh == h, "%ux%u rle %d top %d: %s", w, h, rle, top, e.msg);
                double worst = 0;
                for (size_t i = 0; rc == VXL_OK && i < (size_t)w * h * 3; i++) {
                    double rel = fabs(out[i] - in[i]) / fmax(fmax(in[i - i % 3], fmax(in[i - i % 3 + 1], in[i - i % 3 + 2])), 1e-6);
                    worst = rel > worst ? rel : worst;
                }
                CHECKF(worst < 1.0 / 128, "%ux%u rle %d top %d: worst relative error %g", w, h, rle, top, worst);
                /* every prefix of the file is refused cleanly, never read past */
                for (size_t k = 0; k < n; k += (n > 400 ? 7 : 1)) {
                    uint8_t *cut = malloc(k ? k : 1);
                    REQUIRE(cut);
                    memcpy(cut, file, k);
                    vxl_err ce = {0};
                    uint32_t cw, ch;
                    int crc = vxl_hdr_decode(cut, k, 1u << 20, out, &cw, &ch, &ce);
                    CHECKF(crc == VXL_ERR_FORMAT && ce.msg[0], "prefix %zu of %zu: %d", k, n, crc);
                    free(cut);
                }
                free(file);
                free(in);
                free(out);
            }
}

static int decode_text(const char *text, size_t n, vxl_err *e)
{
    float out[64 * 3];
    uint32_t w, h;
    return vxl_hdr_decode((const uint8_t *)text, n, 64, out, &w, &h, e);
}

TEST(corrupt_radiance_files_are_refused_with_what_is_wrong)
{
#define HEAD "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n"
    static const struct {
        const char *what, *text;
        size_t n;
        int rc;
        const char *says;
    } cases[] = {
        {"no signature", "P6\n1 1\n255\nabc", 14, VXL_ERR_FORMAT, "signature"},
        {"xyze", "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\nabcd", 46, VXL_ERR_FORMAT, "xyze"},
        {"no end of header", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", 34, VXL_ERR_FORMAT, "never ends"},
        {"bad resolution", HEAD "-Y one +X 1\nabcd", 51, VXL_ERR_FORMAT, "resolution"},
        {"rotated", HEAD "+X 1 -Y 1\nabcd", 49, VXL_ERR_FORMAT, "orientation"},
        {"zero width", HEAD "-Y 1 +X 0\n", 45, VXL_ERR_FORMAT, "size"},
        {"too many pixels", HEAD "-Y 100 +X 100\n", 49, VXL_ERR_LIMIT, "exceed"},
        {"short", HEAD "-Y 2 +X 2\nabcdabcd", 53, VXL_ERR_FORMAT, "too short"},
        {"old rle", HEAD "-Y 1 +X 2\n\1\1\1\5abcd", 53, VXL_ERR_FORMAT, "old-style"},
        {"length mismatch", HEAD "-Y 1 +X 8\n\2\2\0\11" "\210\1\210\1\210\1\210\1", 57, VXL_ERR_FORMAT, "length"},
        {"run past the end", HEAD "-Y 1 +X 8\n\2\2\0\10" "\211\1\210\1\210\1\210\1", 57, VXL_ERR_FORMAT, "passes"},
        {"zero count", HEAD "-Y 1 +X 8\n\2\2\0\10" "\0\1\210\1\210\1\210\1", 57, VXL_ERR_FORMAT, "zero count"},
        {"literals past the end", HEAD "-Y 1 +X 8\n\2\2\0\10" "\11\1\1\1\1\1\1\1\1\1\210\1\210\1", 63, VXL_ERR_FORMAT,
         "literal"},
    };
#undef HEAD
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        vxl_err e = {0};
        int rc = decode_text(cases[i].text, cases[i].n, &e);
        CHECKF(rc == cases[i].rc && strstr(e.msg, cases[i].says), "%s: %d %s", cases[i].what, rc, e.msg);
    }
}

TEST(environment_image_load_reads_hdr_and_hands_exr_to_its_helper)
{
    char path[] = "/tmp/vxl_env_XXXXXX.hdr";
    int fd = mkstemps(path, 4);
    REQUIRE(fd >= 0);
    close(fd);
    float in[20 * 10 * 3], out[20 * 10 * 3];
    test_map(in, 20, 10);
    REQUIRE(hdr_write_file(path, in, 20, 10, 1) == 0);
    uint32_t w = 0, h = 0;
    CHECK(vxl_environment_image_load(path, NULL, 0, &w, &h) == VXL_OK && w == 20 && h == 10);
    /* (the messages are the CLI tests': this binary links its own copy of the
     * error room for hdr_read.c, so vxl_last_error here is not the library's) */
    CHECK(vxl_environment_image_load(path, out, 100, &w, &h) == VXL_ERR_LIMIT);
    CHECK(vxl_environment_image_load(path, out, 200, &w, &h) == VXL_OK);
    /* (row 0 shares its exponent with its bright blue: its red is coarse) */
    CHECKF(fabsf(out[3 * 100] - in[3 * 100]) < 0.01f && fabsf(out[3 * 199] - in[3 * 199]) < 0.05f, "%g %g",
           out[3 * 100], out[3 * 199]);
    unlink(path);
    CHECK(vxl_environment_image_load(path, NULL, 0, &w, &h) == VXL_ERR_IO);
    /* OpenEXR goes to the OpenImageIO helper: a missing file is the same
     * VXL_ERR_IO, one that is not OpenEXR inside is VXL_ERR_FORMAT (the
     * images it reads are the CLI tests', written by oiiotool) */
    char exr[] = "/tmp/vxl_env_XXXXXX.exr";
    fd = mkstemps(exr, 4);
    REQUIRE(fd >= 0);
    static const char junk[] = "v/1\001 not OpenEXR";
    REQUIRE(write(fd, junk, sizeof junk - 1) == (ssize_t)(sizeof junk - 1));
    close(fd);
    CHECK(vxl_environment_image_load(exr, NULL, 0, &w, &h) == VXL_ERR_FORMAT);
    unlink(exr);
    CHECK(vxl_environment_image_load(exr, NULL, 0, &w, &h) == VXL_ERR_IO);
}

int main(void)
{
    RUN(a_uniform_map_fills_every_cell_with_its_colour);
    RUN(the_cells_are_weighted_by_solid_angle);
    RUN(the_map_follows_blenders_equirectangular_convention_and_rotation);
    RUN(radiance_files_decode_flat_and_run_length_in_both_row_orders);
    RUN(corrupt_radiance_files_are_refused_with_what_is_wrong);
    RUN(environment_image_load_reads_hdr_and_hands_exr_to_its_helper);
    R = make_renderer(software_backend());
    vxl_phantom_desc d = {.struct_size = sizeof d, .kind = VXL_PHANTOM_SPHERE, .dims = {N, N, N}};
    vxl_volume *v = NULL;
    if (!R || vxl_phantom_create(&d, &v) != VXL_OK || vxl_renderer_set_volume(R, v) != VXL_OK) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    vxl_volume_destroy(v);
    RUN(an_environment_bright_on_one_side_lights_that_side_and_turns_with_its_rotation);
    RUN(an_environment_only_scene_is_not_dark);
    RUN(no_environment_is_todays_image_bit_for_bit);
    RUN(phongs_term_is_the_maps_mean_radiance);
    RUN(the_irradiance_volume_is_rebuilt_only_when_what_it_depends_on_changes);
    RUN(bad_environments_are_refused_with_a_message);
    vxl_renderer_destroy(R);
    return TEST_SUMMARY();
}
