/* test_colour_readers.c - one RGB pattern written by four independent
 * writers, read by four readers, renders one image (docs/colour.md,
 * "Loaders"): an RGB24 NIfTI (tests/nifti_writer.h, read in process), an
 * RGB multi-page TIFF (tests/fuzz/writers.h, read by the OpenImageIO
 * helper), an RGB DICOM series (pydicom, tests/make_colour_dicom.py, read by
 * the dcmtk helper) and a 3-channel MetaImage (written here, read in
 * process). Each file places voxel (i, j, k) at world (i, j, k), so the
 * four volumes must be the same colour volume (scalar, colour, affine) and
 * the same image bit for bit, from an oblique camera and along an axis. An
 * RGBA MetaImage keeps its alpha for the opacity source. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "axis_view.h"
#include "dicom_test_util.h" /* load_dicom_with: dcmtk and our own parser */
#include "fuzz/writers.h"
#include "harness.h"
#include "loader_test_util.h" /* remove_tree, voxel */
#include "nifti_writer.h"
#include "test_util.h"
#include "volume.h"

/* Small on purpose: the DICOM series is one file a slice, and a Mesa
 * shader compile is the cost of a frame. */
enum { NX = 8, NY = 6, NZ = 5, W = 24, H = 24, F = 5 /* inputs */ };

static char g_dir[64];

static int big_endian_host(void)
{
    const uint16_t one = 1;
    return *(const uint8_t *)&one == 0;
}
static uint8_t RGB[NX * NY * NZ * 3]; /* x fastest, then y, then z */
static const float TF[2 * 4] = {1, 1, 1, 0, 1, 1, 1, 1};

static const char *tmp(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
    return buf;
}

/* A pattern where every channel varies along every axis (so a mirrored or
 * transposed read shows), with an empty border for the opacity. */
static void fill_pattern(void)
{
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++) {
                uint8_t *c = RGB + 3 * (i + NX * (j + NY * k));
                const int inside = i > 0 && j > 0 && i < NX - 1 && j < NY - 1;
                c[0] = (uint8_t)(inside ? 30 * i + 5 * k : 0);
                c[1] = (uint8_t)(inside ? 40 * j + 3 * i : 0);
                c[2] = (uint8_t)(inside ? 200 - 35 * k + j : 0);
            }
}

static int write_nifti(const char *path)
{
    tnw_header h;
    tnw_init(&h, 1, 128, NX, NY, NZ); /* RGB24, unit spacing, no transform: voxel = world */
    h.bitpix = 24;
    return tnw_write(path, &h, RGB, sizeof RGB);
}

/* The TIFF's pages are slices; its rows run top first while voxel j runs up
 * (image_stack.cpp), so row y of a page is voxel row NY-1-y. */
static int write_tiff(const char *path)
{
    static uint8_t pages[sizeof RGB];
    for (int k = 0; k < NZ; k++)
        for (int y = 0; y < NY; y++)
            memcpy(pages + 3 * NX * (y + NY * k), RGB + 3 * NX * ((NY - 1 - y) + NY * k), 3 * NX);
    return tw_write_tiff(path, NX, NY, NZ, 3, 8, 1, pages);
}

static int write_dicom(const char *dir)
{
    char raw[256], cmd[1024];
    if (tw_write(tmp(raw, sizeof raw, "pattern.rgb"), RGB, sizeof RGB, NULL, 0)) return -1;
    mkdir(dir, 0755);
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/make_colour_dicom.py %s raw %s %d %d %d", dir, raw, NX, NY,
             NZ);
    return system(cmd) == 0 ? 0 : -1;
}

/* MetaImage is LPS: the matrix flips x and y so the RAS affine is the
 * identity. The RGB file is 8-bit and raw; the RGBA one 16-bit big-endian
 * (257 times the pattern) and zlib-compressed, with an alpha of its own
 * (100 (v mod 251) at voxel v). */
