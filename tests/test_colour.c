/* test_colour.c - colour volumes (docs/colour.md; csrc/volume/colour_volume.c,
 * csrc/colour/colour.c, shaders/lib/colour.glsl): a cube whose x faces are
 * pure red, y faces pure green and z faces pure blue, seen along each axis
 * through an orthographic view whose pixels are one voxel wide, renders
 * exactly that colour at the centre (the other two channels exactly 0: no
 * luminance mixing) in every storage mode, classification and render mode;
 * colour source tf renders bit for bit what the luminance alone renders;
 * NIfTI RGB24, RGBA32 and vector files and an RGB NRRD load as colour with
 * their notes; the
 * opacity source picks the scalar; the colour is charged to the budget. */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <unistd.h>

#include "axis_view.h"
#include "harness.h"
#include "nifti_writer.h"
#include "test_util.h"
#include "voxlight_dev.h" /* vxl_volume_stream_copy */

#define N 16
#define TF_N 2

static char g_dir[64];
static uint8_t CUBE[N * N * N * 4]; /* RGBA: the faces' colours, alpha a ramp along x */
static const float TF[TF_N * 4] = {1, 1, 1, 0, 1, 1, 1, 1};

static const char *tmp(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
    return buf;
}

static void remove_tmp_dir(void)
{
    DIR *d = opendir(g_dir);
    struct dirent *e;
    char p[512];
    while (d && (e = readdir(d)))
        if (e->d_name[0] != '.') unlink(tmp(p, sizeof p, e->d_name));
    if (d) closedir(d);
    rmdir(g_dir);
}

static void fill_cube(void)
{
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) {
                uint8_t *c = CUBE + 4 * (x + N * (y + N * z));
                c[0] = c[1] = c[2] = 0;
                if (x == 0 || x == N - 1) c[0] = 255;
                else if (y == 0 || y == N - 1) c[1] = 255;
                else if (z == 0 || z == N - 1) c[2] = 255;
                c[3] = (uint8_t)(16 * x);
            }
}

/* The cube as RGB (components 3) or RGBA (4) with the given load options. */
static vxl_volume *cube_volume(uint32_t components, const vxl_load_options *lo)
{
    static uint8_t rgb[N * N * N * 4];
    for (int i = 0; i < N * N * N; i++)
        for (uint32_t c = 0; c < components; c++) rgb[components * i + c] = CUBE[4 * i + c];
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U8, .dims = {N, N, N}, .data = rgb,
                         .components = components};
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, lo, &v) == VXL_OK ? v : NULL;
}

/* The luminance the library takes as the scalar, as a grey volume. */
static vxl_volume *luminance_volume(void)
{
    static uint8_t lum[N * N * N];
    for (int i = 0; i < N * N * N; i++) {
        double y = 0.2126 * CUBE[4 * i] + 0.7152 * CUBE[4 * i + 1] + 0.0722 * CUBE[4 * i + 2];
        lum[i] = (uint8_t)floor(y + 0.5);
    }
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U8, .dims = {N, N, N}, .data = lum};
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, NULL, &v) == VXL_OK ? v : NULL;
}

/* View `view` (axis_view.h) of an N^3 unit-spacing volume, N x N pixels;
 * opacity 1 from luminance 10 up, emission only. */
static vxl_render_params axis_params(int view)
{
    vxl_render_params p;
    memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.width = p.height = N;
    p.has_camera = 1;
    const double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {N - 0.5, N - 0.5, N - 0.5};
    vxl_axis_view_camera(view, 1, lo, hi, N, N, p.view, p.proj);
    p.jitter_off = 1;
    p.shading_off = 1;
    p.tf_rgba = TF;
    p.tf_size = TF_N;
    p.has_window = 1;
    p.window_low = 0;
    p.window_high = 10;
    return p;
}

static float IMG[N * N * 4], REF[N * N * 4];

