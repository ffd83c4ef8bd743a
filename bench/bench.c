/* bench.c - run time against error. Times every combination of filter,
 * sampleDistance, step, reuseGradients and backend on analytic phantoms and
 * the ch2better brain, and measures each against ground truth: the analytic
 * reference renderer for phantoms, the finest own setting for real data.
 * Writes one CSV row per configuration; bench/plot.py makes the figure. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "voxlight_dev.h"

#define BRAIN "/usr/share/mricron/templates/ch2better.nii.gz"
#define MAX_CONFIGS 4096

static const int taps[VXL_FILTER_COUNT] = {6, 3, 8, 14, 26, 1, 24}; /* gradient fetches per sample */

typedef struct options {
    int quick;
    uint32_t size, frames;
    const char *csv, *scene_dir;
    uint32_t backends[2];
    int n_backends;
    int spike_only; /* the classification study (and table timings) alone */
} options;

typedef struct workload {
    const char *name;
    int phantom;                 /* 0 = ch2better */
    vxl_phantom_desc pd;
    vxl_volume *vol;
    float *ref;                  /* reference image, size*size*4 */
    float ang_mean[VXL_FILTER_COUNT][3], ang_p95[VXL_FILTER_COUNT][3];
} workload;

static const float sample_distances[3] = {0.5f, 1.0f, 1.5f};
static const float steps_full[3] = {1.0f, 0.5f, 0.25f};

/* Classification per workload: phantoms show their 0.5 iso-region with the
 * bone preset; the brain uses the MRI default. */
static void classify_for(const workload *w, vxl_render_params *p)
{
    if (w->phantom) {
        p->preset = VXL_PRESET_BONE;
        p->has_window = 1;
        p->window_low = 0.35f;
        p->window_high = 0.75f;
    } else {
        p->preset = VXL_PRESET_MRI;
    }
}

static void image_error(const float *a, const float *b, size_t n, double *rmse, double *psnr, double *maxabs)
{
    double s = 0, m = 0;
    for (size_t i = 0; i < n; i++) {
        double d = fabs((double)a[i] - b[i]);
        s += d * d;
        m = d > m ? d : m;
    }
    *rmse = sqrt(s / n);
    *psnr = *rmse > 0 ? 20 * log10(1 / *rmse) : 200;
    *maxabs = m;
}

static double angle(const float *a, const double *b)
{
    double la = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
    double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    if (!(la > 0) || !(lb > 0)) return 180;
    double c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
    return acos(c > 1 ? 1 : c < -1 ? -1 : c) * 180 / M_PI;
}

/* Angular error of every filter and sampleDistance through the shader. */
static int measure_gradients(vxl_renderer *r, workload *w)
{
    enum { MAXP = 4000 };
    static float pts[3 * MAXP], g[3 * MAXP];
    static double truth[3 * MAXP], err[MAXP];
    uint32_t n = 0;
    double iso = w->pd.kind == VXL_PHANTOM_NOISY_BLOB ? 0.5 : 0.5;
    if (vxl_phantom_iso_points(&w->pd, iso, 0.01, 42, pts, MAXP, &n) || n < 100) return 1;
    for (uint32_t i = 0; i < n; i++) {
        double q[3] = {pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]}, v;
        vxl_phantom_eval(&w->pd, q, &v, truth + 3 * i);
    }
    for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++)
        for (int k = 0; k < 3; k++) {
            vxl_render_params p = base_params(1);
            p.filter = f;
            p.sample_distance = sample_distances[k];
            if (vxl_probe_gradients(r, &p, pts, n, g)) return 1;
            double sum = 0;
            for (uint32_t i = 0; i < n; i++) sum += err[i] = angle(g + 3 * i, truth + 3 * i);
            qsort(err, n, sizeof *err, cmp_d);
            w->ang_mean[f][k] = (float)(sum / n);
            w->ang_p95[f][k] = (float)err[(size_t)(0.95 * (n - 1))];
        }
    return 0;
}

static int load_workload(workload *w, vxl_renderer *r, const options *o)
{
    if (w->phantom) {
        if (vxl_phantom_create(&w->pd, &w->vol)) return 1;
    } else if (vxl_volume_load(BRAIN, NULL, &w->vol)) {
        return 1;
    }
    if (vxl_renderer_set_volume(r, w->vol)) return 1;
    size_t n = (size_t)o->size * o->size * 4;
    w->ref = malloc(n * sizeof *w->ref);
    if (!w->ref) return 1;
    vxl_render_params p = base_params(o->size);
    classify_for(w, &p);
    double t = now_ms();
    if (w->phantom) {
        if (vxl_reference_render(&w->pd, w->vol, &p, w->ref, NULL)) return 1;
        if (measure_gradients(r, w)) return 1;
    } else {
        /* No analytic field: the finest own setting, labelled in the docs. */
        p.filter = VXL_FILTER_CUBIC;
        p.step = 0.125f;
        p.jitter_off = 1;
        if (vxl_render(r, &p, w->ref, NULL)) return 1;
    }
    fprintf(stderr, "bench: %s reference in %.1f s\n", w->name, (now_ms() - t) / 1e3);
    return 0;
}

