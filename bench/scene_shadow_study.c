/* scene_shadow_study.c - the cost of scene shadows
 * (docs/scene_shadows.md): the ch2better brain at size^2 in the shadowed
 * model with one sun, and a tessellated sphere of `triangles` triangles
 * between the sun and the brain plus a floor under it as the scene's
 * occluders. Medians of warm frames:
 *   off            the frame without scene_shadows (illumination cached)
 *   on-cached      the same frame with the occluders, their key unchanged
 *   on-hashed      the same with key 0: the library hashes the arrays each frame
 *   mesh-moved     a frame after the sphere moved (new key): the occluders
 *                  uploaded, the sun's map rasterised, its volume swept and
 *                  cut; rebuild_ms is that minus the cached frame, the two
 *                  interleaved so load slows both alike
 *   transmittance  vxl_scene_transmittance of the cached frame, with the
 *                  frame's own depth as the scene (+inf -> a backdrop), so
 *                  every pixel's path is traced
 * Prints a table (and --out CSV). Never run it while others build: the
 * numbers are for a quiet machine. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

#define BRAIN "/usr/share/mricron/templates/ch2better.nii.gz"

typedef struct mesh {
    float *v;
    uint32_t *idx;
    uint32_t nv, nt;
} mesh;

/* A UV sphere of about `triangles` triangles (radius r at c), then a floor
 * quad at height floor_z, in one array pair. */
static int build_mesh(mesh *m, uint32_t triangles, const double c[3], double r, double floor_z)
{
    uint32_t n = (uint32_t)ceil(sqrt(triangles / 2.0)); /* rings = segments = n: 2 n^2 triangles */
    if (n < 3) n = 3;
    m->nv = (n + 1) * (n + 1) + 4;
    m->nt = 2 * n * n + 2;
    m->v = malloc((size_t)m->nv * 3 * sizeof *m->v);
    m->idx = malloc((size_t)m->nt * 3 * sizeof *m->idx);
    if (!m->v || !m->idx) return 1;
    uint32_t k = 0, t = 0;
    for (uint32_t i = 0; i <= n; i++)
        for (uint32_t j = 0; j <= n; j++) {
            double th = M_PI * i / n, ph = 2 * M_PI * j / n;
            m->v[k++] = (float)(c[0] + r * sin(th) * cos(ph));
            m->v[k++] = (float)(c[1] + r * sin(th) * sin(ph));
            m->v[k++] = (float)(c[2] + r * cos(th));
        }
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = 0; j < n; j++) {
            uint32_t a = i * (n + 1) + j, b = a + n + 1;
            const uint32_t q[6] = {a, b, a + 1, a + 1, b, b + 1};
            memcpy(m->idx + t, q, sizeof q);
            t += 6;
        }
    const float fl[12] = {-400, -400, (float)floor_z, 400, -400, (float)floor_z, 400, 400, (float)floor_z, -400, 400, (float)floor_z};
    memcpy(m->v + k, fl, sizeof fl);
    const uint32_t base = (n + 1) * (n + 1), q[6] = {base, base + 1, base + 2, base, base + 2, base + 3};
    memcpy(m->idx + t, q, sizeof q);
    return 0;
}

static void row(FILE *csv, const char *config, uint32_t triangles, double ms, double rebuild)
{
    printf("%-14s %9u %10.2f %10.2f\n", config, triangles, ms, rebuild);
    if (csv) fprintf(csv, "%s,%u,%.3f,%.3f\n", config, triangles, ms, rebuild);
}

/* Median transmittance pass over `frames` calls, after one warm-up. */
static double transmittance_ms(vxl_renderer *r, const vxl_render_params *p, float *out, int frames)
{
    double t[64];
    if (vxl_scene_transmittance(r, p, 0, out)) return -1;
    for (int i = 0; i < frames; i++) {
        double s = now_ms();
        if (vxl_scene_transmittance(r, p, 0, out)) return -1;
        t[i] = now_ms() - s;
    }
    qsort(t, (size_t)frames, sizeof *t, cmp_d);
    return t[frames / 2];
}

