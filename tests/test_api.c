/* test_api.c - the public API's contract: error codes and messages, limits,
 * defaults, NULL handling, backend selection. */
#include <stdio.h>

#include "harness.h"
#include "test_util.h"

TEST(abi_and_names)
{
    CHECK(vxl_abi_version() == VXL_ABI_VERSION);
    uint32_t f = 99;
    CHECK(vxl_filter_from_name("sobel26", &f) == VXL_OK && f == VXL_FILTER_SOBEL26);
    CHECK(vxl_filter_from_name("nope", &f) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_last_error(), "nope") != NULL);
    for (uint32_t i = 0; i < VXL_FILTER_COUNT; i++) {
        uint32_t back;
        CHECK(vxl_filter_from_name(vxl_filter_name(i), &back) == VXL_OK && back == i);
    }
    CHECK(vxl_filter_name(VXL_FILTER_COUNT) == NULL);
    CHECK(vxl_preset_from_name("bone", &f) == VXL_OK && f == VXL_PRESET_BONE);
    CHECK(strcmp(vxl_error_name(VXL_ERR_LIMIT), "over a limit") == 0);
}

TEST(destroy_null_is_a_noop)
{
    vxl_volume_destroy(NULL);
    vxl_renderer_destroy(NULL);
    CHECK(1);
}

TEST(volume_create_validates)
{
    float one = 1;
    vxl_volume_desc d;
    memset(&d, 0, sizeof d);
    d.dtype = VXL_DTYPE_F32;
    d.dims[0] = d.dims[1] = d.dims[2] = 1;
    d.data = &one;
    vxl_volume *v = (vxl_volume *)&one;
    d.data = NULL;
    CHECK(vxl_volume_create(&d, NULL, &v) == VXL_ERR_INVALID_ARGUMENT && v == NULL);
    d.data = &one;
    d.dtype = 42;
    CHECK(vxl_volume_create(&d, NULL, &v) == VXL_ERR_INVALID_ARGUMENT);
    d.dtype = VXL_DTYPE_F32;
    d.dims[1] = 0;
    CHECK(vxl_volume_create(&d, NULL, &v) == VXL_ERR_FORMAT);
    /* absurd sizes are refused before anything is allocated or read */
    d.dims[0] = d.dims[1] = d.dims[2] = 100000;
    CHECK(vxl_volume_create(&d, NULL, &v) == VXL_ERR_LIMIT);
    CHECKF(strstr(vxl_last_error(), "budget") != NULL, "message: %s", vxl_last_error());
    d.dims[0] = d.dims[1] = d.dims[2] = 4000000000u;
    CHECK(vxl_volume_create(&d, NULL, &v) == VXL_ERR_LIMIT);
    vxl_load_options lo = {.struct_size = sizeof lo, .memory_budget_bytes = 1000};
    d.dims[0] = d.dims[1] = d.dims[2] = 11; /* 1331 voxels * 4 bytes > 1000 */
    static float buf[11 * 11 * 11];
    d.data = buf;
    CHECK(vxl_volume_create(&d, &lo, &v) == VXL_ERR_LIMIT);
    lo.memory_budget_bytes = 0;
    CHECK(vxl_volume_create(&d, &lo, &v) == VXL_OK && v);
    vxl_volume_destroy(v);
}

TEST(nan_voxels_are_counted_and_neutralised)
{
    float data[8] = {1, NAN, 3, INFINITY, -INFINITY, 2, 5, NAN};
    vxl_volume_desc d;
    memset(&d, 0, sizeof d);
    d.dtype = VXL_DTYPE_F32;
    d.dims[0] = 2;
    d.dims[1] = 2;
    d.dims[2] = 2;
    d.data = data;
    vxl_volume *v = NULL;
    REQUIRE(vxl_volume_create(&d, NULL, &v) == VXL_OK);
    vxl_volume_info in = {.struct_size = sizeof in};
    REQUIRE(vxl_volume_get_info(v, &in) == VXL_OK);
    CHECK(in.nan_count == 2 && in.inf_count == 2);
    CHECK(in.value_min == 1 && in.value_max == 5);
    vxl_volume_destroy(v);
}