static int write_mha(const char *path, int channels)
{
    static uint16_t wide[NX * NY * NZ * 4];
    static uint8_t narrow[NX * NY * NZ * 3];
    for (int v = 0; v < NX * NY * NZ; v++)
        for (int c = 0; c < channels; c++) {
            if (channels == 3) narrow[3 * v + c] = RGB[3 * v + c];
            else wide[4 * v + c] = (uint16_t)(c < 3 ? 257 * RGB[3 * v + c] : 100 * (v % 251));
        }
    const int msb = channels == 4 && !big_endian_host();
    char hdr[512];
    snprintf(hdr, sizeof hdr,
             "ObjectType = Image\nNDims = 3\nDimSize = %d %d %d\nElementSpacing = 1 1 1\n"
             "TransformMatrix = -1 0 0 0 -1 0 0 0 1\nOffset = 0 0 0\nElementNumberOfChannels = %d\n"
             "ElementType = %s\nBinaryDataByteOrderMSB = %s\nCompressedData = %s\nElementDataFile = LOCAL\n",
             NX, NY, NZ, channels, channels == 3 ? "MET_UCHAR" : "MET_USHORT", channels == 4 ? "True" : "False",
             channels == 4 ? "True" : "False");
    const size_t n = (size_t)NX * NY * NZ * channels;
    void *swapped = msb ? tw_swapped(wide, n, 2) : NULL;
    const void *body = channels == 3 ? (const void *)narrow : swapped ? swapped : (const void *)wide;
    int rc = tw_write_header_data(path, hdr, body, channels == 3 ? n : 2 * n, channels == 3 ? TW_RAW : TW_ZLIB, NULL);
    free(swapped);
    return rc;
}

/* The pattern as a numbered RGB PNG series (slice_01.png, ...), rows top
 * first as in the TIFF. */
static int write_png_series(const char *dir)
{
    mkdir(dir, 0755);
    for (int k = 0; k < NZ; k++) {
        uint8_t page[NX * NY * 3];
        for (int y = 0; y < NY; y++) memcpy(page + 3 * NX * y, RGB + 3 * NX * ((NY - 1 - y) + NY * k), 3 * NX);
        char p[512];
        snprintf(p, sizeof p, "%s/slice_%02d.png", dir, k + 1);
        if (tw_write_png(p, NX, NY, 3, 8, page)) return -1;
    }
    return 0;
}

static int same_colour_volume(const vxl_volume *a, const vxl_volume *b)
{
    const size_t n = (size_t)NX * NY * NZ;
    int ok = !memcmp(a->dims, b->dims, sizeof a->dims) && a->texture_bits == b->texture_bits && a->colour &&
             b->colour && a->components == b->components && !memcmp(a->texels, b->texels, n * (a->texture_bits / 8)) &&
             !memcmp(a->colour, b->colour, 3 * n);
    for (int i = 0; i < 16; i++) ok = ok && fabs(a->affine[i] - b->affine[i]) < 1e-9;
    return ok;
}

static vxl_render_params params(int axis_view)
{
    vxl_render_params p;
    memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.width = W;
    p.height = H;
    p.jitter_off = 1;
    p.tf_rgba = TF;
    p.tf_size = 2;
    p.has_window = 1;
    p.window_low = 0;
    p.window_high = 255;
    if (axis_view >= 0) { /* otherwise the default camera: oblique, perspective */
        p.has_camera = 1;
        const double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {NX - 0.5, NY - 0.5, NZ - 0.5};
        vxl_axis_view_camera(axis_view, 1, lo, hi, W, H, p.view, p.proj);
    }
    return p;
}

