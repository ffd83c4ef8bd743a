/* test_nifti4d.c - 4D NIfTI (fMRI, cardiac phases): vxl_load_options.frame
 * reads one volume, vxl_volume_info reports frame_count, and nothing past the
 * requested frame is needed: a file whose later frames are cut off still
 * opens, its missing frames fail cleanly. Plain .nii (seek) and .nii.gz
 * (streamed), NIfTI-1 and -2, dim[5] counted as further frames. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "loader_test_util.h"
#include "nifti_writer.h"
#include "volume.h"
#include "voxlight.h"

#define N 16
#define FRAMES 40
#define PER (N * N * N)

static char g_dir[64];

/* Value of voxel i of frame f: distinct in every frame and voxel. */
static float value(int f, int i) { return (float)(f * 10000 + i); }

static float *make_frames(void)
{
    float *d = malloc(sizeof(float) * PER * FRAMES);
    if (!d) return NULL;
    for (int f = 0; f < FRAMES; f++)
        for (int i = 0; i < PER; i++) d[(size_t)f * PER + i] = value(f, i);
    return d;
}

/* channels: VXL_CHANNELS_*, how a 5D file's dim[5] is read (docs/channels.md) */
static vxl_volume *load_frame_as(const char *path, uint32_t frame, uint32_t channels)
{
    vxl_load_options opt = {.struct_size = sizeof opt, .frame = frame, .channels = channels};
    vxl_volume *v = NULL;
    return vxl_volume_load(path, &opt, &v) == VXL_OK ? v : NULL;
}

static vxl_volume *load_frame(const char *path, uint32_t frame) { return load_frame_as(path, frame, VXL_CHANNELS_AUTO); }

static void check_frame_as(vxl_test_ctx *T_, const char *path, uint32_t f, uint32_t channels)
{
    vxl_volume *v = load_frame_as(path, f, channels);
    CHECKF(v != NULL, "%s frame %u: %s", path, f, vxl_last_error());
    if (!v) return;
    vxl_volume_info info = {.struct_size = sizeof info};
    CHECK(vxl_volume_get_info(v, &info) == VXL_OK);
    CHECK(info.frame_count == FRAMES && info.frame == f);
    CHECK(info.dims[0] == N && info.dims[1] == N && info.dims[2] == N);
    const uint64_t probes[] = {0, 1, 17, PER / 2, PER - 1};
    for (size_t p = 0; p < sizeof probes / sizeof probes[0]; p++)
        CHECKF(fabs(voxel(v, probes[p]) - value((int)f, (int)probes[p])) < 0.5, "%s frame %u voxel %llu", path,
               f, (unsigned long long)probes[p]);
    vxl_volume_destroy(v);
}

static void check_frame(vxl_test_ctx *T_, const char *path, uint32_t f) { check_frame_as(T_, path, f, VXL_CHANNELS_AUTO); }

TEST(frame_n_of_a_4d_file_is_that_volume)
{
    float *d = make_frames();
    REQUIRE(d);
    const char *names[] = {"fmri.nii", "fmri.nii.gz", "fmri2.nii"};
    for (int k = 0; k < 3; k++) {
        char p[256];
        snprintf(p, sizeof p, "%s/%s", g_dir, names[k]);
        tnw_header h;
        tnw_init(&h, k == 2 ? 2 : 1, 16, N, N, N);
        h.dim[0] = 4;
        h.dim[4] = FRAMES;
        REQUIRE(tnw_write(p, &h, d, sizeof(float) * PER * FRAMES) == 0);
        check_frame(T_, p, 0);
        check_frame(T_, p, 1);
        check_frame(T_, p, 23);
        check_frame(T_, p, FRAMES - 1);
        CHECK(load_frame(p, FRAMES) == NULL && strstr(vxl_last_error(), "frame 40 requested, the file has 40"));
    }
    free(d);
}

TEST(later_frames_are_never_read_so_a_cut_file_opens)
{
    float *d = make_frames();
    REQUIRE(d);
    for (int gz = 0; gz < 2; gz++) {
        char p[256];
        snprintf(p, sizeof p, "%s/cut%s", g_dir, gz ? ".nii.gz" : ".nii");
        tnw_header h;
        tnw_init(&h, 1, 16, N, N, N);
        h.dim[0] = 4;
        h.dim[4] = FRAMES;
        /* 3 whole frames and half of the fourth of the 40 the header names */
        REQUIRE(tnw_write(p, &h, d, sizeof(float) * (PER * 3 + PER / 2)) == 0);
        check_frame(T_, p, 0);
        check_frame(T_, p, 2);
        for (uint32_t f = 3; f < FRAMES; f += 36) {
            vxl_volume *v = load_frame(p, f);
            CHECKF(v == NULL && strstr(vxl_last_error(), "truncated"), "%s frame %u: %s", p, f, vxl_last_error());
            vxl_volume_destroy(v);
        }
    }
    free(d);
}

TEST(dim5_counts_frames_with_channels_off_and_3d_files_have_one)
{
    float *d = make_frames();
    REQUIRE(d);
    char p[256];
    snprintf(p, sizeof p, "%s/5d.nii", g_dir);
    tnw_header h;
    tnw_init(&h, 1, 16, N, N, N);
    h.dim[0] = 5;
    h.dim[4] = 8;
    h.dim[5] = 5; /* 8 x 5 = 40 volumes, in file order */
    REQUIRE(tnw_write(p, &h, d, sizeof(float) * PER * FRAMES) == 0);
    check_frame_as(T_, p, 39, VXL_CHANNELS_OFF); /* as before channels */
    /* by default dim[5] is 5 channels of 8 frames (tests/test_channels.c) */
    vxl_volume *c = load_frame(p, 7);
    vxl_volume_info ci = {.struct_size = sizeof ci};
    CHECK(c && vxl_volume_get_info(c, &ci) == VXL_OK && ci.channel_count == 5 && ci.frame_count == 8 && ci.frame == 7);
    vxl_volume_destroy(c);
    snprintf(p, sizeof p, "%s/3d.nii", g_dir);
    tnw_init(&h, 1, 16, N, N, N);
    REQUIRE(tnw_write(p, &h, d, sizeof(float) * PER) == 0);
    vxl_volume *v = load_frame(p, 0);
    REQUIRE(v);
    vxl_volume_info info = {.struct_size = sizeof info};
    CHECK(vxl_volume_get_info(v, &info) == VXL_OK && info.frame_count == 1 && info.frame == 0);
    /* a caller built against the older, shorter struct gets nothing past it */
    vxl_volume_info old;
    memset(&old, 0x5A, sizeof old);
    old.struct_size = (uint32_t)offsetof(vxl_volume_info, frame_count);
    CHECK(vxl_volume_get_info(v, &old) == VXL_OK && old.frame_count == 0x5A5A5A5Au && old.dims[0] == N);
    vxl_volume_destroy(v);
    CHECK(load_frame(p, 1) == NULL && strstr(vxl_last_error(), "has 1"));
    /* an older vxl_load_options (before frame) reads frame 0 */
    vxl_load_options o = {.struct_size = (uint32_t)offsetof(vxl_load_options, frame), .frame = 5};
    v = NULL;
    CHECK(vxl_volume_load(p, &o, &v) == VXL_OK && v);
    vxl_volume_destroy(v);
    free(d);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_nifti4d_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(frame_n_of_a_4d_file_is_that_volume);
    RUN(later_frames_are_never_read_so_a_cut_file_opens);
    RUN(dim5_counts_frames_with_channels_off_and_3d_files_have_one);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
