/* test_classified_grid.c - vxl_classified_grid against hand computations on
 * volumes of a few voxels: the extinction per world unit -ln(1 - a) /
 * voxel_length, the straight colour made linear, the cell placement, the clip planes
 * baked in, and every refusal with its code. */
#include <math.h>
#include <string.h>

#include "harness.h"
#include "voxlight.h"

/* uint8 volume of n voxels along x, spacing sp (mm) on every axis. */
static vxl_volume *row_volume(const uint8_t *data, uint32_t n, double sp)
{
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U8, .dims = {n, 1, 1}, .data = data,
                         .spacing = {sp, sp, sp}};
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, NULL, &v) == VXL_OK ? v : NULL;
}

/* Red at 0 with opacity 0, blue at 255 with opacity 0.5, window [0, 255]:
 * at value x the colour is (1 - x/255, 0, x/255) and the opacity 0.5 x/255. */
static const float TABLE[8] = {1, 0, 0, 0, 0, 0, 1, 0.5f};

static vxl_render_params params(void)
{
    vxl_render_params p = {.struct_size = sizeof p, .tf_size = 2, .tf_rgba = TABLE, .has_window = 1,
                           .window_low = 0, .window_high = 255};
    return p;
}

static int near(double a, double b) { return fabs(a - b) <= 1e-6 * fmax(1, fabs(b)); }

/* The table's colours are sRGB; the grid's are linear. */
static double linear(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

TEST(density_and_colour_at_voxel_centres)
{
    const uint8_t data[3] = {0, 51, 255};
    vxl_volume *v = row_volume(data, 3, 2.0);
    REQUIRE(v);
    vxl_render_params p = params();
    vxl_grid_info info = {.struct_size = sizeof info};
    float dens[3], rgb[9];
    REQUIRE(vxl_classified_grid(v, &p, NULL, &info, dens, rgb) == VXL_OK);
    CHECK(info.dims[0] == 3 && info.dims[1] == 1 && info.dims[2] == 1);
    CHECK(near(info.voxel_length, 2.0));
    for (int i = 0; i < 3; i++) {
        double x = data[i] / 255.0, sigma = -log(1 - 0.5 * x) / 2.0;
        CHECKF(near(dens[i], sigma), "cell %d: %g, expected %g", i, dens[i], sigma);
        CHECKF(near(rgb[3 * i], linear(1 - x)) && rgb[3 * i + 1] == 0 && near(rgb[3 * i + 2], linear(x)),
               "cell %d: %g %g %g", i, rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]);
    }
    CHECK(near(info.max_density, -log(0.5) / 2.0));
    /* cell centre i is voxel centre i: world x = 2 i with the spacing affine */
    CHECK(near(info.index_to_world[0], 2.0) && near(info.index_to_world[12], 0.0));
    /* opacity_scale 2 makes the last voxel opaque: a large finite density */
    p.opacity_scale = 2;
    REQUIRE(vxl_classified_grid(v, &p, NULL, &info, dens, NULL) == VXL_OK);
    CHECK(isfinite(dens[2]) && dens[2] > 5 && near(dens[1], -log(1 - 2 * 0.5 * 0.2) / 2.0));
    vxl_volume_destroy(v);
}

/* In scene-linear colour the caller's table is the albedo as given, and the
 * library's own (display-referred) presets are decoded once, by the table:
 * a preset's grid is the same in both colour spaces. */
TEST(linear_colour_space_keeps_the_callers_colours_and_decodes_the_presets)
{
    const uint8_t data[3] = {0, 51, 255};
    vxl_volume *v = row_volume(data, 3, 1.0);
    REQUIRE(v);
    vxl_render_params p = params();
    p.color_space = VXL_COLOR_SPACE_LINEAR;
    vxl_grid_info info = {.struct_size = sizeof info};
    float rgb[9], rgb_display[9], dens[3], dens_display[3];
    REQUIRE(vxl_classified_grid(v, &p, NULL, &info, dens, rgb) == VXL_OK);
    for (int i = 0; i < 3; i++) {
        double x = data[i] / 255.0;
        CHECKF(near(rgb[3 * i], 1 - x) && rgb[3 * i + 1] == 0 && near(rgb[3 * i + 2], x), "cell %d: %g %g %g", i,
               rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]);
    }
    p = (vxl_render_params){.struct_size = sizeof p, .preset = VXL_PRESET_HOT, .has_window = 1, .window_high = 255};
    REQUIRE(vxl_classified_grid(v, &p, NULL, &info, dens_display, rgb_display) == VXL_OK);
    p.color_space = VXL_COLOR_SPACE_LINEAR;
    REQUIRE(vxl_classified_grid(v, &p, NULL, &info, dens, rgb) == VXL_OK);
    int coloured = 0;
    for (int i = 0; i < 9; i++) {
        CHECKF(fabs(rgb[i] - rgb_display[i]) <= 1e-6, "component %d: %g linear, %g display", i, rgb[i], rgb_display[i]);
        coloured += rgb[i] > 0.01f && rgb[i] < 0.99f;
    }
    for (int i = 0; i < 3; i++) CHECK(dens[i] == dens_display[i]);
    CHECK(coloured > 0); /* the decode was exercised, not only 0 and 1 */
    p.color_space = VXL_COLOR_SPACE_COUNT;
    CHECK(vxl_classified_grid(v, &p, NULL, &info, dens, rgb) == VXL_ERR_INVALID_ARGUMENT);
    vxl_volume_destroy(v);
}

