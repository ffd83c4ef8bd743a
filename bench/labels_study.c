/* labels_study.c - frame time against the number of labels
 * (docs/labels.md "Rendering"): a 128^3 sphere phantom drawn once with its
 * transfer function alone (the baseline), then with a label volume of the
 * same grid split into 1, 16 and 256 labels (blocks inside the phantom's
 * ellipsoid) in each label mode (surface, mask, tint), all labels visible.
 * Prints the median frame time, its ratio to the baseline (the goal is
 * <= 1.5x) and the samples a ray took (vxl_render_stats: the work, which
 * the label bricks' leaps cut, independent of the machine's load); the
 * times mean nothing on a loaded machine. --boundary voxels draws the raw
 * voxels' faces instead of the smoothed boundaries (the default); the time
 * vxl_renderer_set_labels takes (upload and, when smooth, the margins) is
 * printed per label count. Command:
 *   make -j1 build/voxlight-labelsbench && ./build/voxlight-labelsbench [--size 512] [--frames 5] [--boundary smooth|voxels] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "voxlight_dev.h"

#define N 128

static vxl_volume *label_volume(const vxl_volume *phantom, uint32_t count)
{
    static uint16_t ids[N * N * N];
    /* blocks of a g^3 lattice, g^3 >= count, numbered modulo count, inside the ellipsoid */
    uint32_t g = 1;
    while (g * g * g < count) g++;
    for (uint32_t z = 0; z < N; z++)
        for (uint32_t y = 0; y < N; y++)
            for (uint32_t x = 0; x < N; x++) {
                double u = (x + 0.5) / N * 2 - 1, v = (y + 0.5) / N * 2 - 1, w = (z + 0.5) / N * 2 - 1;
                int in = (u / 0.7) * (u / 0.7) + (v / 0.5) * (v / 0.5) + (w / 0.6) * (w / 0.6) <= 1;
                uint32_t b = (x * g / N) + g * ((y * g / N) + g * (z * g / N));
                ids[x + N * (y + N * z)] = in ? (uint16_t)(1 + b % count) : 0;
            }
    vxl_volume_info info = {.struct_size = sizeof info};
    vxl_volume_get_info(phantom, &info);
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U16, .dims = {N, N, N}, .has_affine = 1, .data = ids};
    memcpy(d.affine, info.affine, sizeof d.affine);
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, NULL, &v) ? NULL : v;
}

/* Samples per ray of the last frame. */
static double samples_per_ray(vxl_renderer *r)
{
    vxl_render_stats st = {.struct_size = sizeof st};
    if (vxl_renderer_get_stats(r, &st) || !st.rays) return 0;
    return (double)st.samples / st.rays;
}

int main(int argc, char **argv)
{
    uint32_t size = 512, boundary = VXL_LABEL_BOUNDARY_SMOOTH;
    int frames = 5, bad = 0;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--size")) size = (uint32_t)atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--frames")) frames = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--boundary") && !strcmp(argv[i + 1], "voxels")) boundary = VXL_LABEL_BOUNDARY_VOXELS;
        else if (strcmp(argv[i], "--boundary") || strcmp(argv[i + 1], "smooth")) bad = 1;
    }
    if (bad || size < 16 || size > 4096 || frames < 1 || frames > 64) {
        fprintf(stderr, "usage: voxlight-labelsbench [--size 16..4096] [--frames 1..64] [--boundary smooth|voxels]\n");
        return 2;
    }
    vxl_renderer_options o = {.struct_size = sizeof o};
    vxl_renderer *r = NULL;
    vxl_phantom_desc ph = {.struct_size = sizeof ph, .kind = VXL_PHANTOM_SPHERE, .dims = {N, N, N}};
    vxl_volume *vol = NULL;
    if (vxl_renderer_create(&o, &r) || vxl_phantom_create(&ph, &vol) || vxl_renderer_set_volume(r, vol)) {
        fprintf(stderr, "voxlight-labelsbench: %s\n", vxl_last_error());
        return 1;
    }
    float *img = malloc((size_t)size * size * 4 * sizeof *img);
    static vxl_label_entry e[256];
    if (!img) return 1;
    vxl_render_params p = base_params(size);
    p.preset = VXL_PRESET_BONE;
    double base = median_ms(r, &p, img, frames);
    printf("| labels | mode | frame ms | x single TF | samples a ray |\n|---|---|---|---|---|\n"
           "| - | transfer function | %.1f | 1.00 | %.1f |\n", base, samples_per_ray(r));
    const uint32_t counts[3] = {1, 16, 256};
    int rc = base < 0;
    for (int c = 0; c < 3 && !rc; c++) {
        vxl_volume *lab = label_volume(vol, counts[c]);
        const double t0 = now_ms();
        if (!lab || vxl_renderer_set_labels(r, lab)) {
            rc = 1;
            break;
        }
        fprintf(stderr, "%u labels: vxl_renderer_set_labels %.1f ms\n", counts[c], now_ms() - t0);
        vxl_volume_destroy(lab);
        for (uint32_t k = 0; k < counts[c]; k++) {
            e[k] = (vxl_label_entry){.struct_size = sizeof e[k], .id = (int32_t)k + 1, .visible = 1};
            e[k].color[0] = (float)((k * 37) % 256) / 255.0f;
            e[k].color[1] = (float)((k * 91) % 256) / 255.0f;
            e[k].color[2] = 0.6f;
            e[k].color[3] = 1;
        }
        for (uint32_t m = 0; m < VXL_LABEL_MODE_COUNT && !rc; m++) {
            vxl_label_style s = {.struct_size = sizeof s, .mode = m, .entry_count = counts[c], .entries = e,
                                 .boundary = boundary};
            p.labels = &s;
            double t = median_ms(r, &p, img, frames);
            p.labels = NULL;
            if (t < 0) rc = 1;
            else
                printf("| %u | %s | %.1f | %.2f | %.1f |\n", counts[c], vxl_label_mode_name(m), t, t / base,
                       samples_per_ray(r));
        }
    }
    if (rc) fprintf(stderr, "voxlight-labelsbench: %s\n", vxl_renderer_error(r));
    free(img);
    vxl_volume_destroy(vol);
    vxl_renderer_destroy(r);
    return rc;
}
