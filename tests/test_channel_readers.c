/* test_channel_readers.c - multi-channel files read by the helper processes
 * (OME-Zarr, TIFF samples, OME-TIFF) and MetaImage (docs/channels.md
 * "Loading"). The files are written by tests/channel_files_write.py (numpy
 * and a TIFF writer of its own, independent of the readers), each beside its
 * voxels as planar uint16 (C, Z, Y, X); every load must be the multi-channel
 * volume vxl_volume_create makes of those voxels in memory: the same packed
 * 16-bit channels, ranges and scalar, bit for bit. Also: the OME names,
 * colours (the file's sRGB), windows and "active" in vxl_volume_info, through
 * the helper stream; `#c=1` and channels OFF still read one channel; 3
 * samples of an RGB photometric stay colour; an over-budget file is refused
 * before allocating, saying why. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "loader_test_util.h"
#include "volume.h"
#include "voxlight.h"

enum { X = 7, Y = 6, Z = 5, V = X * Y * Z };

static char g_dir[64];

static vxl_volume *load(const char *name, uint32_t channels_mode, uint64_t budget)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    vxl_load_options o = {.struct_size = sizeof o, .channels = channels_mode, .memory_budget_bytes = budget};
    vxl_volume *v = NULL;
    return vxl_volume_load(path, &o, &v) == VXL_OK ? v : NULL;
}

/* The volume made in memory of NAME.u16's `channels` planar channels. */
static vxl_volume *reference(const char *name, uint32_t channels)
{
    static uint16_t data[8 * V];
    char path[256];
    snprintf(path, sizeof path, "%s/%s.u16", g_dir, name);
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    const size_t got = fread(data, 2, (size_t)channels * V, f);
    fclose(f);
    if (got != (size_t)channels * V) return NULL;
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U16, .dims = {X, Y, Z}, .data = data,
                         .spacing = {1, 1, 1}, .channels = channels};
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, NULL, &v) == VXL_OK ? v : NULL;
}

/* v holds exactly ref's channels and scalar. */
static int same_channels(vxl_test_ctx *T_, const char *name, const vxl_volume *v, const vxl_volume *ref)
{
    CHECKF(v && ref, "%s: %s", name, vxl_last_error());
    if (!v || !ref) return 0;
    int ok = v->channel_count == ref->channel_count && v->scalar_channel == ref->scalar_channel &&
             !memcmp(v->dims, ref->dims, sizeof v->dims) && v->texture_bits == ref->texture_bits;
    CHECKF(ok, "%s: %u channels (want %u), dims %ux%ux%u", name, v->channel_count, ref->channel_count, v->dims[0],
           v->dims[1], v->dims[2]);
    if (!ok) return 0;
    const size_t n = (size_t)V * v->channel_count * 2;
    ok = v->channels && !memcmp(v->channels, ref->channels, n) && !memcmp(v->texels, ref->texels, ref->storage_bytes);
    for (uint32_t c = 0; c < v->channel_count; c++)
        ok &= v->ch_tex_lo[c] == ref->ch_tex_lo[c] && v->ch_tex_hi[c] == ref->ch_tex_hi[c] &&
              v->ch_min[c] == ref->ch_min[c] && v->ch_max[c] == ref->ch_max[c];
    CHECKF(ok, "%s: the channels differ from the same voxels made in memory", name);
    return ok;
}

static int close_to(float a, double b) { return fabs(a - b) < 1e-6; }

TEST(ome_zarr_c_axis_loads_as_channels_with_omero_metadata)
{
    vxl_volume *v = load("omero.zarr", VXL_CHANNELS_AUTO, 0), *ref = reference("omero", 3);
    same_channels(T_, "omero.zarr", v, ref);
    REQUIRE(v);
    const vxl_volume_info in = volume_info_of(v);
    CHECKF(strstr(in.notes, "OME-Zarr c axis: 3 channels (channel 0 is the scalar)") != NULL, "notes '%s'", in.notes);
    CHECK(!strcmp(in.channel_names[0], "DAPI") && !strcmp(in.channel_names[1], "GFP") &&
          !strcmp(in.channel_names[2], "mCherry") && !in.channel_names[3][0]);
    /* "0000FF", "00FF00", "FF00FF": the file's sRGB / 255, not decoded */
    CHECK(in.channel_color_known[0] && in.channel_color_known[1] && in.channel_color_known[2] &&
          !in.channel_color_known[3]);
    CHECK(close_to(in.channel_colors[0][2], 1) && close_to(in.channel_colors[0][0], 0) &&
          close_to(in.channel_colors[1][1], 1) && close_to(in.channel_colors[2][0], 1) &&
          close_to(in.channel_colors[2][1], 0));
    CHECK(in.channel_window_known[1] && in.channel_window_low[1] == 20 && in.channel_window_high[1] == 600);
    CHECK(in.channel_active[0] == 1 && in.channel_active[1] == 0 && in.channel_active[2] == 1);
    vxl_volume_destroy(v);
    vxl_volume_destroy(ref);
    /* "#c=1" and channels OFF: one channel, as before */
    v = load("omero.zarr#c=1", VXL_CHANNELS_AUTO, 0);
    CHECKF(v && volume_info_of(v).channel_count == 0, "#c=1: %s", vxl_last_error());
    if (v) CHECK(volume_info_of(v).value_min == 4 && volume_info_of(v).value_max == 134); /* channel 1's range */
    vxl_volume_destroy(v);
    v = load("omero.zarr", VXL_CHANNELS_OFF, 0);
    CHECKF(v && volume_info_of(v).channel_count == 0 && volume_info_of(v).value_max == 63, "off: %s", vxl_last_error());
    vxl_volume_destroy(v);
}

