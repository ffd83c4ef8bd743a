/* path_study.c - the PATH shading model's cost against its noise, on
 * ch2better (or --input FILE) at size^2 (osmesa), one sun and the default
 * material: the time to the first frame (a fresh renderer: programs, the
 * illumination volumes and the majorant built, one sample per pixel), then
 * per sample count N the time of one call of N samples and its RMSE and
 * PSNR (linear colour, 0..1) against a reference of many samples (another
 * seed, accumulated in calls of 16 with vxl_path_accumulate, so it is
 * independent of the images it judges). A benchmark, not a test: run it on
 * a quiet machine (docs/lighting.md).
 *   voxlight-pathbench [--input FILE] [--size N] [--bounces B] [--reference N] [--samples 1,2,4,...] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

#define BRAIN "/usr/share/mricron/templates/ch2better.nii.gz"
#define MAX_COUNTS 16

static int fail(vxl_renderer *r)
{
    fprintf(stderr, "voxlight-pathbench: %s\n", r ? vxl_renderer_error(r) : vxl_last_error());
    return 1;
}

static double rmse_rgb(const float *a, const float *b, size_t npix)
{
    double s = 0;
    for (size_t i = 0; i < npix; i++)
        for (int c = 0; c < 3; c++) s += ((double)a[4 * i + c] - b[4 * i + c]) * ((double)a[4 * i + c] - b[4 * i + c]);
    return sqrt(s / (3.0 * npix));
}

int main(int argc, char **argv)
{
    const char *input = BRAIN, *list = "1,2,4,8,16,32,64";
    uint32_t size = 512, bounces = 0, ref_samples = 1024;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--input")) input = argv[i + 1];
        else if (!strcmp(argv[i], "--size")) size = (uint32_t)atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--bounces")) bounces = (uint32_t)atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--reference")) ref_samples = (uint32_t)atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--samples")) list = argv[i + 1];
    }
    uint32_t counts[MAX_COUNTS];
    int n_counts = 0;
    for (const char *s = list; *s && n_counts < MAX_COUNTS;) {
        counts[n_counts++] = (uint32_t)strtoul(s, (char **)&s, 10);
        if (*s == ',') s++;
        else if (*s) break;
    }
    if (size < 16 || ref_samples < 16 || n_counts == 0 || counts[0] == 0) {
        fprintf(stderr, "usage: voxlight-pathbench [--input FILE] [--size N] [--bounces B] [--reference N>=16] "
                        "[--samples 1,2,4,...]\n");
        return 2;
    }
    const size_t npix = (size_t)size * size;
    float *img = malloc(npix * 4 * sizeof *img), *ref = malloc(npix * 4 * sizeof *ref);
    if (!img || !ref) return 1;
    vxl_render_params p = base_params(size);
    p.shading_model = VXL_SHADING_PATH;
    p.path_bounces = bounces;
    p.light_count = 1;
    const float sun[4] = {1, 0.3f, 0.5f, 0};
    memcpy(p.lights[0].position, sun, sizeof sun);

    /* the first frame of a fresh renderer, as the viewport's first redraw */
    double t0 = now_ms();
    vxl_renderer *r = renderer_with_volume(input, "voxlight-pathbench");
    if (!r) return 1;
    double t1 = now_ms();
    p.path_samples = 1;
    if (vxl_render(r, &p, img, NULL)) return fail(r);
    const double first = now_ms() - t1, loaded = t1 - t0;

    /* the reference: another seed, in calls of 16 */
    p.path_seed = 1000;
    p.path_samples = 16;
    for (uint32_t k = 0; k < ref_samples; k += 16) {
        p.path_sample_offset = k;
        if (vxl_render(r, &p, img, NULL)) return fail(r);
        vxl_path_accumulate(ref, img, npix * 4, k, 16);
    }
    printf("input %s, %u^2, bounces %u, reference %u samples\n", input, size, bounces ? bounces : VXL_PATH_DEFAULT_BOUNCES,
           ref_samples);
    printf("load + renderer %.1f ms; first frame (1 sample, cold) %.1f ms\n\n", loaded, first);
    printf("| samples | ms (one call) | RMSE | PSNR (dB) |\n|---|---|---|---|\n");
    p.path_seed = 1;
    p.path_sample_offset = 0;
    for (int k = 0; k < n_counts; k++) {
        p.path_samples = counts[k];
        double s = now_ms();
        if (vxl_render(r, &p, img, NULL)) return fail(r);
        double ms = now_ms() - s, e = rmse_rgb(img, ref, npix);
        printf("| %u | %.1f | %.5f | %.1f |\n", counts[k], ms, e, e > 0 ? 20 * log10(1 / e) : 200.0);
    }
    free(img);
    free(ref);
    vxl_renderer_destroy(r);
    return 0;
}