/* Dumps what the VTK peer needs to match our frame honestly. */
static void write_scene(const options *o, const workload *w, vxl_renderer *r, const vxl_render_params *p,
                        const float *img)
{
    char path[512];
    snprintf(path, sizeof path, "%s/scene_%s.json", o->scene_dir, w->name);
    FILE *f = fopen(path, "w");
    if (!f) return;
    float view[16], proj[16];
    vxl_default_camera(r, p, view, proj);
    vxl_volume_info in = {.struct_size = sizeof in};
    vxl_volume_get_info(w->vol, &in);
    fprintf(f, "{\n  \"workload\": \"%s\",\n  \"volume\": \"%s\",\n  \"width\": %u, \"height\": %u,\n", w->name,
            w->phantom ? "" : BRAIN, p->width, p->height);
    fprintf(f, "  \"view\": [");
    for (int i = 0; i < 16; i++) fprintf(f, "%s%.9g", i ? ", " : "", view[i]);
    fprintf(f, "],\n  \"proj\": [");
    for (int i = 0; i < 16; i++) fprintf(f, "%s%.9g", i ? ", " : "", proj[i]);
    fprintf(f, "],\n  \"affine\": [");
    for (int i = 0; i < 16; i++) fprintf(f, "%s%.9g", i ? ", " : "", in.affine[i]);
    fprintf(f, "],\n  \"dims\": [%u, %u, %u],\n  \"value_min\": %.9g, \"value_max\": %.9g,\n", in.dims[0], in.dims[1],
            in.dims[2], in.value_min, in.value_max);
    fprintf(f, "  \"preset\": \"%s\",\n  \"step_voxels\": %g,\n  \"filter\": \"%s\",\n", vxl_preset_name(p->preset),
            p->step ? p->step : 0.5, vxl_filter_name(p->filter));
    fprintf(f, "  \"material\": [0.3, 0.7, 0.3, 24],\n  \"light\": \"headlight\",\n");
    fprintf(f, "  \"reference_image\": \"ref_%s.f32\",\n  \"voxlight_image\": \"voxlight_%s.f32\"\n}\n", w->name, w->name);
    fclose(f);
    size_t n = (size_t)p->width * p->height * 4;
    snprintf(path, sizeof path, "%s/ref_%s.f32", o->scene_dir, w->name);
    if ((f = fopen(path, "wb"))) { fwrite(w->ref, sizeof(float), n, f); fclose(f); }
    snprintf(path, sizeof path, "%s/voxlight_%s.f32", o->scene_dir, w->name);
    if ((f = fopen(path, "wb"))) { fwrite(img, sizeof(float), n, f); fclose(f); }
}

static int run_config(FILE *csv, const options *o, workload *w, vxl_renderer *r, const char *backend,
                      vxl_render_params *p, float *img, int sd_index)
{
    uint32_t frames = o->frames;
    double ms = median_ms(r, p, img, (int)frames);
    if (ms < 0) {
        fprintf(stderr, "bench: %s: %s\n", w->name, vxl_renderer_error(r));
        return 1;
    }
    vxl_render_stats st = {.struct_size = sizeof st};
    vxl_renderer_get_stats(r, &st);
    double rmse, psnr, maxabs;
    image_error(img, w->ref, (size_t)o->size * o->size * 4, &rmse, &psnr, &maxabs);
    int sd_applies = p->filter != VXL_FILTER_PRECOMPUTED && p->filter != VXL_FILTER_CUBIC;
    fprintf(csv, "%s,%s,", w->name, vxl_filter_name(p->filter));
    if (sd_applies) fprintf(csv, "%g", p->sample_distance);
    fprintf(csv, ",%g,%u,post,%s,voxlight,%.2f,%d,", p->step, p->reuse_gradients, backend, ms,
            1 + taps[p->filter]);
    if (w->phantom) fprintf(csv, "%.3f,%.3f", w->ang_mean[p->filter][sd_index], w->ang_p95[p->filter][sd_index]);
    else fprintf(csv, ",");
    fprintf(csv, ",%.6f,%.2f,%.5f,%ux%u,%u,%llu,%s\n", rmse, psnr, maxabs, o->size, o->size, frames,
            (unsigned long long)st.samples, w->phantom ? "analytic" : "voxlight cubic step 0.125");
    fflush(csv);
    return 0;
}