static int render(vxl_renderer *r, const vxl_volume *v, const vxl_render_params *p, float *img)
{
    int rc = vxl_renderer_set_volume(r, v);
    if (rc == VXL_OK) rc = vxl_render(r, p, img, NULL);
    if (rc != VXL_OK) fprintf(stderr, "    render: %s: %s\n", vxl_error_name(rc), vxl_renderer_error(r));
    return rc;
}

/* The centre pixel of a view along axis a (0 x, 1 y, 2 z) shows channel a
 * alone: above 0 in it (how bright depends on the mode: an average over
 * the black inside is dark), exactly 0 in the other two. */
static int centre_is_pure(const float *img, int axis)
{
    const float *px = img + 4 * ((N / 2) * N + N / 2);
    int ok = px[axis] > 0.01f && px[3] > 0.01f;
    for (int c = 0; c < 3; c++)
        if (c != axis && px[c] != 0.0f) ok = 0;
    if (!ok) fprintf(stderr, "    centre pixel (%g, %g, %g, %g), axis %d\n", px[0], px[1], px[2], px[3], axis);
    return ok;
}

TEST(faces_render_their_own_colour_in_every_storage_mode)
{
    vxl_volume *v = cube_volume(3, NULL);
    REQUIRE(v);
    vxl_volume *streamed = NULL;
    REQUIRE(vxl_volume_stream_copy(v, 1, &streamed) == VXL_OK);
    const uint32_t storages[] = {VXL_STORAGE_DENSE, VXL_STORAGE_BRICKED, VXL_STORAGE_SPARSE, VXL_STORAGE_COMPRESSED};
    static float dense[3][N * N * 4];
    for (int s = 0; s <= 4; s++) {
        vxl_renderer *r = make_stored_renderer(s < 4 ? storages[s] : VXL_STORAGE_AUTO, 8, 0, 0);
        REQUIRE(r);
        for (int axis = 0; axis < 3; axis++) {
            vxl_render_params p = axis_params(2 * axis);
            CHECK(render(r, s < 4 ? v : streamed, &p, IMG) == VXL_OK);
            CHECKF(centre_is_pure(IMG, axis), "storage %s", s < 4 ? vxl_storage_name(storages[s]) : "streamed");
            CHECK(image_is_sane(IMG, NULL, N * N));
            if (s == 0) memcpy(dense[axis], IMG, sizeof IMG);
            /* the colour texture is the same in every mode; the scalar's bricks hold it exactly */
            double diff = 0;
            for (int i = 0; i < N * N * 4; i++) diff = fmax(diff, fabs(IMG[i] - dense[axis][i]));
            CHECKF(diff <= 1e-5, "storage %d axis %d differs from dense by %g", s, axis, diff);
        }
        vxl_renderer_destroy(r);
    }
    vxl_volume_destroy(streamed);
    vxl_volume_destroy(v);
}

