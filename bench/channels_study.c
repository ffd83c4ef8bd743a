/* channels_study.c - frame time against the number of channels
 * (docs/channels.md "Cost against channels"): a 4-channel 16-bit stack
 * (default 512x512x128, each channel its own lattice of soft blobs over a
 * dim background, as fluorescence stacks look) drawn
 *   - as one channel: channel 0 as an ordinary one-channel volume, and
 *     channel 0 alone through the channel march,
 *   - as 4 channels in one march (additive and maximum blending),
 *   - as 4 overlays of the same data (channel 0 the base volume, channels
 *     1-3 overlays on the same grid, blend ADD), the way to show channels
 *     before multi-channel volumes,
 * emission only and lit, empty-space skipping on. Prints the median frame
 * time, its ratio to one channel and each image's alpha sum (a frame that
 * draws nothing would be cheap and wrong), and the GL memory of the scalar
 * and of the channels in the storage mode asked for (--storage, dense by
 * default; the paged modes page the channels too). The times mean nothing
 * on a loaded machine; the bytes are the same on any. Command:
 *   make -j1 build/voxlight-channelsbench && ./build/voxlight-channelsbench [--size 512] [--frames 5] [--dims 512x512x128]
 *       [--storage dense|bricked|sparse|compressed] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

#define C 4

/* Channel c at voxel (x, y, z): blobs of radius r on a lattice of pitch
 * 4r, shifted by c so the channels interleave, over a background of 300. */
static uint16_t voxel(uint32_t c, uint32_t x, uint32_t y, uint32_t z, const uint32_t d[3])
{
    const double r = d[2] / 10.0 > 2 ? d[2] / 10.0 : 2, pitch = 4 * r, shift = c * pitch / C;
    double q[3] = {x + shift, y + 0.5 * shift, (double)z};
    double d2 = 0;
    for (int a = 0; a < 3; a++) {
        const double k = q[a] - pitch * floor(q[a] / pitch + 0.5);
        d2 += k * k;
    }
    const double f = 1.0 - d2 / (r * r);
    return (uint16_t)(300 + (f > 0 ? (20000.0 + 8000.0 * c) * f : 0));
}

/* --size S --frames F --dims XxYxZ --storage NAME; 0 on anything else or out of range. */
static int parse_args(int argc, char **argv, uint32_t *size, int *frames, uint32_t d[3], uint32_t *storage)
{
    for (int i = 1; i < argc; i++) {
        const int has_value = i + 1 < argc;
        if (has_value && !strcmp(argv[i], "--size")) *size = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (has_value && !strcmp(argv[i], "--frames")) *frames = (int)strtol(argv[++i], NULL, 10);
        else if (has_value && !strcmp(argv[i], "--dims")) {
            if (sscanf(argv[++i], "%ux%ux%u", &d[0], &d[1], &d[2]) != 3) return 0;
        } else if (has_value && !strcmp(argv[i], "--storage")) {
            if (vxl_storage_from_name(argv[++i], storage) || *storage == VXL_STORAGE_AUTO) return 0;
        } else return 0;
    }
    for (int a = 0; a < 3; a++)
        if (d[a] < 8 || d[a] > 2048) return 0;
    return *size >= 16 && *size <= 4096 && *frames >= 1 && *frames <= 64;
}

static double alpha_sum(const float *img, uint32_t size)
{
    double s = 0;
    for (size_t i = 0; i < (size_t)size * size; i++) s += img[4 * i + 3];
    return s;
}