TEST(histogram_counts_data_values)
{
    float data[8] = {1, NAN, 3, INFINITY, 1.5f, 2, 5, NAN};
    vxl_volume_desc d;
    memset(&d, 0, sizeof d);
    d.dtype = VXL_DTYPE_F32;
    d.dims[0] = 8;
    d.dims[1] = d.dims[2] = 1;
    d.data = data;
    vxl_volume *v = NULL;
    REQUIRE(vxl_volume_create(&d, NULL, &v) == VXL_OK);
    uint64_t c[4] = {9, 9, 9, 9};
    /* bins of width 1 over [1, 5]: {1, 1.5} {2} {3} {5 and +inf clamped to 5}; NaN excluded */
    REQUIRE(vxl_volume_histogram(v, 4, 1, 5, c) == VXL_OK);
    CHECK(c[0] == 2 && c[1] == 1 && c[2] == 1 && c[3] == 2);
    REQUIRE(vxl_volume_histogram(v, 2, 10, 20, c) == VXL_OK); /* all outside */
    CHECK(c[0] == 0 && c[1] == 0);
    CHECK(vxl_volume_histogram(v, 0, 1, 5, c) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_volume_histogram(v, 4, 5, 1, c) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_volume_histogram(v, 4, 1, NAN, c) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_volume_histogram(NULL, 4, 1, 5, c) == VXL_ERR_INVALID_ARGUMENT);
    vxl_volume_destroy(v);
}

TEST(scaling_and_int_types)
{
    int16_t data[8] = {-32768, -1, 0, 1, 100, 200, 300, 32767};
    vxl_volume_desc d;
    memset(&d, 0, sizeof d);
    d.dtype = VXL_DTYPE_I16;
    d.dims[0] = 8;
    d.dims[1] = d.dims[2] = 1;
    d.data = data;
    d.scl_slope = -2;
    d.scl_inter = 10;
    vxl_volume *v = NULL;
    REQUIRE(vxl_volume_create(&d, NULL, &v) == VXL_OK);
    vxl_volume_info in = {.struct_size = sizeof in};
    vxl_volume_get_info(v, &in);
    CHECK(in.value_min == 32767 * -2.0 + 10 && in.value_max == -32768 * -2.0 + 10);
    CHECK(in.texture_bits == 16);
    vxl_volume_destroy(v);
}

TEST(renderer_errors_are_reported)
{
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(r);
    static float img[16 * 16 * 4];
    vxl_render_params p = default_params(16, 16);
    CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_STATE);
    CHECK(strstr(vxl_renderer_error(r), "no volume") != NULL);
    CHECK(strstr(vxl_last_error(), "no volume") != NULL);
    double prm[4] = {0.1, 0, 0, 0};
    vxl_volume *v = make_volume_f32(8, 8, 8, field_ramp, prm);
    REQUIRE(v && vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_volume_destroy(v);
    CHECK(vxl_render(r, &p, NULL, NULL) == VXL_ERR_INVALID_ARGUMENT);
    p.filter = 77;
    CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    p = default_params(16, 16);
    p.step = -1;
    CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    p = default_params(16, 16);
    p.has_camera = 1; /* all-zero matrices are singular */
    CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_renderer_error(r), "singular") != NULL);
    p = default_params(16, 16);
    p.struct_size = 8;
    CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    p = default_params(16, 16);
    p.light_count = 9;
    CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    p = default_params(16, 16);
    p.has_window = 1;
    p.window_low = NAN;
    CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
    /* after all those failures the renderer still works */
    p = default_params(16, 16);
    CHECK(vxl_render(r, &p, img, NULL) == VXL_OK);
    vxl_renderer_destroy(r);
}

