/* test_api.c - the public API's contract: error codes and messages, limits,
 * defaults, NULL handling, backend selection, the names of the enumerations
 * and the struct_size promise for callers built against older headers. */
#include <stddef.h>
#include <stdio.h>
#include <unistd.h>

#include "harness.h"
#include "nifti_writer.h"
#include "test_util.h"
#include "voxlight_dev.h" /* the gradient probe, to check it honours struct_size too */

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
    vxl_renderer_info info = {.struct_size = sizeof info};
    CHECK(vxl_renderer_get_info(r, &info) == VXL_OK && info.max_3d_texture_size >= 256);
    vxl_renderer_destroy(r);
}

TEST(backend_environment_override)
{
    vxl_os_set_env("VOXLIGHT_BACKEND", "bogus");
    vxl_renderer *r = NULL;
    CHECK(vxl_renderer_create(NULL, &r) == VXL_ERR_INVALID_ARGUMENT && r == NULL);
    CHECK(strstr(vxl_last_error(), "VOXLIGHT_BACKEND") != NULL);
    uint32_t sw = software_backend();
    vxl_os_set_env("VOXLIGHT_BACKEND", vxl_backend_name(sw));
    CHECK(vxl_renderer_create(NULL, &r) == VXL_OK);
    vxl_renderer_info info = {.struct_size = sizeof info};
    CHECK(r && vxl_renderer_get_info(r, &info) == VXL_OK && info.backend == sw);
    vxl_renderer_destroy(r);
    vxl_os_set_env("VOXLIGHT_BACKEND", NULL);
}

