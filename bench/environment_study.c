/* environment_study.c - what the World's light (vxl_environment) costs on
 * ch2better at size^2 (osmesa): a cached shadowed frame with one sun, the
 * same with an environment too, and with the environment alone (no lamp);
 * and what a rebuild of the irradiance volume adds (the map turned every
 * frame). Medians of warm frames, the two cached kinds interleaved over
 * `rounds` so load slows both alike. The map: a 128x64 sky, brighter
 * towards the zenith, with a small sun.
 *   voxlight-envbench [--size N] [--frames N] [--rounds N] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

#define BRAIN "/usr/share/mricron/templates/ch2better.nii.gz"
#define MW 128
#define MH 64

static int fail(vxl_renderer *r)
{
    fprintf(stderr, "voxlight-envbench: %s\n", r ? vxl_renderer_error(r) : vxl_last_error());
    return 1;
}

static void sky(float *rgb)
{
    for (int j = 0; j < MH; j++)
        for (int i = 0; i < MW; i++) {
            float up = (float)j / MH, *px = rgb + 3 * (j * MW + i);
            px[0] = 0.3f + 0.5f * up;
            px[1] = 0.4f + 0.5f * up;
            px[2] = 0.6f + 0.6f * up;
            if (abs(i - 40) < 2 && abs(j - 48) < 2) px[0] = px[1] = px[2] = 200.0f;
        }
}

int main(int argc, char **argv)
{
    uint32_t size = 512;
    int frames = 5, rounds = 3;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--size")) size = (uint32_t)atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--frames")) frames = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--rounds")) rounds = atoi(argv[i + 1]);
    }
    if (size < 16 || frames < 1 || frames > 64 || rounds < 1) {
        fprintf(stderr, "usage: voxlight-envbench [--size N] [--frames 1..64] [--rounds N]\n");
        return 2;
    }
    vxl_renderer *r = renderer_with_volume(BRAIN, "voxlight-envbench");
    if (!r) return 1;
    float *img = malloc((size_t)size * size * 4 * sizeof *img), *map = malloc(MW * MH * 3 * sizeof *map);
    if (!img || !map) return 1;
    sky(map);
    vxl_render_params p = {.struct_size = sizeof p, .width = size, .height = size, .azimuth_deg = 30,
                           .elevation_deg = 15, .shading_model = VXL_SHADING_SHADOWED, .light_count = 1};
    const float sun[4] = {1, 0.3f, 0.5f, 0};
    memcpy(p.lights[0].position, sun, sizeof sun);
    vxl_environment env = {.struct_size = sizeof env, .width = MW, .height = MH, .rgb = map, .strength = 1};

    double plain = 1e30, lit = 1e30, alone = 1e30;
    for (int k = 0; k < rounds; k++) { /* the best round's medians: the least disturbed */
        p.environment = NULL;
        p.light_count = 1;
        double a = median_ms(r, &p, img, frames);
        p.environment = &env;
        double b = median_ms(r, &p, img, frames);
        p.light_count = 0;
        double c = median_ms(r, &p, img, frames);
        if (a < 0 || b < 0 || c < 0) return fail(r);
        plain = a < plain ? a : plain;
        lit = b < lit ? b : lit;
        alone = c < alone ? c : alone;
    }
    /* a rebuild: the map turns every frame (the reduction and the irradiance volume) */
    p.light_count = 1;
    double t[64];
    for (int i = 0; i < frames; i++) {
        env.rotation_deg = 10.0f * (float)(i + 1);
        double s = now_ms();
        if (vxl_render(r, &p, img, NULL)) return fail(r);
        t[i] = now_ms() - s;
    }
    qsort(t, (size_t)frames, sizeof *t, cmp_d);
    const double turned = t[frames / 2];
    vxl_render_stats st = {.struct_size = sizeof st};
    vxl_renderer_get_stats(r, &st);
    printf("| frame | illumination size | ms |\n|---|---|---|\n");
    printf("| shadowed-cached (one sun) | %u | %.1f |\n", st.illumination_size, plain);
    printf("| shadowed-cached, sun + environment | %u | %.1f |\n", st.illumination_size, lit);
    printf("| shadowed-cached, environment alone | %u | %.1f |\n", st.illumination_size, alone);
    printf("| environment turned every frame | %u | %.1f |\n", st.illumination_size, turned);
    printf("\nenvironment over a cached shadowed frame: %.2fx (alone %.2fx); irradiance rebuild %.1f ms\n",
           lit / plain, alone / plain, turned - lit);
    free(img);
    free(map);
    vxl_renderer_destroy(r);
    return 0;
}