int main(int argc, char **argv)
{
    uint32_t size = 512, triangles = 300000, map = 1024;
    int frames = 5;
    const char *out = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) {
            size = 96;
            triangles = 20000;
            frames = 1;
        } else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--triangles") && i + 1 < argc) triangles = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--map") && i + 1 < argc) map = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
        else
            return fprintf(stderr, "usage: voxlight-sceneshadowbench [--quick] [--size S] [--triangles N] [--map M] "
                                   "[--frames F] [--out CSV]\n"), 2;
    }
    if (frames < 1 || frames > 64 || size < 16 || size > 4096) return fprintf(stderr, "bad --frames or --size\n"), 2;
    vxl_volume *v = NULL;
    if (vxl_volume_load(BRAIN, NULL, &v)) return fprintf(stderr, "%s\n", vxl_last_error()), 1;
    vxl_renderer_options o = {.struct_size = sizeof o, .backend = VXL_BACKEND_OSMESA};
    vxl_renderer *r = NULL;
    if (vxl_renderer_create(&o, &r) || vxl_renderer_set_volume(r, v))
        return fprintf(stderr, "%s\n", r ? vxl_renderer_error(r) : vxl_last_error()), 1;
    vxl_volume_info info = {.struct_size = sizeof info};
    vxl_volume_get_info(v, &info);
    vxl_volume_destroy(v);
    /* the brain's world centre, and a sphere of a quarter of its size towards the sun */
    double centre[3], half = 0;
    for (int a = 0; a < 3; a++) {
        centre[a] = info.affine[12 + a];
        for (int b = 0; b < 3; b++) centre[a] += info.affine[4 * b + a] * 0.5 * (info.dims[b] - 1);
        half = fmax(half, 0.5 * info.dims[a] * fabs(info.affine[5 * a]));
    }
    const float sun[3] = {0.4f, 0.2f, 0.9f};
    const double len = sqrt(sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]);
    double sc[3];
    for (int a = 0; a < 3; a++) sc[a] = centre[a] + sun[a] / len * 1.6 * half;
    mesh m;
    if (build_mesh(&m, triangles, sc, 0.35 * half, centre[2] - 1.2 * half)) return fprintf(stderr, "out of memory\n"), 1;

    float *img = malloc((size_t)size * size * 4 * sizeof *img), *depth = malloc((size_t)size * size * sizeof *depth);
    if (!img || !depth) return 1;
    vxl_render_params p = base_params(size);
    p.shading_model = VXL_SHADING_SHADOWED;
    p.light_count = 1;
    memcpy(p.lights[0].position, sun, sizeof sun);
    vxl_scene_shadows s = {.struct_size = sizeof s, .occluder_vertex_count = m.nv, .occluder_vertices = m.v,
                           .occluder_indices = m.idx, .occluder_triangle_count = m.nt, .shadow_map_size = map,
                           .occluder_key = 1};
    FILE *csv = out ? fopen(out, "w") : NULL;
    if (out && !csv) return perror(out), 1;
    if (csv) fprintf(csv, "config,triangles,frame_ms,rebuild_ms\n");
    printf("ch2better %ux%u, shadowed, one sun, map %u^2 (medians of %d frames)\n", size, size, map, frames);
    printf("%-14s %9s %10s %10s\n", "config", "triangles", "frame_ms", "rebuild_ms");
    int fails = 0;

    const double off = median_ms(r, &p, img, frames);
    row(csv, "off", 0, off, NAN);
    p.scene_shadows = &s;
    const double on = median_ms(r, &p, img, frames);
    row(csv, "on-cached", m.nt, on, NAN);
    s.occluder_key = 0;
    const double hashed = median_ms(r, &p, img, frames);
    row(csv, "on-hashed", m.nt, hashed, NAN);
    row(csv, "ratio-on/off", m.nt, on / off, NAN);
    fails += off < 0 || on < 0 || hashed < 0;

    /* the sphere moves: a new key each time, the same frame again cached */
    double moved[64], cached[64];
    int n = 0;
    for (int i = 0; i < frames + 1 && i < 64; i++) {
        const float dx = i % 2 ? 2.0f : -2.0f;
        for (uint32_t k = 0; k + 12 < m.nv * 3; k += 3) m.v[k] += dx; /* not the floor */
        s.occluder_key = 100 + (uint64_t)i;
        double t0 = now_ms();
        fails += vxl_render(r, &p, img, NULL) != 0;
        double ms = now_ms() - t0;
        vxl_render_stats st = {.struct_size = sizeof st};
        vxl_renderer_get_stats(r, &st);
        t0 = now_ms();
        fails += vxl_render(r, &p, img, depth) != 0;
        if (i == 0 || !st.illumination_rebuilt) continue; /* the first pays for programs */
        cached[n] = now_ms() - t0;
        moved[n++] = ms;
    }
    if (n) {
        qsort(moved, (size_t)n, sizeof *moved, cmp_d);
        qsort(cached, (size_t)n, sizeof *cached, cmp_d);
        row(csv, "mesh-moved", m.nt, moved[n / 2], moved[n / 2] - cached[n / 2]);
    } else {
        fails++;
    }

    /* the frame's own depth as the scene; the background a plane behind it */
    float far = 0;
    for (size_t i = 0; i < (size_t)size * size; i++) far = isfinite(depth[i]) && depth[i] > far ? depth[i] : far;
    for (size_t i = 0; i < (size_t)size * size; i++) depth[i] = isfinite(depth[i]) ? depth[i] : 1.2f * far;
    p.scene_depth = depth;
    const double tr = transmittance_ms(r, &p, img, frames);
    row(csv, "transmittance", m.nt, tr, NAN);
    fails += tr < 0;
    if (fails) fprintf(stderr, "%s\n", vxl_renderer_error(r));
    if (csv) fclose(csv);
    free(img);
    free(depth);
    free(m.v);
    free(m.idx);
    vxl_renderer_destroy(r);
    return fails != 0;
}