TEST(classification_and_render_modes_keep_the_colour)
{
    vxl_volume *v = cube_volume(3, NULL);
    REQUIRE(v);
    vxl_renderer *r = make_stored_renderer(VXL_STORAGE_DENSE, 0, 0, 0);
    REQUIRE(r);
    for (int axis = 0; axis < 3; axis++) {
        for (uint32_t cl = 0; cl < VXL_CLASSIFY_COUNT; cl++) {
            vxl_render_params p = axis_params(2 * axis);
            p.classify = cl;
            CHECK(render(r, v, &p, IMG) == VXL_OK);
            CHECKF(centre_is_pure(IMG, axis), "classify %s", vxl_classify_name(cl));
        }
        const uint32_t modes[] = {VXL_MODE_MIP, VXL_MODE_AVERAGE, VXL_MODE_ISO};
        for (int m = 0; m < 3; m++) {
            vxl_render_params p = axis_params(2 * axis);
            p.mode = modes[m];
            p.iso_value = 10;
            CHECK(render(r, v, &p, IMG) == VXL_OK);
            CHECKF(centre_is_pure(IMG, axis), "mode %s", vxl_mode_name(modes[m]));
        }
        /* lit without a specular highlight (which adds white): still one channel */
        vxl_render_params p = axis_params(2 * axis);
        p.shading_off = 0;
        p.has_material = 1;
        p.ambient = 0.3f;
        p.diffuse = 0.7f;
        p.specular = 0;
        p.shininess = 10;
        for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++) {
            p.filter = f;
            CHECK(render(r, v, &p, IMG) == VXL_OK);
            CHECKF(centre_is_pure(IMG, axis), "shaded, filter %s", vxl_filter_name(f));
        }
        p.filter = 0;
        p.shading_model = VXL_SHADING_SHADOWED;
        CHECK(render(r, v, &p, IMG) == VXL_OK);
        CHECKF(centre_is_pure(IMG, axis), "shadowed");
        /* the slicing comparison modes sample the same colour */
        vxl_render_params q = axis_params(2 * axis);
        q.technique = VXL_TECHNIQUE_SLICES3D;
        CHECK(render(r, v, &q, IMG) == VXL_OK);
        CHECKF(centre_is_pure(IMG, axis), "slices3d");
    }
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
}

