/* lighting_study.c - the numbers (docs/lighting.md): the cost
 * of the shadowed and scatter shading models on the ch2better brain
 * (cached illumination volume against a Phong frame, the rebuild after a
 * light move, the switch of the illumination grid a dragged light makes in
 * Blender), and run time against error on the two-blobs phantom, whose
 * double-precision reference (vxl_reference_render) casts real shadow rays,
 * occlusion rays and single scattering. Frame times are medians of warm
 * frames; a rebuild is the median frame that rebuilt the light's volume
 * minus the median cached frame, the two interleaved. Writes a CSV (bench/plot_lighting.py plots it). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "voxlight_dev.h"

#define BRAIN "/usr/share/mricron/templates/ch2better.nii.gz"

static int fail(vxl_renderer *r)
{
    fprintf(stderr, "%s\n", r ? vxl_renderer_error(r) : vxl_last_error());
    return 1;
}

static void set_light(vxl_render_params *p, float x, float y, float z, float w)
{
    memset(&p->lights[0], 0, sizeof p->lights[0]);
    p->lights[0].position[0] = x;
    p->lights[0].position[1] = y;
    p->lights[0].position[2] = z;
    p->lights[0].position[3] = w;
    p->light_count = 1;
}

/* A light move's cost: frames alternate between one whose light moved (two
 * positions, alternated; its stats must say the light's volume was rebuilt)
 * and the same frame again, cached, so load on the machine slows both
 * alike. *moved gets the median moved frame, *cached the median cached one;
 * -1 on failure. */
static int moving_light_ms(vxl_renderer *r, vxl_render_params *p, const float a[4], const float b[4], float *img,
                           int frames, double *moved, double *cached)
{
    double t[64], c[64];
    int n = 0;
    for (int i = 0; i < frames; i++) {
        const float *l = i % 2 ? a : b;
        set_light(p, l[0], l[1], l[2], l[3]);
        double s = now_ms();
        if (vxl_render(r, p, img, NULL)) return -1;
        double ms = now_ms() - s;
        vxl_render_stats st = {.struct_size = sizeof st};
        vxl_renderer_get_stats(r, &st);
        s = now_ms();
        if (vxl_render(r, p, img, NULL)) return -1;
        if (!st.illumination_rebuilt) continue;
        c[n] = now_ms() - s;
        t[n++] = ms;
    }
    if (!n) return -1;
    qsort(t, (size_t)n, sizeof *t, cmp_d);
    qsort(c, (size_t)n, sizeof *c, cmp_d);
    *moved = t[n / 2];
    *cached = c[n / 2];
    return 0;
}

/* One frame that switches the illumination grid to `to` cells (from
 * `from`), its light moved as a drag moves it: what a drag's first frame
 * (to < from) or its settling (to > from) costs. Median over `frames`
 * switches. */
static double switch_ms(vxl_renderer *r, vxl_render_params *p, uint32_t from, uint32_t to, float *img, int frames)
{
    double t[64];
    for (int i = 0; i < frames; i++) {
        p->illumination_size = from;
        set_light(p, 1, 0.3f + 0.01f * i, 0.5f, 0);
        if (vxl_render(r, p, img, NULL)) return -1;
        p->illumination_size = to;
        set_light(p, 1, 0.3f + 0.01f * i + 0.005f, 0.5f, 0);
        double s = now_ms();
        if (vxl_render(r, p, img, NULL)) return -1;
        t[i] = now_ms() - s;
    }
    qsort(t, (size_t)frames, sizeof *t, cmp_d);
    return t[frames / 2];
}

static void row(FILE *csv, const char *part, const char *config, uint32_t size, double frame, double rebuild,
                double rmse, double psnr_db)
{
    fprintf(stderr, "  %-10s %-28s size %3u  frame %8.1f ms  rebuild %8.1f ms  rmse %.5f  PSNR %5.1f dB\n", part,
            config, size, frame, rebuild, rmse, psnr_db);
    fprintf(csv, "%s,%s,%u,%.2f,%.2f,%.6f,%.2f\n", part, config, size, frame, rebuild, rmse, psnr_db);
}