int main(int argc, char **argv)
{
    uint32_t size = 512, d[3] = {512, 512, 128};
    int frames = 5;
    uint32_t storage = VXL_STORAGE_DENSE;
    if (!parse_args(argc, argv, &size, &frames, d, &storage)) {
        fprintf(stderr, "usage: voxlight-channelsbench [--size 16..4096] [--frames 1..64] [--dims XxYxZ] "
                        "[--storage dense|bricked|sparse|compressed]\n");
        return 2;
    }
    const size_t n = (size_t)d[0] * d[1] * d[2];
    uint16_t *planes = malloc(n * C * sizeof *planes);
    float *img = malloc((size_t)size * size * 4 * sizeof *img);
    if (!planes || !img) return 1;
    for (uint32_t c = 0; c < C; c++)
        for (uint32_t z = 0; z < d[2]; z++)
            for (uint32_t y = 0; y < d[1]; y++)
                for (uint32_t x = 0; x < d[0]; x++)
                    planes[c * n + x + (size_t)d[0] * (y + (size_t)d[1] * z)] = voxel(c, x, y, z, d);
    vxl_volume *multi = NULL, *one[C] = {NULL};
    vxl_volume_desc md = {.struct_size = sizeof md, .dtype = VXL_DTYPE_U16, .dims = {d[0], d[1], d[2]},
                          .data = planes, .channels = C};
    int rc = vxl_volume_create(&md, NULL, &multi);
    for (uint32_t c = 0; c < C && !rc; c++) {
        vxl_volume_desc od = {.struct_size = sizeof od, .dtype = VXL_DTYPE_U16, .dims = {d[0], d[1], d[2]},
                              .data = planes + c * n};
        rc = vxl_volume_create(&od, NULL, &one[c]);
    }
    free(planes);
    const vxl_renderer_options o = {.struct_size = sizeof o, .storage = storage};
    vxl_renderer *r = NULL;
    if (!rc) rc = vxl_renderer_create(&o, &r);
    if (rc) {
        fprintf(stderr, "voxlight-channelsbench: %s\n", vxl_last_error());
        return 1;
    }
    /* every channel and overlay: a grey ramp over its blobs' range, the background transparent */
    static const float tf[4 * 4] = {0, 0, 0, 0, 1, 1, 1, 0.02f, 1, 1, 1, 0.05f, 1, 1, 1, 0.1f};
    vxl_channel_style st[C];
    vxl_overlay_style ov[C - 1];
    for (uint32_t c = 0; c < C; c++) {
        st[c] = (vxl_channel_style){.struct_size = sizeof st[c], .channel = c, .tf_rgba = tf, .tf_size = 4,
                                    .has_window = 1, .window_low = 2000, .window_high = 50000};
        if (c) ov[c - 1] = (vxl_overlay_style){.struct_size = sizeof ov[0], .slot = c - 1, .blend = VXL_BLEND_ADD,
                                               .tf_rgba = tf, .tf_size = 4, .has_window = 1, .window_low = 2000,
                                               .window_high = 50000};
    }
    printf("4 channels of %ux%ux%u uint16, %s storage, %u^2 frames, median of %d\n\n", d[0], d[1], d[2],
           vxl_storage_name(storage), size, frames);
    printf("| drawn | shading | frame ms | x one channel | alpha sum |\n|---|---|---|---|---|\n");
    for (uint32_t lit = 0; lit < 2 && !rc; lit++) {
        vxl_render_params p = base_params(size);
        p.shading_off = !lit;
        p.tf_rgba = tf;
        p.tf_size = 4;
        p.has_window = 1;
        p.window_low = 2000;
        p.window_high = 50000;
        const char *shade = lit ? "Phong" : "emission";
        /* one channel as an ordinary volume: the baseline */
        rc = vxl_renderer_set_volume(r, one[0]);
        const double base = rc ? -1 : median_ms(r, &p, img, frames);
        if (base < 0) break;
        printf("| channel 0 as a one-channel volume | %s | %.1f | 1.00 | %.0f |\n", shade, base, alpha_sum(img, size));
        /* four overlays of the same data */
        for (uint32_t k = 0; k + 1 < C && !rc; k++) rc = vxl_renderer_set_overlay(r, k, one[k + 1]);
        p.overlay_count = C - 1;
        p.overlays = ov;
        const double t_ov = rc ? -1 : median_ms(r, &p, img, frames);
        if (t_ov < 0) break;
        printf("| 4 volumes: channel 0 + 3 overlays (add) | %s | %.1f | %.2f | %.0f |\n", shade, t_ov, t_ov / base,
               alpha_sum(img, size));
        p.overlay_count = 0;
        p.overlays = NULL;
        for (uint32_t k = 0; k + 1 < C; k++) vxl_renderer_set_overlay(r, k, NULL);
        /* the channel march: one channel, then four, added and by maximum */
        rc = vxl_renderer_set_volume(r, multi);
        static const struct { uint32_t count, blend; const char *name; } rows[3] = {
            {1, VXL_CHANNEL_BLEND_ADD, "channel 0 through the channel march"},
            {C, VXL_CHANNEL_BLEND_ADD, "4 channels in one march (add)"},
            {C, VXL_CHANNEL_BLEND_MAX, "4 channels in one march (max)"}};
        for (int k = 0; k < 3 && !rc; k++) {
            p.channel_count = rows[k].count;
            p.channel_blend = rows[k].blend;
            p.channels = st;
            const double t = median_ms(r, &p, img, frames);
            if (t < 0) rc = 1;
            else printf("| %s | %s | %.1f | %.2f | %.0f |\n", rows[k].name, shade, t, t / base, alpha_sum(img, size));
        }
        vxl_render_stats s = {.struct_size = sizeof s};
        if (!lit && !rc && !vxl_renderer_get_stats(r, &s))
            printf("| GL memory | %s storage | scalar %.2f MiB | channels %.2f MiB | dense channels %.2f MiB |\n",
                   vxl_storage_name(storage), s.resident_bytes / 1048576.0, s.channel_bytes / 1048576.0,
                   n * C * 2 / 1048576.0);
        if (base < 0 || rc) rc = 1;
    }
    if (rc) fprintf(stderr, "voxlight-channelsbench: %s\n", vxl_renderer_error(r));
    free(img);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(multi);
    for (uint32_t c = 0; c < C; c++) vxl_volume_destroy(one[c]);
    return rc;
}