TEST(colour_source_tf_renders_what_the_luminance_renders)
{
    vxl_volume *v = cube_volume(3, NULL), *lum = luminance_volume();
    REQUIRE(v && lum);
    vxl_renderer *r = make_stored_renderer(VXL_STORAGE_DENSE, 0, 0, 0);
    REQUIRE(r);
    for (int shaded = 0; shaded < 2; shaded++) {
        vxl_render_params p = axis_params(0);
        p.shading_off = (uint32_t)!shaded;
        p.azimuth_deg = 0;
        CHECK(render(r, lum, &p, REF) == VXL_OK); /* today's grey volume, every default */
        p.color_source = VXL_COLOR_SOURCE_TF;
        CHECK(render(r, v, &p, IMG) == VXL_OK);
        CHECKF(!memcmp(IMG, REF, sizeof IMG), "shaded %d: tf colour differs from the luminance's render", shaded);
        /* auto is the data's colour for a colour volume, and today's for a grey one */
        p.color_source = VXL_COLOR_SOURCE_AUTO;
        CHECK(render(r, v, &p, IMG) == VXL_OK);
        CHECK(memcmp(IMG, REF, sizeof IMG) != 0);
        float data[N * N * 4];
        p.color_source = VXL_COLOR_SOURCE_DATA;
        CHECK(render(r, v, &p, data) == VXL_OK);
        CHECK(!memcmp(IMG, data, sizeof IMG));
        p.color_source = VXL_COLOR_SOURCE_AUTO;
        CHECK(render(r, lum, &p, IMG) == VXL_OK);
        CHECK(!memcmp(IMG, REF, sizeof IMG));
    }
    /* the data's colour of a grey volume is a state error naming it; bad values are refused */
    vxl_render_params p = axis_params(0);
    p.color_source = VXL_COLOR_SOURCE_DATA;
    CHECK(render(r, lum, &p, IMG) == VXL_ERR_STATE);
    CHECK(strstr(vxl_renderer_error(r), "color_source data") != NULL);
    p.color_source = VXL_COLOR_SOURCE_COUNT;
    CHECK(vxl_render(r, &p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT);
    p.color_source = 0;
    p.color_space = VXL_COLOR_SPACE_COUNT;
    CHECK(vxl_render(r, &p, IMG, NULL) == VXL_ERR_INVALID_ARGUMENT);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
    vxl_volume_destroy(lum);
}

/* A colour volume's RGB is display-referred: in scene-linear colour the
 * image is its decoded value (emission only, the first voxel opaque); a lit
 * image is not clamped to 1 there, and is in display colour. */
TEST(linear_colour_space_decodes_the_data_colour_and_keeps_light_above_one)
{
    static uint8_t rgb[N * N * N * 3];
    const uint8_t c8[3] = {200, 90, 30};
    for (int i = 0; i < N * N * N; i++) memcpy(rgb + 3 * i, c8, 3);
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U8, .dims = {N, N, N}, .data = rgb,
                         .components = 3};
    vxl_volume *v = NULL;
    REQUIRE(vxl_volume_create(&d, NULL, &v) == VXL_OK);
    vxl_renderer *r = make_stored_renderer(VXL_STORAGE_DENSE, 0, 0, 0);
    REQUIRE(r);
    vxl_render_params p = axis_params(0);
    REQUIRE(render(r, v, &p, IMG) == VXL_OK);
    p.color_space = VXL_COLOR_SPACE_LINEAR;
    REQUIRE(render(r, v, &p, REF) == VXL_OK);
    const float *disp = IMG + 4 * ((N / 2) * N + N / 2), *lin = REF + 4 * ((N / 2) * N + N / 2);
    for (int c = 0; c < 3; c++) {
        double s = c8[c] / 255.0, want = s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4);
        CHECKF(fabs(disp[c] - s) <= 2e-3, "display channel %d: %g, want %g", c, disp[c], s);
        CHECKF(fabs(lin[c] - want) <= 2e-3, "linear channel %d: %g, want %g", c, lin[c], want);
    }
    CHECK(fabs(disp[3] - 1) <= 1e-4 && fabs(lin[3] - 1) <= 1e-4);
    /* a light ten times white on the cube's faces: lit colour above 1 in
     * linear, clamped in display */
    vxl_volume_destroy(v);
    v = cube_volume(3, NULL);
    REQUIRE(v);
    p.color_space = VXL_COLOR_SPACE_LINEAR;
    p.shading_off = 0;
    p.light_count = 2; /* along the view axis, one of them facing the camera */
    p.lights[0] = (vxl_light){.position = {1, 0, 0, 0}, .color = {1, 1, 1}, .intensity = 10};
    p.lights[1] = (vxl_light){.position = {-1, 0, 0, 0}, .color = {1, 1, 1}, .intensity = 10};
    REQUIRE(render(r, v, &p, REF) == VXL_OK);
    p.color_space = VXL_COLOR_SPACE_DISPLAY;
    REQUIRE(render(r, v, &p, IMG) == VXL_OK);
    float max_lin = 0, max_disp = 0;
    for (int i = 0; i < N * N; i++) {
        for (int c = 0; c < 3; c++) {
            max_lin = fmaxf(max_lin, REF[4 * i + c]);
            max_disp = fmaxf(max_disp, IMG[4 * i + c]);
        }
        CHECK(REF[4 * i + 3] <= 1.0f && isfinite(REF[4 * i]));
    }
    CHECKF(max_lin > 1.5f && max_disp <= 1.0f, "brightest: %g linear, %g display", max_lin, max_disp);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
}