static int run_workload(FILE *csv, const options *o, workload *w)
{
    float *img = malloc((size_t)o->size * o->size * 4 * sizeof *img);
    int rc = 0;
    for (int b = 0; b < o->n_backends && !rc; b++) {
        vxl_renderer_options ro = {.struct_size = sizeof ro, .backend = o->backends[b]};
        vxl_renderer *r = NULL;
        if (vxl_renderer_create(&ro, &r)) {
            fprintf(stderr, "bench: backend %u unavailable: %s\n", o->backends[b], vxl_last_error());
            continue;
        }
        vxl_renderer_info info = {.struct_size = sizeof info};
        vxl_renderer_get_info(r, &info);
        if (!w->ref && load_workload(w, r, o)) {
            fprintf(stderr, "bench: cannot prepare %s: %s\n", w->name, vxl_last_error());
            vxl_renderer_destroy(r);
            free(img);
            return 1;
        }
        if (w->ref && vxl_renderer_set_volume(r, w->vol)) rc = 1;
        int n_steps = o->quick ? 1 : 3;
        for (uint32_t f = 0; f < VXL_FILTER_COUNT && !rc; f++) {
            int n_sd = (o->quick || f == VXL_FILTER_PRECOMPUTED || f == VXL_FILTER_CUBIC) ? 1 : 3;
            for (int k = 0; k < n_sd && !rc; k++)
                for (int s = 0; s < n_steps && !rc; s++)
                    for (uint32_t reuse = 0; reuse < (o->quick ? 1u : 2u) && !rc; reuse++) {
                        vxl_render_params p = base_params(o->size);
                        classify_for(w, &p);
                        p.filter = f;
                        int sdi = o->quick ? 1 : (n_sd == 1 ? 1 : k);
                        p.sample_distance = sample_distances[sdi];
                        p.step = o->quick ? 0.5f : steps_full[s];
                        p.reuse_gradients = reuse;
                        rc = run_config(csv, o, w, r, info.backend_name, &p, img, sdi);
                        if (!rc && b == 0 && f == VXL_FILTER_CENTRAL && sdi == 1 && p.step == 0.5f && !reuse)
                            write_scene(o, w, r, &p, img);
                    }
        }
        vxl_renderer_destroy(r);
    }
    free(img);
    return rc;
}

/* A thin opacity spike on the sphere phantom: the high-frequency transfer
 * function where classification modes differ. Post, pre and pre-integrated
 * classification across steps, against the analytic reference. */
static int run_spike_study(FILE *csv, const options *o)
{
    enum { NTF = 256 };
    static float tf[NTF * 4];
    for (int i = 0; i < NTF; i++) {
        double x = i / (NTF - 1.0);
        tf[4 * i + 0] = (float)(0.4 + 0.6 * x);
        tf[4 * i + 1] = (float)(0.9 - 0.5 * x);
        tf[4 * i + 2] = 0.5f;
        tf[4 * i + 3] = (float)(0.8 * exp(-0.5 * pow((x - 0.5) / 0.02, 2)));
    }
    vxl_phantom_desc pd = {sizeof pd, VXL_PHANTOM_SPHERE, {64, 64, 64}, 0, 0};
    vxl_volume *v = NULL;
    vxl_renderer *r = NULL;
    size_t n = (size_t)o->size * o->size * 4;
    float *ref = malloc(n * sizeof *ref), *img = malloc(n * sizeof *img);
    int rc = !ref || !img || vxl_phantom_create(&pd, &v) || vxl_renderer_create(NULL, &r) || vxl_renderer_set_volume(r, v);
    vxl_render_params p = base_params(o->size);
    p.tf_rgba = tf;
    p.tf_size = NTF;
    p.has_window = 1;
    p.window_low = 0.42f;
    p.window_high = 0.62f;
    p.shading_off = 1;
    if (!rc) rc = vxl_reference_render(&pd, v, &p, ref, NULL);
    const float steps[5] = {2.0f, 1.0f, 0.5f, 0.25f, 0.125f};
    const char *modes[VXL_CLASSIFY_COUNT] = {"post", "pre", "preint"};
    vxl_renderer_info info = {.struct_size = sizeof info};
    if (!rc) vxl_renderer_get_info(r, &info);
    for (uint32_t m = 0; m < VXL_CLASSIFY_COUNT && !rc; m++)
        for (int s = 0; s < (o->quick ? 3 : 5) && !rc; s++) {
            p.classify = m;
            p.step = steps[s];
            double ms = median_ms(r, &p, img, (int)o->frames);
            if (ms < 0) {
                rc = 1;
                break;
            }
            double rmse, psnr, maxabs;
            image_error(img, ref, n, &rmse, &psnr, &maxabs);
            fprintf(csv, "spike64,central,,%g,0,%s,%s,voxlight,%.2f,1,,,%.6f,%.2f,%.5f,%ux%u,%u,,analytic\n", p.step,
                    modes[m], info.backend_name, ms, rmse, psnr, maxabs, o->size, o->size, o->frames);
        }
    if (rc) fprintf(stderr, "bench: spike study: %s\n", vxl_last_error());
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
    free(ref);
    free(img);
    return rc;
}

