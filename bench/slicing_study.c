/* slicing_study.c - the slicing comparison modes (docs/slicing.md)
 * against the ray caster: time and error per technique and sampling rate
 * (step = slice spacing), and the popping of 2D stacks where they switch
 * axis at 45 degrees azimuth.
 *
 * Workloads: ch2better (MRI preset, sobel8, shaded; reference: the ray
 * caster's finest setting, cubic at step 0.125, as voxlight-bench) and the
 * Marschner-Lobb phantom (bone window, sobel8, shaded; reference: the
 * double-precision analytic renderer). Popping: the image change (RMSE)
 * from azimuth 44.9 to 45.1 degrees, across the switch, against the change
 * from 44.7 to 44.9, which switches nothing. Steps 2, 1, 0.5, 0.25 on the
 * phantom; 2, 1, 0.5 on ch2better.
 *
 * usage: voxlight-slicingbench [--quick] [--size N] [--frames N] [--out CSV] */
#include <stdio.h>

#include "bench_util.h"
#include "voxlight_dev.h"

#define BRAIN "/usr/share/mricron/templates/ch2better.nii.gz"

static double rmse_of(const float *a, const float *b, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; i++) s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return sqrt(s / n);
}

typedef struct study {
    const char *name, *reference;
    vxl_render_params p; /* the scene; technique and step set per row */
    float *ref, *img, *pop[3];
    size_t n;
} study;

/* One row per technique and step: median time, error against the reference;
 * popping columns at step 1. */
static int run_study(FILE *csv, vxl_renderer *r, study *s, const float *steps, int n_steps, int frames)
{
    for (int k = 0; k < n_steps; k++)
        for (uint32_t t = 0; t < VXL_TECHNIQUE_COUNT; t++) {
            vxl_render_params p = s->p;
            p.technique = t;
            p.step = steps[k];
            double ms = median_ms(r, &p, s->img, frames);
            if (ms < 0) return fprintf(stderr, "slicingbench: %s\n", vxl_renderer_error(r)), 1;
            double e = rmse_of(s->img, s->ref, s->n);
            fprintf(csv, "%s,%s,%s,%g,%.1f,%.6f,%.2f,%s,", s->name, vxl_technique_name(t), vxl_filter_name(p.filter),
                    p.step, ms, e, e > 0 ? 20 * log10(1 / e) : 200.0, s->reference);
            if (steps[k] == 1.0f) {
                const float az[3] = {44.7f, 44.9f, 45.1f};
                for (int i = 0; i < 3; i++) {
                    p.azimuth_deg = az[i];
                    if (vxl_render(r, &p, s->pop[i], NULL)) return 1;
                }
                fprintf(csv, "%.5f,%.5f", rmse_of(s->pop[1], s->pop[2], s->n), rmse_of(s->pop[0], s->pop[1], s->n));
            } else {
                fprintf(csv, ",");
            }
            fprintf(csv, ",%ux%u,%d\n", p.width, p.height, frames);
            fflush(csv);
        }
    return 0;
}

static int alloc_images(study *s)
{
    s->n = (size_t)s->p.width * s->p.height * 4;
    float **bufs[5] = {&s->ref, &s->img, &s->pop[0], &s->pop[1], &s->pop[2]};
    for (int i = 0; i < 5; i++)
        if (!(*bufs[i] = malloc(s->n * sizeof(float)))) return 1;
    return 0;
}

static void free_images(study *s)
{
    free(s->ref);
    free(s->img);
    for (int i = 0; i < 3; i++) free(s->pop[i]);
}

int main(int argc, char **argv)
{
    int quick = 0, frames = 3;
    uint32_t size = 512;
    const char *out = "bench/slicing.csv";
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) quick = 1, size = 64, frames = 1;
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
        else return fprintf(stderr, "usage: %s [--quick] [--size N] [--frames 1..64] [--out CSV]\n", argv[0]), 2;
    }
    if (size < 16 || size > 4096 || frames < 1 || frames > 64) return fprintf(stderr, "bad --size or --frames\n"), 2;
    FILE *csv = fopen(out, "w");
    if (!csv) return fprintf(stderr, "cannot write %s\n", out), 1;
    fprintf(csv, "workload,technique,filter,step,ms,rmse,psnr_db,reference,pop_across_rmse,pop_nearby_rmse,size,frames\n");
    vxl_renderer_options ro = {.struct_size = sizeof ro};
    vxl_renderer *r = NULL;
    if (vxl_renderer_create(&ro, &r)) return fprintf(stderr, "slicingbench: %s\n", vxl_last_error()), 1;
    const float steps[4] = {2.0f, 1.0f, 0.5f, 0.25f};
    int rc = 0;

    /* the phantom against the analytic reference */
    {
        vxl_phantom_desc pd = {.struct_size = sizeof pd, .kind = VXL_PHANTOM_MARSCHNER_LOBB, .dims = {64, 64, 64}};
        vxl_volume *v = NULL;
        study s = {.name = "marschner-lobb", .reference = "analytic", .p = base_params(quick ? 48 : size / 2)};
        s.p.preset = VXL_PRESET_BONE;
        s.p.has_window = 1;
        s.p.window_low = 0.35f;
        s.p.window_high = 0.75f;
        s.p.filter = VXL_FILTER_SOBEL8;
        s.p.jitter_off = 1;
        rc = vxl_phantom_create(&pd, &v) || vxl_renderer_set_volume(r, v) || alloc_images(&s) ||
             vxl_reference_render(&pd, v, &s.p, s.ref, NULL);
        if (!rc) rc = run_study(csv, r, &s, steps, 4, frames);
        free_images(&s);
        vxl_volume_destroy(v);
    }
    /* ch2better against the ray caster's finest setting */
    vxl_volume *brain = NULL;
    if (!rc && !quick && vxl_volume_load(BRAIN, NULL, &brain) == VXL_OK) {
        study s = {.name = "ch2better", .reference = "voxlight cubic step 0.125", .p = base_params(size)};
        s.p.elevation_deg = 15;
        s.p.preset = VXL_PRESET_MRI;
        s.p.filter = VXL_FILTER_SOBEL8;
        s.p.jitter_off = 1;
        vxl_render_params rp = s.p;
        rp.filter = VXL_FILTER_CUBIC;
        rp.step = 0.125f;
        rc = vxl_renderer_set_volume(r, brain) || alloc_images(&s) || vxl_render(r, &rp, s.ref, NULL);
        /* the finest spacing is left to the phantom: ~1000 full-frame slices take minutes on llvmpipe */
        if (!rc) rc = run_study(csv, r, &s, steps, 3, frames);
        free_images(&s);
    } else if (!rc && !quick) {
        fprintf(stderr, "slicingbench: %s not loaded (%s): phantom only\n", BRAIN, vxl_last_error());
    }
    vxl_volume_destroy(brain);
    if (rc) fprintf(stderr, "slicingbench: failed: %s\n", vxl_renderer_error(r));
    vxl_renderer_destroy(r);
    fclose(csv);
    return rc;
}