TEST(opacity_source_picks_the_scalar)
{
    vxl_volume_info in = {.struct_size = sizeof in};
    vxl_volume *v = cube_volume(4, NULL);
    REQUIRE(v);
    vxl_volume_get_info(v, &in);
    CHECK(in.components == 4 && in.opacity_source == VXL_OPACITY_SOURCE_LUMINANCE);
    CHECK(in.color_bytes == 3ull * N * N * N);
    CHECK(in.value_min == 0 && in.value_max == 182); /* round(0.7152 * 255): green */
    CHECK(strstr(in.notes, "luminance") && strstr(in.notes, "alpha not used"));
    vxl_volume_destroy(v);

    vxl_load_options lo = {.struct_size = sizeof lo, .opacity_source = VXL_OPACITY_SOURCE_ALPHA};
    v = cube_volume(4, &lo);
    REQUIRE(v);
    vxl_volume_get_info(v, &in);
    CHECK(in.opacity_source == VXL_OPACITY_SOURCE_ALPHA && in.value_min == 0 && in.value_max == 16 * (N - 1));
    CHECK(strstr(in.notes, "alpha channel") != NULL);
    vxl_volume_destroy(v);

    lo.opacity_source = VXL_OPACITY_SOURCE_CHANNEL;
    lo.opacity_channel = 2;
    v = cube_volume(3, &lo);
    REQUIRE(v);
    vxl_volume_get_info(v, &in);
    CHECK(in.components == 3 && in.value_max == 255 && strstr(in.notes, "blue channel"));
    vxl_volume_destroy(v);

    /* refused: alpha of RGB, a channel past the last, an unknown source, 2 components */
    v = NULL;
    lo.opacity_source = VXL_OPACITY_SOURCE_ALPHA;
    CHECK(cube_volume(3, &lo) == NULL && strstr(vxl_last_error(), "alpha"));
    lo.opacity_source = VXL_OPACITY_SOURCE_CHANNEL;
    lo.opacity_channel = 3;
    CHECK(cube_volume(3, &lo) == NULL && strstr(vxl_last_error(), "channel"));
    lo.opacity_source = 7;
    CHECK(cube_volume(3, &lo) == NULL && strstr(vxl_last_error(), "opacity source"));
    CHECK(cube_volume(2, NULL) == NULL && strstr(vxl_last_error(), "components"));

    /* grey volumes: one component, no colour */
    vxl_volume *lum = luminance_volume();
    REQUIRE(lum);
    vxl_volume_get_info(lum, &in);
    CHECK(in.components == 1 && in.color_bytes == 0 && in.opacity_source == 0);
    vxl_volume_destroy(lum);
}

TEST(slice_planes_show_the_data_colour)
{
    vxl_volume *v = cube_volume(3, NULL);
    REQUIRE(v);
    vxl_renderer *r = make_stored_renderer(VXL_STORAGE_DENSE, 0, 0, 0);
    REQUIRE(r);
    CHECK(vxl_renderer_set_volume(r, v) == VXL_OK);
    /* the plane z = 0 (the bottom face): x edges red, y edges green, blue inside; pixel i at voxel i */
    vxl_slice_params s = {.struct_size = sizeof s, .interpolation = VXL_INTERP_NEAREST};
    s.plane_to_world[0] = s.plane_to_world[5] = N / 2.0f;
    s.plane_to_world[10] = s.plane_to_world[15] = 1;
    s.plane_to_world[12] = s.plane_to_world[13] = (N - 1) / 2.0f;
    vxl_render_params p = axis_params(4);
    for (uint32_t interp = 0; interp < VXL_INTERP_COUNT; interp++) {
        s.interpolation = interp;
        CHECK(vxl_render_slice(r, &p, &s, IMG) == VXL_OK);
        const float *mid = IMG + 4 * (N / 2 * N + N / 2), *edge = IMG + 4 * (N / 2 * N);
        CHECKF(mid[0] == 0 && mid[1] == 0 && mid[2] == 1 && mid[3] == 1, "%s: centre (%g, %g, %g, %g)",
               vxl_interpolation_name(interp), mid[0], mid[1], mid[2], mid[3]);
        CHECKF(edge[0] > 0 && edge[1] == 0 && edge[2] == 0, "%s: x edge (%g, %g, %g)", vxl_interpolation_name(interp),
               edge[0], edge[1], edge[2]);
    }
    /* the table's colour of the luminance with colour source tf: grey */
    p.color_source = VXL_COLOR_SOURCE_TF;
    s.interpolation = VXL_INTERP_NEAREST;
    CHECK(vxl_render_slice(r, &p, &s, IMG) == VXL_OK);
    const float *mid = IMG + 4 * (N / 2 * N + N / 2);
    CHECKF(mid[0] == mid[1] && mid[1] == mid[2] && mid[0] > 0, "tf: (%g, %g, %g, %g)", mid[0], mid[1], mid[2], mid[3]);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
}