/* ch2better at size^2: the cost table. */
static int brain(FILE *csv, uint32_t size, int frames)
{
    vxl_renderer *r = renderer_with_volume(BRAIN, "voxlight-lightbench");
    if (!r) return 1;
    float *img = malloc((size_t)size * size * 4 * sizeof *img);
    if (!img) return 1;
    vxl_render_params p = {.struct_size = sizeof p, .width = size, .height = size, .azimuth_deg = 30, .elevation_deg = 15};
    const float sun_a[4] = {1, 0.3f, 0.5f, 0}, sun_b[4] = {-0.3f, 1, 0.5f, 0};
    set_light(&p, sun_a[0], sun_a[1], sun_a[2], sun_a[3]);
    vxl_render_stats st = {.struct_size = sizeof st};
    int fails = 0;

    p.shading_model = VXL_SHADING_PHONG;
    const double phong = median_ms(r, &p, img, frames);
    row(csv, "ch2better", "phong", 0, phong, NAN, NAN, NAN);

    p.shading_model = VXL_SHADING_SHADOWED;
    const double shadowed = median_ms(r, &p, img, frames);
    vxl_renderer_get_stats(r, &st);
    row(csv, "ch2better", "shadowed-cached", st.illumination_size, shadowed, NAN, NAN, NAN);
    row(csv, "ch2better", "ratio-shadowed/phong", st.illumination_size, shadowed / phong, NAN, NAN, NAN);
    double moved = -1, cached = -1;
    fails += moving_light_ms(r, &p, sun_a, sun_b, img, frames < 3 ? 2 : frames, &moved, &cached) != 0;
    row(csv, "ch2better", "shadowed-sun-moved", st.illumination_size, moved, moved - cached, NAN, NAN);
    const float point_a[4] = {30, 20, 40, 1}, point_b[4] = {-30, 20, 40, 1};
    fails += moving_light_ms(r, &p, point_a, point_b, img, frames < 3 ? 2 : frames, &moved, &cached) != 0;
    row(csv, "ch2better", "shadowed-point-moved", st.illumination_size, moved, moved - cached, NAN, NAN);
    fails += phong < 0 || shadowed < 0;

    set_light(&p, sun_a[0], sun_a[1], sun_a[2], sun_a[3]);
    p.ambient_occlusion = 4;
    p.occlusion_strength = 0.5f;
    const double ao = median_ms(r, &p, img, frames);
    row(csv, "ch2better", "shadowed-ao4-cached", st.illumination_size, ao, NAN, NAN, NAN);
    p.shading_model = VXL_SHADING_SCATTER;
    p.anisotropy = 0.3f;
    const double scatter = median_ms(r, &p, img, frames);
    row(csv, "ch2better", "scatter-ao4-cached", st.illumination_size, scatter, NAN, NAN, NAN);
    fails += ao < 0 || scatter < 0;

    /* a transfer-function change: the extinction pass and the light's sweep */
    p.ambient_occlusion = 0;
    p.shading_model = VXL_SHADING_SHADOWED;
    double tf_change = 0, tf_cached = 0;
    for (int i = 0; i < 2; i++) { /* the second change is timed, then the same frame cached */
        p.opacity_scale = i ? 1.0f : 0.999f;
        double t0 = now_ms();
        fails += vxl_render(r, &p, img, NULL) != 0;
        tf_change = now_ms() - t0;
        t0 = now_ms();
        fails += vxl_render(r, &p, img, NULL) != 0;
        tf_cached = now_ms() - t0;
    }
    row(csv, "ch2better", "shadowed-tf-changed", st.illumination_size, tf_change, tf_change - tf_cached, NAN, NAN);

    /* Blender's drag at quality Medium (128) or High (256): each drag frame
     * sweeps the moved light at 64 instead, and the drag's first frame and
     * its settling switch the grid (the extinction grid is kept) */
    for (uint32_t from = 128; from <= 256; from *= 2) {
        char name[64];
        p.illumination_size = from;
        snprintf(name, sizeof name, "sun-moved-at-%u", from);
        double ms = -1, still = -1;
        fails += moving_light_ms(r, &p, sun_a, sun_b, img, frames < 3 ? 2 : 4, &ms, &still) != 0;
        row(csv, "ch2better", name, from, ms, ms - still, NAN, NAN);
        snprintf(name, sizeof name, "drag-start-%u-to-64", from);
        ms = switch_ms(r, &p, from, 64, img, frames < 3 ? 1 : 3);
        row(csv, "ch2better", name, 64, ms, NAN, NAN, NAN);
        snprintf(name, sizeof name, "drag-settle-64-to-%u", from);
        double back = switch_ms(r, &p, 64, from, img, frames < 3 ? 1 : 3);
        row(csv, "ch2better", name, from, back, NAN, NAN, NAN);
        fails += still < 0 || ms < 0 || back < 0;
    }
    if (fails) fprintf(stderr, "%s\n", vxl_renderer_error(r));
    free(img);
    vxl_renderer_destroy(r);
    return fails;
}

