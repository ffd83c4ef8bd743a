/* overlays_study.c - frame time against the number of overlays
 * (docs/overlays.md "Measured"): a 128^3 sphere phantom drawn alone (the
 * baseline), then with 1, 2 and 3 overlays, each a 96^3 Gaussian blob on its
 * own grid (scaled, turned and shifted so the boxes overlap the base's and
 * each other's), blended OVER, MAX and ADD in turn, linear and cubic, with
 * empty-space skipping on (the union of occupancies) and off. Prints the
 * median frame time and its ratio to the baseline; the times mean nothing
 * on a loaded machine. Command:
 *   make -j1 build/voxlight-overlaysbench && ./build/voxlight-overlaysbench [--size 512] [--frames 5] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "voxlight_dev.h"

#define N 128
#define M 96

/* Overlay k: the blob phantom with the base's affine, scaled by 1.1 - 0.1 k
 * about its centre, turned by 20 (k + 1) degrees about z and shifted. */
static vxl_volume *overlay_volume(const vxl_volume *base, int k)
{
    vxl_volume_info bi = {.struct_size = sizeof bi};
    vxl_volume_get_info(base, &bi);
    /* voxel -> base voxel (centre on centre, scaled, turned, shifted by k * 10 voxels), then the base's affine */
    const double s = (double)N / M * (1.1 - 0.1 * k), a = 20.0 * (k + 1) * M_PI / 180, c = (M - 1) / 2.0, cb = (N - 1) / 2.0;
    const double m[16] = {s * cos(a), s * sin(a), 0, 0, -s * sin(a), s * cos(a), 0, 0, 0, 0, s, 0,
                          cb - s * c * (cos(a) - sin(a)) + 10 * k, cb - s * c * (sin(a) + cos(a)) - 8 * k, cb - s * c, 1};
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_F32, .dims = {M, M, M}, .has_affine = 1};
    for (int col = 0; col < 4; col++)
        for (int r = 0; r < 4; r++) {
            d.affine[col * 4 + r] = 0;
            for (int j = 0; j < 4; j++) d.affine[col * 4 + r] += bi.affine[j * 4 + r] * m[col * 4 + j];
        }
    float *data = malloc((size_t)M * M * M * sizeof *data);
    if (!data) return NULL;
    for (uint32_t z = 0; z < M; z++)
        for (uint32_t y = 0; y < M; y++)
            for (uint32_t x = 0; x < M; x++) {
                double u = (x + 0.5) / M - 0.5, w = (y + 0.5) / M - 0.5, t = (z + 0.5) / M - 0.5;
                double r2 = u * u + w * w + t * t;
                data[x + M * (y + (size_t)M * z)] = (float)exp(-r2 / (2 * 0.15 * 0.15));
            }
    d.data = data;
    vxl_volume *out = NULL;
    int rc = vxl_volume_create(&d, NULL, &out);
    free(data);
    return rc ? NULL : out;
}

/* --size S --frames F; 0 on anything else or out of range. */
static int parse_args(int argc, char **argv, uint32_t *size, int *frames)
{
    for (int i = 1; i < argc; i++) {
        const int has_value = i + 1 < argc;
        if (has_value && !strcmp(argv[i], "--size")) *size = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (has_value && !strcmp(argv[i], "--frames")) *frames = (int)strtol(argv[++i], NULL, 10);
        else return 0;
    }
    return *size >= 16 && *size <= 4096 && *frames >= 1 && *frames <= 64;
}

/* A default renderer holding the 128^3 sphere phantom (*vol keeps it for its affine). */
static vxl_renderer *sphere_renderer(vxl_volume **vol)
{
    const vxl_renderer_options o = {.struct_size = sizeof o};
    const vxl_phantom_desc ph = {.struct_size = sizeof ph, .kind = VXL_PHANTOM_SPHERE, .dims = {N, N, N}};
    vxl_renderer *r = NULL;
    *vol = NULL;
    if (!vxl_renderer_create(&o, &r) && !vxl_phantom_create(&ph, vol) && !vxl_renderer_set_volume(r, *vol)) return r;
    vxl_renderer_destroy(r);
    return NULL;
}

int main(int argc, char **argv)
{
    uint32_t size = 512;
    int frames = 5;
    if (!parse_args(argc, argv, &size, &frames)) {
        fprintf(stderr, "usage: voxlight-overlaysbench [--size 16..4096] [--frames 1..64]\n");
        return 2;
    }
    vxl_volume *vol;
    vxl_renderer *r = sphere_renderer(&vol);
    if (!r) {
        fprintf(stderr, "voxlight-overlaysbench: %s\n", vxl_last_error());
        vxl_volume_destroy(vol);
        return 1;
    }
    float *img = malloc((size_t)size * size * 4 * sizeof *img);
    if (!img) return 1;
    int rc = 0;
    for (int k = 0; k < VXL_MAX_OVERLAYS && !rc; k++) {
        vxl_volume *ov = overlay_volume(vol, k);
        rc = !ov || vxl_renderer_set_overlay(r, (uint32_t)k, ov);
        vxl_volume_destroy(ov);
    }
    static const uint32_t blends[VXL_MAX_OVERLAYS] = {VXL_BLEND_OVER, VXL_BLEND_MAX, VXL_BLEND_ADD};
    vxl_overlay_style s[VXL_MAX_OVERLAYS];
    for (int k = 0; k < VXL_MAX_OVERLAYS; k++)
        s[k] = (vxl_overlay_style){.struct_size = sizeof s[k], .slot = (uint32_t)k, .blend = blends[k],
                                   .preset = VXL_PRESET_HOT, .has_window = 1, .window_low = 0.3f, .window_high = 1.0f};
    vxl_render_params p = base_params(size);
    p.preset = VXL_PRESET_BONE;
    double base = rc ? -1 : median_ms(r, &p, img, frames);
    rc = base < 0;
    if (!rc)
        printf("| overlays | interpolation | skipping | frame ms | x base alone |\n|---|---|---|---|---|\n"
               "| 0 | - | on | %.1f | 1.00 |\n", base);
    for (uint32_t interp = VXL_INTERP_LINEAR; interp <= VXL_INTERP_CUBIC && !rc; interp++)
        for (uint32_t skip_off = 0; skip_off < 2 && !rc; skip_off++)
            for (uint32_t n = 1; n <= VXL_MAX_OVERLAYS && !rc; n++) {
                for (int k = 0; k < VXL_MAX_OVERLAYS; k++) {
                    s[k].interpolation = interp;
                    s[k].interpolation_set = 1;
                }
                p.overlay_count = n;
                p.overlays = s;
                p.no_skip = skip_off;
                double t = median_ms(r, &p, img, frames);
                if (t < 0) rc = 1;
                else printf("| %u | %s | %s | %.1f | %.2f |\n", n, interp == VXL_INTERP_CUBIC ? "cubic" : "linear",
                            skip_off ? "off" : "on", t, t / base);
            }
    if (rc) fprintf(stderr, "voxlight-overlaysbench: %s\n", vxl_renderer_error(r));
    free(img);
    vxl_volume_destroy(vol);
    vxl_renderer_destroy(r);
    return rc;
}