TEST(colour_is_charged_to_the_budget)
{
    vxl_volume *v = cube_volume(3, NULL), *lum = luminance_volume();
    REQUIRE(v && lum);
    /* room for the scalar (4 KiB) but not for it and its colour (16 KiB) */
    vxl_renderer *r = make_stored_renderer(VXL_STORAGE_DENSE, 0, 10000, 0);
    REQUIRE(r);
    vxl_render_params p = axis_params(0);
    CHECK(render(r, lum, &p, REF) == VXL_OK);
    CHECK(vxl_renderer_set_volume(r, v) == VXL_ERR_LIMIT);
    CHECK(strstr(vxl_renderer_error(r), "colour") != NULL);
    /* the refused volume took nothing away */
    CHECK(vxl_render(r, &p, IMG, NULL) == VXL_OK && !memcmp(IMG, REF, sizeof IMG));
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
    vxl_volume_destroy(lum);
}

/* The cube written as a NIfTI file of the given kind: 0 RGB24, 1 RGBA32
 * (NIfTI-2), 2 float32 vector (dim[0] 5, dim[5] 3, planar, intent vector). */
static int write_cube_nifti(const char *path, int kind)
{
    tnw_header h;
    static float planes[3 * N * N * N];
    static uint8_t bytes[4 * N * N * N];
    if (kind == 2) {
        tnw_init(&h, 1, 16, N, N, N);
        h.dim[0] = 5;
        h.dim[5] = 3;
        h.patch_at = 68; /* intent_code: NIFTI_INTENT_VECTOR (1007), little-endian */
        h.patch_len = 2;
        h.patch[0] = 1007 & 0xff;
        h.patch[1] = 1007 >> 8;
        for (int c = 0; c < 3; c++)
            for (int i = 0; i < N * N * N; i++) planes[c * N * N * N + i] = CUBE[4 * i + c] / 255.0f;
        return tnw_write(path, &h, planes, sizeof planes);
    }
    const int comp = kind ? 4 : 3;
    tnw_init(&h, kind ? 2 : 1, kind ? 2304 : 128, N, N, N);
    h.bitpix = 8 * comp;
    for (int i = 0; i < N * N * N; i++)
        for (int c = 0; c < comp; c++) bytes[comp * i + c] = CUBE[4 * i + c];
    return tnw_write(path, &h, bytes, (size_t)comp * N * N * N);
}