TEST(coarser_grid_interpolates_between_voxels)
{
    /* 4 voxels, 2 cells: cell centres at voxel x = 0.5 and 2.5 */
    const uint8_t data[4] = {0, 102, 204, 255};
    vxl_volume *v = row_volume(data, 4, 1.0);
    REQUIRE(v);
    vxl_render_params p = params();
    vxl_grid_params g = {.struct_size = sizeof g, .dims = {2, 0, 0}};
    vxl_grid_info info = {0};
    float dens[2];
    REQUIRE(vxl_classified_grid(v, &p, &g, &info, dens, NULL) == VXL_OK);
    CHECK(info.dims[0] == 2 && info.dims[1] == 1);
    double x0 = 51 / 255.0, x1 = 229.5 / 255.0;
    CHECK(near(dens[0], -log(1 - 0.5 * x0)) && near(dens[1], -log(1 - 0.5 * x1)));
    /* each cell is two voxels wide; cell 0's centre is at voxel 0.5 */
    CHECK(near(info.index_to_world[0], 2.0) && near(info.index_to_world[12], 0.5));
    vxl_volume_destroy(v);
}

TEST(clip_plane_baked_into_density)
{
    const uint8_t data[4] = {255, 255, 255, 255};
    vxl_volume *v = row_volume(data, 4, 1.0);
    REQUIRE(v);
    vxl_render_params p = params();
    /* keeps world x >= 1.5: voxels 2 and 3 */
    vxl_cutaway cut = {.struct_size = sizeof cut, .clip_plane_count = 1, .clip_planes = {{.plane = {1, 0, 0, -1.5f}}}};
    p.cutaway = &cut;
    vxl_grid_info info = {0};
    float dens[4], rgb[12];
    REQUIRE(vxl_classified_grid(v, &p, NULL, &info, dens, rgb) == VXL_OK);
    CHECK(dens[0] == 0 && dens[1] == 0 && near(dens[2], -log(0.5)) && near(dens[3], -log(0.5)));
    vxl_volume_destroy(v);
}

TEST(slices_filled_by_every_worker)
{
    /* one column of 9 slices: the slabs the processors share, each value its own */
    const uint8_t data[9] = {0, 30, 60, 90, 120, 150, 180, 210, 240};
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U8, .dims = {1, 1, 9}, .data = data};
    vxl_volume *v = NULL;
    REQUIRE(vxl_volume_create(&d, NULL, &v) == VXL_OK);
    vxl_render_params p = params();
    vxl_grid_info info = {0};
    float dens[9], rgb[27];
    REQUIRE(vxl_classified_grid(v, &p, NULL, &info, dens, rgb) == VXL_OK);
    for (int z = 0; z < 9; z++) {
        double x = data[z] / 255.0;
        CHECKF(near(dens[z], -log(1 - 0.5 * x)), "slice %d: %g", z, dens[z]);
        CHECK(near(rgb[3 * z + 2], linear(x)));
    }
    CHECK(near(info.max_density, -log(1 - 0.5 * 240 / 255.0)));
    vxl_volume_destroy(v);
}

TEST(refusals)
{
    const uint8_t data[2] = {0, 255};
    vxl_volume *v = row_volume(data, 2, 1.0);
    REQUIRE(v);
    vxl_render_params p = params();
    vxl_grid_info info = {0};
    CHECK(vxl_classified_grid(NULL, &p, NULL, &info, NULL, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_classified_grid(v, &p, NULL, NULL, NULL, NULL) == VXL_ERR_INVALID_ARGUMENT);
    p.mode = VXL_MODE_MIP;
    CHECK(vxl_classified_grid(v, &p, NULL, &info, NULL, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_last_error(), "mip") != NULL);
    p = params();
    vxl_grid_params g = {.struct_size = 4};
    CHECK(vxl_classified_grid(v, &p, &g, &info, NULL, NULL) == VXL_ERR_INVALID_ARGUMENT);
    g = (vxl_grid_params){.dims = {1u << 20, 1u << 20, 2}};
    CHECK(vxl_classified_grid(v, &p, &g, &info, NULL, NULL) == VXL_ERR_LIMIT);
    /* sizing call: no buffers, info only */
    CHECK(vxl_classified_grid(v, &p, NULL, &info, NULL, NULL) == VXL_OK && info.dims[0] == 2);
    vxl_volume_destroy(v);
}

int main(void)
{
    RUN(density_and_colour_at_voxel_centres);
    RUN(linear_colour_space_keeps_the_callers_colours_and_decodes_the_presets);
    RUN(coarser_grid_interpolates_between_voxels);
    RUN(clip_plane_baked_into_density);
    RUN(slices_filled_by_every_worker);
    RUN(refusals);
    return TEST_SUMMARY();
}