/* Rebuild time of the pre-integration table, the cost of every transfer
 * function edit in PREINT mode. */
static void time_preint_tables(const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) return;
    float tf[256 * 4];
    for (int i = 0; i < 256; i++)
        for (int c = 0; c < 4; c++) tf[4 * i + c] = (float)(0.5 + 0.5 * sin(i * 0.1 + c));
    fprintf(f, "table_size,ms_median\n");
    const uint32_t sizes[2] = {256, 1024};
    for (int k = 0; k < 2; k++) {
        float *out = malloc((size_t)sizes[k] * sizes[k] * 4 * sizeof *out);
        double t[7];
        for (int i = 0; i < 7 && out; i++) {
            double t0 = now_ms();
            vxl_preint_table(tf, 256, 1, 0.5f, sizes[k], out);
            t[i] = now_ms() - t0;
        }
        qsort(t, 7, sizeof *t, cmp_d);
        if (out) fprintf(f, "%u,%.2f\n", sizes[k], t[3]);
        free(out);
    }
    fclose(f);
}

int main(int argc, char **argv)
{
    options o = {.quick = 0, .size = 512, .frames = 5, .csv = "bench/results.csv", .scene_dir = "bench/out",
                 .backends = {VXL_BACKEND_OSMESA, VXL_BACKEND_EGL}, .n_backends = 2};
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) { o.quick = 1; o.size = 64; o.frames = 3; o.n_backends = 1; }
        else if (!strcmp(argv[i], "--full")) o.quick = 0;
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) o.csv = argv[++i];
        else if (!strcmp(argv[i], "--scene-dir") && i + 1 < argc) o.scene_dir = argv[++i];
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) o.size = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) o.frames = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--osmesa-only")) o.n_backends = 1;
        else if (!strcmp(argv[i], "--spike-only")) o.spike_only = 1;
        else {
            fprintf(stderr, "usage: voxlight-bench [--quick|--full] [--out CSV] [--scene-dir DIR] [--size N] [--frames N] "
                            "[--osmesa-only] [--spike-only]\n");
            return 2;
        }
    }
    if (o.size < 8 || o.size > 4096 || o.frames < 1 || o.frames > 64) {
        fprintf(stderr, "bench: --size must be 8..4096 and --frames 1..64\n");
        return 2;
    }
    workload w[4];
    memset(w, 0, sizeof w);
    w[0] = (workload){.name = "ml64", .phantom = 1, .pd = {sizeof(vxl_phantom_desc), VXL_PHANTOM_MARSCHNER_LOBB, {64, 64, 64}, 0, 0}};
    w[1] = (workload){.name = "ml41", .phantom = 1, .pd = {sizeof(vxl_phantom_desc), VXL_PHANTOM_MARSCHNER_LOBB, {41, 41, 41}, 0, 0}};
    w[2] = (workload){.name = "noisy64", .phantom = 1, .pd = {sizeof(vxl_phantom_desc), VXL_PHANTOM_NOISY_BLOB, {64, 64, 64}, 7, 0.05}};
    w[3] = (workload){.name = "ch2better", .phantom = 0};
    FILE *csv = fopen(o.csv, "w");
    if (!csv) {
        perror(o.csv);
        return 1;
    }
    fprintf(csv, "workload,filter,sample_distance,step,reuse_gradients,classify,backend,renderer,ms_median,"
                 "fetches_per_sample,ang_mean_deg,ang_p95_deg,rmse,psnr_db,max_abs,size,frames,samples,reference\n");
    char preint_path[512];
    snprintf(preint_path, sizeof preint_path, "%s/preint_timing.csv", o.scene_dir);
    time_preint_tables(preint_path);
    int rc = run_spike_study(csv, &o);
    for (int i = 0; i < 4 && !rc && !o.spike_only; i++) {
        double t = now_ms();
        rc = run_workload(csv, &o, &w[i]);
        fprintf(stderr, "bench: %s done in %.1f s\n", w[i].name, (now_ms() - t) / 1e3);
        vxl_volume_destroy(w[i].vol);
        free(w[i].ref);
    }
    fclose(csv);
    return rc;
}