TEST(renderer_budget_and_defaults)
{
    vxl_renderer_options o = {.struct_size = sizeof o, .backend = software_backend(), .memory_budget_bytes = 4096};
    vxl_renderer *r = NULL;
    REQUIRE(vxl_renderer_create(&o, &r) == VXL_OK);
    double prm[4] = {0.1, 0, 0, 0};
    vxl_volume *v = make_volume_f32(16, 16, 16, field_ramp, prm); /* 16 KiB as float */
    REQUIRE(v);
    CHECK(vxl_renderer_set_volume(r, v) == VXL_ERR_LIMIT);
    CHECK(strstr(vxl_renderer_error(r), "budget") != NULL);
    vxl_volume_destroy(v);
    vxl_renderer_destroy(r);
    /* a zero-initialised options struct and NULL both mean defaults */
    r = NULL;
    CHECK(vxl_renderer_create(NULL, &r) == VXL_OK && r);
    vxl_renderer_info info;
    CHECK(vxl_renderer_get_info(r, &info) == VXL_OK && info.max_3d_texture_size >= 256);
    vxl_renderer_destroy(r);
}

TEST(backend_environment_override)
{
    setenv("VOXLIGHT_BACKEND", "bogus", 1);
    vxl_renderer *r = NULL;
    CHECK(vxl_renderer_create(NULL, &r) == VXL_ERR_INVALID_ARGUMENT && r == NULL);
    CHECK(strstr(vxl_last_error(), "VOXLIGHT_BACKEND") != NULL);
    uint32_t sw = software_backend();
    setenv("VOXLIGHT_BACKEND", sw == VXL_BACKEND_OSMESA ? "osmesa" : "egl", 1);
    CHECK(vxl_renderer_create(NULL, &r) == VXL_OK);
    vxl_renderer_info info = {.struct_size = sizeof info};
    CHECK(r && vxl_renderer_get_info(r, &info) == VXL_OK && info.backend == sw);
    vxl_renderer_destroy(r);
    unsetenv("VOXLIGHT_BACKEND");
}

/* auto takes a GPU through EGL, else OSMesa, else Mesa's surfaceless EGL: on
 * a machine without OSMesa it must still open (on EGL), and asking for
 * OSMesa there is a clear error naming the package. */
TEST(auto_uses_what_is_installed)
{
    vxl_renderer *r = make_renderer(VXL_BACKEND_AUTO);
    REQUIRE(r);
    vxl_renderer_info info = {.struct_size = sizeof info};
    CHECK(vxl_renderer_get_info(r, &info) == VXL_OK);
    fprintf(stderr, "    auto: %s\n", info.backend_name);
    if (osmesa_installed())
        CHECKF(!strcmp(info.backend_name, "osmesa") || !strcmp(info.backend_name, "egl-device"), "auto chose %s",
               info.backend_name);
    else
        CHECKF(info.backend == VXL_BACKEND_EGL, "auto chose %s without OSMesa", info.backend_name);
    vxl_renderer_destroy(r);
    r = make_renderer(VXL_BACKEND_OSMESA);
    if (osmesa_installed()) {
        CHECK(r != NULL);
    } else {
        CHECK(r == NULL);
        CHECKF(strstr(vxl_last_error(), "libosmesa6") != NULL, "error: %s", vxl_last_error());
    }
    vxl_renderer_destroy(r);
}

TEST(shader_dir_override_loads_from_disk)
{
    vxl_renderer_options o = {.struct_size = sizeof o, .backend = software_backend(), .shader_dir = "/nonexistent"};
    vxl_renderer *r = NULL;
    REQUIRE(vxl_renderer_create(&o, &r) == VXL_OK);
    double prm[4] = {0.1, 0, 0, 0};
    vxl_volume *v = make_volume_f32(8, 8, 8, field_ramp, prm);
    REQUIRE(v && vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_volume_destroy(v);
    static float img[16 * 16 * 4];
    vxl_render_params p = default_params(16, 16);
    CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_SHADER);
    CHECK(strstr(vxl_renderer_error(r), "not found") != NULL);
    vxl_renderer_destroy(r);
}

int main(void)
{
    RUN(abi_and_names);
    RUN(destroy_null_is_a_noop);
    RUN(volume_create_validates);
    RUN(nan_voxels_are_counted_and_neutralised);
    RUN(histogram_counts_data_values);
    RUN(scaling_and_int_types);
    RUN(renderer_errors_are_reported);
    RUN(renderer_budget_and_defaults);
    RUN(backend_environment_override);
    RUN(auto_uses_what_is_installed);
    RUN(shader_dir_override_loads_from_disk);
    return TEST_SUMMARY();
}