/* auto takes a GPU through EGL, else OSMesa, else Mesa's surfaceless EGL: on
 * a machine without OSMesa it must still open (on EGL), and asking for
 * OSMesa there is a clear error naming the package. On Windows auto is WGL
 * and OSMesa is refused as a backend Windows does not have. */
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
        CHECKF(info.backend == software_backend(), "auto chose %s without OSMesa", info.backend_name);
    vxl_renderer_destroy(r);
    r = make_renderer(VXL_BACKEND_OSMESA);
    if (osmesa_installed()) {
        CHECK(r != NULL);
    } else {
        CHECK(r == NULL);
        const char *names = strcmp(vxl_os_name(), "windows") ? "libosmesa6" : "not one of Windows'";
        CHECKF(strstr(vxl_last_error(), names) != NULL, "error: %s", vxl_last_error());
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

typedef struct enum_names {
    const char *what;
    const char *(*name)(uint32_t);
    int (*from_name)(const char *, uint32_t *);
    uint32_t count;
} enum_names;

/* Every enumeration the CLI and the add-on list has its names in the
 * library: distinct, round-tripping (case-insensitively), NULL at *_COUNT,
 * and an unknown name is an error naming it. */
TEST(every_enumeration_has_names)
{
    static const enum_names all[] = {
        {"filter", vxl_filter_name, vxl_filter_from_name, VXL_FILTER_COUNT},
        {"preset", vxl_preset_name, vxl_preset_from_name, VXL_PRESET_COUNT},
        {"storage", vxl_storage_name, vxl_storage_from_name, VXL_STORAGE_COUNT},
        {"classify", vxl_classify_name, vxl_classify_from_name, VXL_CLASSIFY_COUNT},
        {"gradient opacity", vxl_gradient_opacity_name, vxl_gradient_opacity_from_name, VXL_GOPACITY_COUNT},
        {"gradient store", vxl_gradient_store_name, vxl_gradient_store_from_name, VXL_GRADIENT_STORE_COUNT},
        {"backend", vxl_backend_name, vxl_backend_from_name, VXL_BACKEND_COUNT},
        {"shading model", vxl_shading_model_name, vxl_shading_model_from_name, VXL_SHADING_COUNT},
        {"technique", vxl_technique_name, vxl_technique_from_name, VXL_TECHNIQUE_COUNT},
    };
    for (size_t e = 0; e < sizeof all / sizeof *all; e++) {
        const enum_names *E = &all[e];
        for (uint32_t i = 0; i < E->count; i++) {
            const char *n = E->name(i);
            CHECKF(n && *n, "%s %u has no name", E->what, i);
            if (!n) continue;
            char upper[64];
            size_t len = strlen(n);
            REQUIRE(len < sizeof upper);
            for (size_t c = 0; c <= len; c++) upper[c] = (char)(n[c] >= 'a' && n[c] <= 'z' ? n[c] - 32 : n[c]);
            uint32_t back = 999, back_upper = 999;
            CHECKF(E->from_name(n, &back) == VXL_OK && back == i, "%s '%s' -> %u", E->what, n, back);
            CHECKF(E->from_name(upper, &back_upper) == VXL_OK && back_upper == i, "%s '%s'", E->what, upper);
            for (uint32_t j = 0; j < i; j++) CHECKF(strcmp(E->name(j), n) != 0, "%s %u and %u share '%s'", E->what, j, i, n);
        }
        CHECKF(E->name(E->count) == NULL, "%s past the last value has a name", E->what);
        uint32_t v = 7;
        CHECK(E->from_name("no-such-name", &v) == VXL_ERR_INVALID_ARGUMENT && v == 7);
        CHECKF(strstr(vxl_last_error(), "no-such-name") != NULL, "%s: %s", E->what, vxl_last_error());
        CHECK(E->from_name(NULL, &v) == VXL_ERR_INVALID_ARGUMENT);
        CHECK(E->from_name(E->name(0), NULL) == VXL_ERR_INVALID_ARGUMENT);
    }
    /* the tables follow the header's numbers */
    uint32_t v;
    CHECK(vxl_classify_from_name("preint", &v) == VXL_OK && v == VXL_CLASSIFY_PREINT);
    CHECK(vxl_gradient_opacity_from_name("iso", &v) == VXL_OK && v == VXL_GOPACITY_ISO);
    CHECK(vxl_gradient_store_from_name("16f", &v) == VXL_OK && v == VXL_GRADIENT_STORE_16F);
    CHECK(vxl_backend_from_name("osmesa", &v) == VXL_OK && v == VXL_BACKEND_OSMESA);
    CHECK(vxl_storage_from_name("compressed", &v) == VXL_OK && v == VXL_STORAGE_COMPRESSED);
    CHECK(vxl_dtype_name(0) == NULL && vxl_dtype_name(VXL_DTYPE_COUNT) == NULL);
    CHECK(!strcmp(vxl_dtype_name(VXL_DTYPE_U8), "uint8") && !strcmp(vxl_dtype_name(VXL_DTYPE_I16), "int16") &&
          !strcmp(vxl_dtype_name(VXL_DTYPE_F64), "float64"));
}

/* ---- the struct_size promise: older, shorter structs ----
 * Each test gives a struct the size an older release had, inside a buffer
 * whose bytes past it hold values the library would refuse (or notice): a
 * library that read them fails. The same struct also goes in a heap block
 * of exactly the old size, where the ASan build reports any read past it. */

/* vxl_render_params before its reserved room grew: up to reserved[0]. */
/* the layout before the lighting and technique fields were taken from reserved[] */
#define OLD_RENDER_PARAMS_SIZE (offsetof(vxl_render_params, shading_model) + sizeof(uint32_t))

static vxl_render_params *heap_copy(const void *src, size_t size)
{
    void *p = malloc(size);
    if (p) memcpy(p, src, size);
    return p;
}

TEST(old_render_params_are_read_up_to_their_size)
{
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(r);
    double prm[4] = {0.5, 0.5, 0.5, 0.35};
    vxl_volume *v = make_volume_f32(16, 16, 16, field_ball, prm);
    REQUIRE(v && vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_volume_destroy(v);
    enum { W = 24, H = 20 };
    static float want[W * H * 4], got[W * H * 4];
    vxl_render_params p = default_params(W, H);
    p.azimuth_deg = 30;
    REQUIRE(vxl_render(r, &p, want, NULL) == VXL_OK);
    float view[16], proj[16], view_old[16], proj_old[16];
    REQUIRE(vxl_default_camera(r, &p, view, proj) == VXL_OK);
    const float point[3] = {7.5f, 7.0f, 8.0f};
    float grad[3], grad_old[3];
    REQUIRE(vxl_probe_gradients(r, &p, point, 1, grad) == VXL_OK);

    vxl_render_params old = p;
    old.struct_size = (uint32_t)OLD_RENDER_PARAMS_SIZE;
    /* whatever lies past the old caller's struct is not read */
    memset((char *)&old + OLD_RENDER_PARAMS_SIZE, 0xA5, sizeof old - OLD_RENDER_PARAMS_SIZE);
    CHECKF(vxl_render(r, &old, got, NULL) == VXL_OK, "%s", vxl_renderer_error(r));
    CHECK(memcmp(want, got, sizeof want) == 0);
    CHECK(vxl_default_camera(r, &old, view_old, proj_old) == VXL_OK);
    CHECK(!memcmp(view, view_old, sizeof view) && !memcmp(proj, proj_old, sizeof proj));
    CHECK(vxl_probe_gradients(r, &old, point, 1, grad_old) == VXL_OK && !memcmp(grad, grad_old, sizeof grad));
    /* today's struct with a reserved word set: refused */
    old = p;
    old.reserved[1] = 0xA5A5A5A5u;
    CHECK(vxl_render(r, &old, got, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(vxl_renderer_error(r), "reserved[1]") != NULL, "message: %s", vxl_renderer_error(r));
    CHECK(vxl_default_camera(r, &old, view_old, proj_old) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_probe_gradients(r, &old, point, 1, grad_old) == VXL_ERR_INVALID_ARGUMENT);

    vxl_render_params *heap = heap_copy(&p, OLD_RENDER_PARAMS_SIZE);
    REQUIRE(heap);
    heap->struct_size = (uint32_t)OLD_RENDER_PARAMS_SIZE;
    memset(got, 0, sizeof got);
    CHECK(vxl_render(r, heap, got, NULL) == VXL_OK && memcmp(want, got, sizeof want) == 0);
    CHECK(vxl_default_camera(r, heap, view_old, proj_old) == VXL_OK && !memcmp(view, view_old, sizeof view));
    CHECK(vxl_probe_gradients(r, heap, point, 1, grad_old) == VXL_OK && !memcmp(grad, grad_old, sizeof grad));
    free(heap);
    vxl_renderer_destroy(r);
}

/* vxl_renderer_options of ABI 1's first release ended at shader_dir. */
TEST(old_renderer_options_get_the_defaults)
{
    const size_t old_size = offsetof(vxl_renderer_options, storage);
    vxl_renderer_options o = {.struct_size = (uint32_t)old_size, .backend = software_backend(), .storage = 99};
    vxl_renderer *r = NULL;
    CHECKF(vxl_renderer_create(&o, &r) == VXL_OK, "%s", vxl_last_error());
    double prm[4] = {0.1, 0, 0, 0};
    vxl_volume *v = make_volume_f32(8, 8, 8, field_ramp, prm);
    REQUIRE(v);
    if (r) {
        CHECK(vxl_renderer_set_volume(r, v) == VXL_OK);
        static float img[8 * 8 * 4];
        vxl_render_params p = default_params(8, 8);
        CHECK(vxl_render(r, &p, img, NULL) == VXL_OK);
        vxl_render_stats st = {.struct_size = sizeof st};
        CHECK(vxl_renderer_get_stats(r, &st) == VXL_OK && st.storage == VXL_STORAGE_DENSE);
    }
    vxl_renderer_destroy(r);
    o.struct_size = sizeof o; /* today's size: the same storage value is refused */
    r = NULL;
    CHECK(vxl_renderer_create(&o, &r) == VXL_ERR_INVALID_ARGUMENT && r == NULL);
    vxl_renderer_options *heap = (vxl_renderer_options *)heap_copy(&o, old_size);
    REQUIRE(heap);
    heap->struct_size = (uint32_t)old_size;
    CHECK(vxl_renderer_create(heap, &r) == VXL_OK && r);
    free(heap);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
}

/* vxl_load_options of ABI 1's first release ended at memory_budget_bytes;
 * voxel_size, frame and series came later. */
TEST(old_load_options_get_the_defaults)
{
    char path[256];
    const char *dir = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/vxl_test_api_%d.nii", dir && *dir ? dir : "/tmp", (int)getpid());
    tnw_header h;
    tnw_init(&h, 1, 16, 4, 3, 2); /* float32 */
    float data[4 * 3 * 2];
    for (int i = 0; i < 24; i++) data[i] = (float)i;
    REQUIRE(tnw_write(path, &h, data, sizeof data) == 0);
    const size_t old_size = offsetof(vxl_load_options, voxel_size);
    vxl_load_options o = {.struct_size = (uint32_t)old_size, .frame = 5};
    vxl_volume *v = NULL;
    CHECKF(vxl_volume_load(path, &o, &v) == VXL_OK, "%s", vxl_last_error());
    vxl_volume_info info = {.struct_size = sizeof info};
    CHECK(v && vxl_volume_get_info(v, &info) == VXL_OK && info.frame == 0 && info.frame_count == 1);
    vxl_volume_destroy(v);
    v = NULL;
    o.struct_size = sizeof o; /* today's size: frame 5 of a 3D file is an error */
    CHECK(vxl_volume_load(path, &o, &v) != VXL_OK && v == NULL);
    vxl_load_options *heap = (vxl_load_options *)heap_copy(&o, old_size);
    REQUIRE(heap);
    heap->struct_size = (uint32_t)old_size;
    CHECK(vxl_volume_load(path, heap, &v) == VXL_OK && v);
    free(heap);
    vxl_volume_destroy(v);
    remove(path);
}

/* Output structs: an older caller's shorter struct is written only up to
 * its struct_size; the bytes after it keep the caller's sentinel. */
TEST(old_output_structs_are_written_up_to_their_size)
{
    double prm[4] = {0.1, 0, 0, 0};
    vxl_volume *v = make_volume_f32(8, 8, 8, field_ramp, prm);
    REQUIRE(v);
    vxl_volume_info vi;
    memset(&vi, 0xEE, sizeof vi);
    vi.struct_size = (uint32_t)offsetof(vxl_volume_info, frame_count); /* before 4D inputs */
    CHECK(vxl_volume_get_info(v, &vi) == VXL_OK && vi.dims[0] == 8 && vi.frame_count == 0xEEEEEEEEu);

    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(r);
    CHECK(vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_volume_destroy(v);
    vxl_renderer_info ri;
    memset(&ri, 0xEE, sizeof ri);
    ri.struct_size = (uint32_t)offsetof(vxl_renderer_info, gl_renderer);
    CHECK(vxl_renderer_get_info(r, &ri) == VXL_OK && ri.backend_name[0] != (char)0xEE);
    CHECK(ri.struct_size == offsetof(vxl_renderer_info, gl_renderer) && (unsigned char)ri.gl_renderer[0] == 0xEE &&
          (unsigned char)ri.gl_version[127] == 0xEE);
    static float img[8 * 8 * 4];
    vxl_render_params p = default_params(8, 8);
    CHECK(vxl_render(r, &p, img, NULL) == VXL_OK);
    vxl_render_stats st;
    memset(&st, 0xEE, sizeof st);
    st.struct_size = (uint32_t)offsetof(vxl_render_stats, storage); /* a struct from before the storage fields */
    CHECK(vxl_renderer_get_stats(r, &st) == VXL_OK && st.rays > 0 && st.storage == 0xEEEEEEEEu);
    vxl_renderer_destroy(r);
}

/* A reader's notes (vxl_volume_add_note stands in for one) reach
 * vxl_volume_info.notes: "; "-joined, one line, the first kept and "..."
 * when full, and only for a caller whose struct covers all of notes. */
TEST(notes_reach_the_volume_info)
{
    double prm[4] = {0.1, 0, 0, 0};
    vxl_volume *v = make_volume_f32(4, 4, 4, field_ramp, prm);
    REQUIRE(v);
    vxl_volume_info in = {.struct_size = sizeof in};
    CHECK(vxl_volume_get_info(v, &in) == VXL_OK && in.notes[0] == '\0');
    CHECK(vxl_volume_add_note(v, "PixelSpacing missing: 1 mm assumed") == VXL_OK);
    CHECK(vxl_volume_add_note(v, "2 slices interpolated\nwhere slices are missing") == VXL_OK);
    CHECK(vxl_volume_get_info(v, &in) == VXL_OK);
    CHECKF(!strcmp(in.notes, "PixelSpacing missing: 1 mm assumed; 2 slices interpolated where slices are missing"),
           "%s", in.notes);
    CHECK(vxl_volume_add_note(NULL, "x") == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_volume_add_note(v, NULL) == VXL_ERR_INVALID_ARGUMENT);

    /* an older caller's struct, and one that ends inside notes: notes untouched */
    const uint32_t notes_at = (uint32_t)offsetof(vxl_volume_info, notes);
    const uint32_t sizes[2] = {notes_at, notes_at + 10};
    for (int i = 0; i < 2; i++) {
        vxl_volume_info old;
        memset(&old, 0xEE, sizeof old);
        old.struct_size = sizes[i];
        CHECK(vxl_volume_get_info(v, &old) == VXL_OK && old.dims[0] == 4 && old.bytes_read == 0);
        CHECK(old.struct_size == notes_at && (unsigned char)old.notes[0] == 0xEE &&
              (unsigned char)old.notes[VXL_NOTES_MAX - 1] == 0xEE);
    }

    /* too many notes: the first survive, the last are cut to "..." */
    char long_note[101];
    memset(long_note, 'n', 100);
    long_note[100] = '\0';
    for (int i = 0; i < 8; i++) CHECK(vxl_volume_add_note(v, long_note) == VXL_OK);
    CHECK(vxl_volume_get_info(v, &in) == VXL_OK);
    size_t len = strnlen(in.notes, sizeof in.notes);
    CHECKF(len == VXL_NOTES_MAX - 1 && !strcmp(in.notes + len - 3, "...") &&
           !strncmp(in.notes, "PixelSpacing missing", 20), "%zu: %s", len, in.notes);
    vxl_volume_destroy(v);

    /* notes filled exactly: the next note is lost, and the notes say so */
    v = make_volume_f32(4, 4, 4, field_ramp, prm);
    REQUIRE(v);
    char full[VXL_NOTES_MAX - 1];
    memset(full, 'f', sizeof full - 1);
    full[sizeof full - 1] = '\0';
    CHECK(vxl_volume_add_note(v, full) == VXL_OK && vxl_volume_get_info(v, &in) == VXL_OK && !strcmp(in.notes, full));
    CHECK(vxl_volume_add_note(v, "lost") == VXL_OK && vxl_volume_get_info(v, &in) == VXL_OK);
    len = strlen(in.notes);
    CHECKF(len == sizeof full - 1 && !strcmp(in.notes + len - 3, "...") && in.notes[0] == 'f', "%s", in.notes);
    vxl_volume_destroy(v);
}

int main(void)
{
    RUN(abi_and_names);
    RUN(every_enumeration_has_names);
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
    RUN(old_render_params_are_read_up_to_their_size);
    RUN(old_renderer_options_get_the_defaults);
    RUN(old_load_options_get_the_defaults);
    RUN(old_output_structs_are_written_up_to_their_size);
    RUN(notes_reach_the_volume_info);
    return TEST_SUMMARY();
}