TEST(rgb_nifti_tiff_dicom_mha_and_png_of_one_pattern_give_one_image)
{
    char path[F][256];
    REQUIRE(write_nifti(tmp(path[0], sizeof path[0], "rgb.nii")) == 0);
    REQUIRE(write_tiff(tmp(path[1], sizeof path[1], "rgb.tif")) == 0);
    REQUIRE(write_dicom(tmp(path[2], sizeof path[2], "dicom")) == 0);
    REQUIRE(write_mha(tmp(path[3], sizeof path[3], "rgb.mha"), 3) == 0);
    REQUIRE(write_png_series(tmp(path[4], sizeof path[4], "png")) == 0);
    static const char *const note[F] = {"NIfTI RGB24: colour", "TIFF/PNG RGB: colour", "DICOM RGB: colour",
                                        "MetaImage RGB: colour from the data, opacity and gradients from luminance",
                                        "TIFF/PNG RGB: colour"};
    vxl_volume *v[F] = {NULL};
    for (int f = 0; f < F; f++) {
        const int rc = f == 2 ? load_dicom_with(path[f], NULL, &v[f]) : vxl_volume_load(path[f], NULL, &v[f]);
        CHECKF(rc == VXL_OK, "%s: %s", path[f], vxl_last_error());
        vxl_volume_info in = {.struct_size = sizeof in};
        CHECKF(v[f] && vxl_volume_get_info(v[f], &in) == VXL_OK && in.components == 3 &&
                   in.color_bytes == sizeof RGB && strstr(in.notes, note[f]),
               "%s: %u components, notes '%s'", path[f], v[f] ? in.components : 0, v[f] ? in.notes : "");
    }
    for (int f = 0; f < F; f++) REQUIRE(v[f]);
    /* the NIfTI holds the pattern's own bytes; the others the same volume */
    CHECK(!memcmp(v[0]->colour, RGB, sizeof RGB));
    for (int f = 1; f < F; f++) CHECKF(same_colour_volume(v[0], v[f]), "%s differs from the NIfTI", path[f]);

    vxl_renderer *r = make_stored_renderer(VXL_STORAGE_DENSE, 0, 0, 0);
    REQUIRE(r);
    static float ref[W * H * 4], img[W * H * 4];
    const int views[2] = {-1, 4}; /* the default oblique camera; along z */
    for (int c = 0; c < 2; c++) {
        vxl_render_params p = params(views[c]);
        CHECK(vxl_renderer_set_volume(r, v[0]) == VXL_OK && vxl_render(r, &p, ref, NULL) == VXL_OK);
        double alpha = 0;
        for (int i = 0; i < W * H; i++) alpha += ref[4 * i + 3];
        CHECKF(alpha > 1 && image_is_sane(ref, NULL, W * H), "view %d: the NIfTI renders nothing", views[c]);
        for (int f = 1; f < F; f++) {
            CHECK(vxl_renderer_set_volume(r, v[f]) == VXL_OK && vxl_render(r, &p, img, NULL) == VXL_OK);
            CHECKF(!memcmp(img, ref, sizeof img), "view %d: %s renders differently from the NIfTI (rmse %g)",
                   views[c], path[f], image_rmse(img, ref, W * H * 4));
        }
    }
    vxl_renderer_destroy(r);
    for (int f = 0; f < F; f++) vxl_volume_destroy(v[f]);
}

/* An RGBA MetaImage (16-bit, big-endian, zlib): alpha is the 4th channel,
 * the scalar when the opacity source is alpha, with its 16 bits; the
 * colour is windowed into 8 bits over the R, G and B range, 0 to 257 times
 * the pattern's largest value. 2 channels are refused (test_loaders.c). */
TEST(rgba_mha_keeps_alpha_for_the_opacity_source)
{
    char path[256];
    REQUIRE(write_mha(tmp(path, sizeof path, "rgba.mha"), 4) == 0);
    vxl_load_options o = {.struct_size = sizeof o, .opacity_source = VXL_OPACITY_SOURCE_ALPHA};
    vxl_volume *v = NULL;
    CHECKF(vxl_volume_load(path, &o, &v) == VXL_OK, "%s", vxl_last_error());
    REQUIRE(v);
    CHECK(v->components == 4 && v->colour && v->texture_bits == 16);
    CHECKF(strstr(v->notes, "MetaImage RGBA: colour from the data, opacity and gradients from the alpha channel") &&
               strstr(v->notes, "windowed over the data's range"),
           "notes '%s'", v->notes);
    int top = 0;
    for (size_t i = 0; i < sizeof RGB; i++) top = RGB[i] > top ? RGB[i] : top;
    double worst_alpha = 0, worst_colour = 0;
    for (int i = 0; i < NX * NY * NZ; i++) {
        worst_alpha = fmax(worst_alpha, fabs(voxel(v, (uint64_t)i) - 100 * (i % 251)));
        for (int c = 0; c < 3; c++)
            worst_colour = fmax(worst_colour, fabs(v->colour[3 * i + c] - floor(RGB[3 * i + c] * 255.0 / top + 0.5)));
    }
    CHECKF(worst_alpha < 1e-6 && worst_colour == 0, "alpha off by %g, colour by %g", worst_alpha, worst_colour);
    vxl_volume_destroy(v);
    /* streaming asked for: read whole, and said so */
    o = (vxl_load_options){.struct_size = sizeof o, .streaming = VXL_STREAMING_ON};
    CHECK(vxl_volume_load(path, &o, &v) == VXL_OK && v && !v->source && strstr(v->notes, "does not stream"));
    vxl_volume_destroy(v);
}

OWN_PARSER_TEST

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_colour_readers_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    fill_pattern();
    RUN(rgb_nifti_tiff_dicom_mha_and_png_of_one_pattern_give_one_image);
    RUN(rgba_mha_keeps_alpha_for_the_opacity_source);
    RUN(own_parser_agrees_with_dcmtk);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