TEST(tiff_samples_and_ome_tiff_planes_load_as_channels)
{
    static const struct { const char *file, *ref; uint32_t n; const char *note; int named; } cases[] = {
        {"two_samples.tif", "two_samples", 2, "TIFF samples: 2 channels", 0},
        {"three_samples.tif", "three_samples", 3, "TIFF samples: 3 channels", 0},
        {"cells.ome.tif", "cells", 3, "OME-TIFF SizeC: 3 channels", 1},     /* XYZCT */
        {"cells_czt.ome.tif", "cells", 3, "OME-TIFF SizeC: 3 channels", 1}, /* XYCZT */
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        vxl_volume *v = load(cases[k].file, VXL_CHANNELS_AUTO, 0), *ref = reference(cases[k].ref, cases[k].n);
        same_channels(T_, cases[k].file, v, ref);
        if (v) {
            const vxl_volume_info in = volume_info_of(v);
            CHECKF(strstr(in.notes, cases[k].note) != NULL, "%s: notes '%s'", cases[k].file, in.notes);
            if (cases[k].named) {
                CHECK(!strcmp(in.channel_names[0], "DAPI") && !strcmp(in.channel_names[2], "mCherry"));
                /* Color -16711681 is 0xFF00FFFF: magenta, alpha ignored */
                CHECK(in.channel_color_known[2] && close_to(in.channel_colors[2][0], 1) &&
                      close_to(in.channel_colors[2][1], 0) && close_to(in.channel_colors[2][2], 1));
                CHECK(!in.channel_window_known[0] && in.channel_active[2]);
            } else {
                CHECK(!in.channel_names[0][0] && !in.channel_color_known[0]);
            }
        }
        vxl_volume_destroy(v);
        vxl_volume_destroy(ref);
    }
    /* channels OFF: as before: three samples are RGB colour, OME pages are slices */
    vxl_volume *v = load("three_samples.tif", VXL_CHANNELS_OFF, 0);
    CHECKF(v && volume_info_of(v).components == 3 && volume_info_of(v).channel_count == 0, "%s", vxl_last_error());
    vxl_volume_destroy(v);
    v = load("cells.ome.tif", VXL_CHANNELS_OFF, 0);
    CHECKF(v && volume_info_of(v).dims[2] == 3 * Z && volume_info_of(v).channel_count == 0 &&
               strstr(volume_info_of(v).notes, "SizeC=3 not used (channels off)"),
           "%s", v ? volume_info_of(v).notes : vxl_last_error());
    vxl_volume_destroy(v);
}

TEST(metaimage_element_channels_load_as_channels)
{
    vxl_volume *v = load("five.mha", VXL_CHANNELS_AUTO, 0), *ref = reference("five", 5);
    same_channels(T_, "five.mha", v, ref);
    if (v) {
        CHECKF(strstr(volume_info_of(v).notes, "MetaImage ElementNumberOfChannels: 5 channels") != NULL, "notes '%s'",
               volume_info_of(v).notes);
        /* MetaImage geometry is LPS: x and y spacing negated into RAS */
        CHECK(v->affine[0] == -0.5 && v->affine[5] == -0.5 && v->affine[10] == 2.0);
    }
    vxl_volume_destroy(v);
    vxl_volume_destroy(ref);
    char path[256];
    snprintf(path, sizeof path, "%s/five.mha", g_dir);
    vxl_load_options off = {.struct_size = sizeof off, .channels = VXL_CHANNELS_OFF};
    v = NULL;
    CHECK(vxl_volume_load(path, &off, &v) == VXL_ERR_FORMAT && !v);
    CHECKF(strstr(vxl_last_error(), "5 channels per voxel and channels off") != NULL, "'%s'", vxl_last_error());
}

TEST(over_budget_files_are_refused_before_allocating)
{
    /* 210 voxels: the 16-bit scalar + 2 bytes a channel is 8 B (3 channels)
     * to 12 B (5) a voxel, over 1 KiB; each reader plans before reading */
    static const char *files[] = {"omero.zarr", "two_samples.tif", "cells.ome.tif", "five.mha"};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        vxl_volume *v = load(files[k], VXL_CHANNELS_AUTO, 1024);
        CHECKF(!v && strstr(vxl_last_error(), "over the memory budget") &&
                   strstr(vxl_last_error(), "multi-channel volumes are read whole"),
               "%s: '%s'", files[k], vxl_last_error());
        vxl_volume_destroy(v);
    }
}

int main(void)
{
    char cmd[256];
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_test_chanread_XXXXXX");
    if (!mkdtemp(g_dir)) return perror("mkdtemp"), 1;
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/channel_files_write.py %s", g_dir);
    if (system(cmd) != 0) return fprintf(stderr, "tests/channel_files_write.py failed\n"), 1;
    RUN(ome_zarr_c_axis_loads_as_channels_with_omero_metadata);
    RUN(tiff_samples_and_ome_tiff_planes_load_as_channels);
    RUN(metaimage_element_channels_load_as_channels);
    RUN(over_budget_files_are_refused_before_allocating);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