TEST(nifti_and_nrrd_colour_files_load_as_colour_with_a_note)
{
    char path[256];
    vxl_renderer *r = make_stored_renderer(VXL_STORAGE_DENSE, 0, 0, 0);
    REQUIRE(r);
    vxl_volume *mem = cube_volume(3, NULL);
    REQUIRE(mem);
    vxl_render_params p = axis_params(0);
    CHECK(render(r, mem, &p, REF) == VXL_OK);
    static const char *const names[3] = {"rgb24.nii", "rgba32.nii.gz", "vector.nii"};
    static const char *const notes[3] = {"NIfTI RGB24: colour from the data, opacity and gradients from luminance",
                                         "NIfTI RGBA32: colour from the data", "NIfTI RGB vector: colour from the data"};
    for (int kind = 0; kind < 3; kind++) {
        REQUIRE(write_cube_nifti(tmp(path, sizeof path, names[kind]), kind) == 0);
        vxl_volume *v = NULL;
        vxl_load_options lo = {.struct_size = sizeof lo};
        CHECKF(vxl_volume_load(path, &lo, &v) == VXL_OK, "%s: %s", names[kind], vxl_last_error());
        if (!v) continue;
        vxl_volume_info in = {.struct_size = sizeof in};
        vxl_volume_get_info(v, &in);
        CHECKF(in.components == (kind == 1 ? 4u : 3u), "%s: components %u", names[kind], in.components);
        CHECKF(strstr(in.notes, notes[kind]) != NULL, "%s: notes '%s'", names[kind], in.notes);
        CHECK(in.dims[0] == N && in.dims[1] == N && in.dims[2] == N && in.frame_count == 1);
        if (kind == 2) CHECK(strstr(in.notes, "windowed over the data's range [0, 1]") != NULL);
        CHECK(render(r, v, &p, IMG) == VXL_OK);
        CHECKF(centre_is_pure(IMG, 0), "%s", names[kind]);
        /* the 8-bit files are the same voxels as the volume made in memory */
        if (kind < 2) CHECKF(!memcmp(IMG, REF, sizeof IMG), "%s renders differently from the same voxels in memory", names[kind]);
        vxl_volume_destroy(v);
    }
    /* NRRD: the fastest axis RGB-color, the same voxels */
    {
        static uint8_t body[3 * N * N * N];
        for (int i = 0; i < N * N * N; i++)
            for (int c = 0; c < 3; c++) body[3 * i + c] = CUBE[4 * i + c];
        char hdr[256];
        int n = snprintf(hdr, sizeof hdr, "NRRD0004\ntype: uint8\ndimension: 4\nsizes: 3 %d %d %d\n"
                                          "kinds: RGB-color domain domain domain\nencoding: raw\n\n", N, N, N);
        FILE *f = fopen(tmp(path, sizeof path, "rgb.nrrd"), "wb");
        REQUIRE(f);
        CHECK(fwrite(hdr, 1, (size_t)n, f) == (size_t)n && fwrite(body, 1, sizeof body, f) == sizeof body);
        fclose(f);
        vxl_volume *v = NULL;
        CHECKF(vxl_volume_load(path, NULL, &v) == VXL_OK, "rgb.nrrd: %s", vxl_last_error());
        if (v) {
            vxl_volume_info in = {.struct_size = sizeof in};
            vxl_volume_get_info(v, &in);
            CHECK(in.components == 3 && strstr(in.notes, "NRRD RGB: colour from the data"));
            CHECK(render(r, v, &p, IMG) == VXL_OK && !memcmp(IMG, REF, sizeof IMG));
            vxl_volume_destroy(v);
        }
    }
    /* streaming on: still read whole, and the note says so */
    vxl_load_options on = {.struct_size = sizeof on, .streaming = VXL_STREAMING_ON};
    vxl_volume *v = NULL;
    CHECK(vxl_volume_load(tmp(path, sizeof path, names[0]), &on, &v) == VXL_OK);
    if (v) {
        vxl_volume_info in = {.struct_size = sizeof in};
        vxl_volume_get_info(v, &in);
        CHECK(!in.streamed && strstr(in.notes, "does not stream"));
        vxl_volume_destroy(v);
    }
    /* over the load budget: refused naming colour and streaming */
    vxl_load_options small = {.struct_size = sizeof small, .memory_budget_bytes = 8192};
    CHECK(vxl_volume_load(path, &small, &v) == VXL_ERR_LIMIT && strstr(vxl_last_error(), "colour volumes are read whole"));
    vxl_volume_destroy(mem);
    vxl_renderer_destroy(r);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_test_colour_XXXXXX");
    if (!mkdtemp(g_dir)) {
        fprintf(stderr, "mkdtemp: %s\n", strerror(errno));
        return 1;
    }
    fill_cube();
    RUN(faces_render_their_own_colour_in_every_storage_mode);
    RUN(classification_and_render_modes_keep_the_colour);
    RUN(colour_source_tf_renders_what_the_luminance_renders);
    RUN(linear_colour_space_decodes_the_data_colour_and_keeps_light_above_one);
    RUN(opacity_source_picks_the_scalar);
    RUN(slice_planes_show_the_data_colour);
    RUN(colour_is_charged_to_the_budget);
    RUN(nifti_and_nrrd_colour_files_load_as_colour_with_a_note);
    remove_tmp_dir();
    return TEST_SUMMARY();
}
