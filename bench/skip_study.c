/* skip_study.c - what empty-space skipping buys, measured in one run: frame
 * time with every in-frame skip on against all off (--no-skip), per brick
 * size, on the ch2better brain and on a sparse phantom (~5% occupied) and
 * its dense twin. Also checks the skipped image against the unskipped one. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "voxlight_dev.h"

#define BRAIN "/usr/share/mricron/templates/ch2better.nii.gz"

int main(int argc, char **argv)
{
    uint32_t size = 512, phantom_n = 256;
    int frames = 5;
    const char *out = "bench/skipping.csv";
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) { size = 96; phantom_n = 64; frames = 3; }
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
        else { fprintf(stderr, "usage: voxlight-skipbench [--quick] [--out CSV]\n"); return 2; }
    }
    FILE *csv = fopen(out, "w");
    if (!csv) { perror(out); return 1; }
    fprintf(csv, "workload,brick_size,filter,ms_skip,ms_noskip,speedup,samples_skip,samples_noskip,bricks_total,"
                 "bricks_occupied,occupied_fraction,psnr_skip_vs_noskip_db\n");
    vxl_renderer *r = NULL;
    if (vxl_renderer_create(NULL, &r)) { fprintf(stderr, "%s\n", vxl_last_error()); return 1; }
    float *img = malloc((size_t)size * size * 4 * sizeof *img), *ref = malloc((size_t)size * size * 4 * sizeof *ref);
    const char *names[3] = {"ch2better", "sparse-balls", "dense-balls"};
    const uint32_t kinds[3] = {0, VXL_PHANTOM_SPARSE_BALLS, VXL_PHANTOM_DENSE_BALLS};
    const uint32_t bricks[4] = {4, 8, 16, 32};
    const uint32_t filters[2] = {VXL_FILTER_CENTRAL, VXL_FILTER_SOBEL26};
    int rc = 0;
    for (int w = 0; w < 3 && !rc; w++) {
        vxl_volume *v = NULL;
        if (kinds[w]) {
            vxl_phantom_desc pd = {.struct_size = sizeof pd, .kind = kinds[w], .dims = {phantom_n, phantom_n, phantom_n}};
            rc = vxl_phantom_create(&pd, &v);
        } else {
            rc = vxl_volume_load(BRAIN, NULL, &v);
        }
        if (rc) { fprintf(stderr, "%s: %s\n", names[w], vxl_last_error()); break; }
        for (int b = 0; b < 4 && !rc; b++) {
            char bs[8];
            snprintf(bs, sizeof bs, "%u", bricks[b]);
            setenv("VOXLIGHT_BRICK_SIZE", bs, 1);
            if ((rc = vxl_renderer_set_volume(r, v))) break; /* drops the grid: rebuilt at this size */
            for (int f = 0; f < 2 && !rc; f++) {
                vxl_render_params p = base_params(size);
                p.filter = filters[f];
                if (kinds[w]) {
                    p.preset = VXL_PRESET_BONE;
                    p.has_window = 1;
                    p.window_low = 0.35f;
                    p.window_high = 0.75f;
                }
                p.no_skip = 1;
                double t_off = median_ms(r, &p, ref, frames);
                vxl_render_stats s_off = {.struct_size = sizeof s_off}, s_on = s_off;
                vxl_renderer_get_stats(r, &s_off);
                p.no_skip = 0;
                double t_on = median_ms(r, &p, img, frames);
                vxl_renderer_get_stats(r, &s_on);
                if (t_on < 0 || t_off < 0) { rc = 1; break; }
                fprintf(csv, "%s,%u,%s,%.2f,%.2f,%.2f,%llu,%llu,%u,%u,%.4f,%.1f\n", names[w], bricks[b],
                        vxl_filter_name(filters[f]), t_on, t_off, t_off / t_on, (unsigned long long)s_on.samples,
                        (unsigned long long)s_off.samples, s_on.bricks_total, s_on.bricks_occupied,
                        (double)s_on.bricks_occupied / (s_on.bricks_total ? s_on.bricks_total : 1),
                        psnr(img, ref, (size_t)size * size * 4));
                fflush(csv);
                fprintf(stderr, "skip: %s brick %u %s: %.1f ms vs %.1f ms\n", names[w], bricks[b],
                        vxl_filter_name(filters[f]), t_on, t_off);
            }
        }
        vxl_volume_destroy(v);
    }
    unsetenv("VOXLIGHT_BRICK_SIZE");
    free(img);
    free(ref);
    vxl_renderer_destroy(r);
    fclose(csv);
    return rc;
}