/* The two-blobs phantom at n^3, size^2 images: error against the reference. */
static int phantom(FILE *csv, uint32_t n, uint32_t size, int frames, int quick)
{
    vxl_phantom_desc d = {.struct_size = sizeof d, .kind = VXL_PHANTOM_TWO_BLOBS, .dims = {n, n, n}};
    vxl_volume *v = NULL;
    if (vxl_phantom_create(&d, &v)) return fail(NULL);
    const size_t px = (size_t)size * size * 4;
    float *img = malloc(2 * px * sizeof *img); /* our image, then the reference's */
    if (!img) return 1;
    float *ref = img + px;
    /* white blobs, opacity ramping to 0.8 per voxel over their edge (tests/test_shadows.c's scene) */
    const float tf[8] = {1, 1, 1, 0, 1, 1, 1, 0.8f};
    vxl_render_params p = {.struct_size = sizeof p, .width = size, .height = size, .azimuth_deg = 30,
                           .elevation_deg = 20, .tf_rgba = tf, .tf_size = 2, .has_window = 1, .window_low = 0.3f,
                           .window_high = 0.6f, .jitter_off = 1};
    set_light(&p, 1, 0.2f, 0.4f, 0); /* from the +x side: the +x blob shadows the other */
    const struct {
        const char *name;
        uint32_t model;
        float ao, g;
        uint32_t sizes[4];
    } cfgs[] = {
        {"phong", VXL_SHADING_PHONG, 0, 0, {0}},
        {"shadowed", VXL_SHADING_SHADOWED, 0, 0, {16, 32, 64, 128}},
        {"shadowed-ao4", VXL_SHADING_SHADOWED, 4, 0, {16, 32, 64, 128}},
        {"scatter-g0.3", VXL_SHADING_SCATTER, 0, 0.3f, {16, 32, 64, 128}},
    };
    int fails = 0;
    for (size_t c = 0; c < sizeof cfgs / sizeof *cfgs; c++) {
        p.shading_model = cfgs[c].model;
        p.ambient_occlusion = cfgs[c].ao;
        p.occlusion_strength = cfgs[c].ao > 0 ? 0.5f : 0;
        p.anisotropy = cfgs[c].g;
        double t0 = now_ms();
        if (vxl_reference_render(&d, v, &p, ref, NULL)) {
            fails += fail(NULL);
            continue;
        }
        fprintf(stderr, "  %s: reference in %.0f ms\n", cfgs[c].name, now_ms() - t0);
        for (int k = 0; k < 4 && (k == 0 || cfgs[c].sizes[k]); k++) {
            if (quick && k > 1) break;
            p.illumination_size = cfgs[c].sizes[k];
            /* a renderer per row: one that held a finer grid would keep its
             * extinction (illumination.h), and a row must show its size alone */
            vxl_renderer_options o = {.struct_size = sizeof o, .backend = VXL_BACKEND_OSMESA};
            vxl_renderer *r = NULL;
            if (vxl_renderer_create(&o, &r) || vxl_renderer_set_volume(r, v)) {
                fails += fail(r);
                vxl_renderer_destroy(r);
                continue;
            }
            /* the first frame builds; the light moves and back to time a rebuild */
            double frame = median_ms(r, &p, img, frames), moved = NAN, cached = NAN;
            const float away[4] = {1, 0.25f, 0.4f, 0}, here[4] = {1, 0.2f, 0.4f, 0};
            int rc = frame < 0;
            if (!rc && cfgs[c].model != VXL_SHADING_PHONG)
                rc = moving_light_ms(r, &p, away, here, img, frames < 3 ? 2 : 4, &moved, &cached);
            set_light(&p, here[0], here[1], here[2], here[3]);
            if (rc || vxl_render(r, &p, img, NULL)) {
                fails += fail(r);
                vxl_renderer_destroy(r);
                continue;
            }
            vxl_renderer_destroy(r);
            double e = 0;
            for (size_t i = 0; i < px; i++) e += ((double)img[i] - ref[i]) * ((double)img[i] - ref[i]);
            e = sqrt(e / px);
            row(csv, "blobs", cfgs[c].name, cfgs[c].sizes[k], frame, moved - cached, e, psnr(img, ref, px));
        }
    }
    vxl_volume_destroy(v);
    free(img);
    return fails;
}

int main(int argc, char **argv)
{
    uint32_t size = 512, n = 128, ref_size = 96;
    int frames = 5, quick = 0;
    const char *out = "bench/lighting.csv";
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) {
            size = 64;
            n = 24;
            ref_size = 24;
            frames = 1;
            quick = 1;
        } else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
        else return fprintf(stderr, "usage: voxlight-lightbench [--quick] [--out CSV]\n"), 2;
    }
    FILE *csv = fopen(out, "w");
    if (!csv) return perror(out), 1;
    fprintf(csv, "workload,config,illumination_size,frame_ms,rebuild_ms,rmse,psnr_db\n");
    int fails = brain(csv, size, frames);
    fails += phantom(csv, n, ref_size, frames, quick);
    fclose(csv);
    return fails != 0;
}
