/* test_kernels.c - the kernels that derive volumes exist once in GLSL
 * (shaders/lib/, shaders/compute/); the CPU copies that bricked and
 * sparse storage need (csrc/gradients/bspline_bricks.c: the B-spline prefilter of a
 * brick from the CPU bricks, and the precomputed filter's largest gradient;
 * csrc/storage/paging.c: the skipping grid's min-max, bit for bit)
 * must give what the GLSL gives on the same data. The volume is small
 * enough that every brick's prefilter window spans whole lines (P = 8, at
 * most 16 voxels an axis: a window reaches 12 voxels past the brick and its
 * ghost), so the CPU and the GLSL filter exactly the same lines:
 * - the prefilter: to float rounding. The CPU runs the GLSL's recursion
 *   step for step, but C11 rounds every product and sum (-std=c11 does not
 *   contract a*b+c), while GLSL lets the compiler fuse and reorder float
 *   operations that are not `precise`; on llvmpipe about a tenth of the
 *   probed components differ by 1-2 ulp (still a twentieth with `precise`
 *   on the accumulators). Bit-exactness would need the GLSL changed, and
 *   with it every dense cubic render.
 * - the largest gradient: to float rounding, because the CPU runs the blur
 *   and the Sobel as separable 3-tap passes (9 + 3x9 multiplies a voxel
 *   instead of 2 x 27) and so sums in another order than the GLSL.
 * A kernel that differs in anything but rounding (pole, gain, boundary,
 * weights, clamping) is off by orders more than that bound (ROUNDINGS). */
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "files.h"
#include "test_util.h"
#include "voxlight_dev.h"

/* "to float rounding": within 64 roundings (relative 2^-24 each) of the
 * largest component, one per term of the longest sum involved (the cubic
 * weighs 64 coefficients, the Sobel 26 taps of 27-tap blurs); measured: 1
 * (cubic) and 4 (precomputed), against what test_paging's
 * storage comparison allows (5e-4, about 2^13; its windows are truncated). */
#define ROUNDINGS (64.0 / 16777216.0)

#define NX 16
#define NY 15
#define NZ 13

/* deterministic white noise in [0, 1): every line has detail to filter */
static double field_noise(double x, double y, double z, const double *prm)
{
    (void)prm;
    uint32_t h = (uint32_t)x * 73856093u ^ (uint32_t)y * 19349663u ^ (uint32_t)z * 83492791u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return (double)(h >> 8) / 16777216.0;
}

static vxl_renderer *make_stored(uint32_t storage)
{
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.backend = software_backend();
    o.storage = storage;
    o.page_brick = storage == VXL_STORAGE_DENSE ? 0 : 8;
    vxl_renderer *r = NULL;
    return vxl_renderer_create(&o, &r) == VXL_OK ? r : NULL;
}

/* dense and bricked renderers holding the noise volume; 0 on failure */
static int make_pair(vxl_renderer *rs[2])
{
    rs[0] = make_stored(VXL_STORAGE_DENSE);
    rs[1] = make_stored(VXL_STORAGE_BRICKED);
    vxl_volume *v = make_volume_f32(NX, NY, NZ, field_noise, NULL);
    int ok = rs[0] && rs[1] && v && vxl_renderer_set_volume(rs[0], v) == VXL_OK &&
             vxl_renderer_set_volume(rs[1], v) == VXL_OK;
    vxl_volume_destroy(v);
    return ok;
}

/* the page brick the last frame used (0: dense): renders one */
static uint32_t page_brick_of(vxl_renderer *r, const vxl_render_params *p)
{
    static float img[16 * 16 * 4];
    if (vxl_render(r, p, img, NULL) != VXL_OK) return 0;
    vxl_render_stats s;
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    return vxl_renderer_get_stats(r, &s) == VXL_OK ? s.page_brick : 0;
}

/* The cubic filter reads the coefficients texel-exact and weighs them with
 * the same GLSL in both storages: the probed gradients, at points all over
 * the box (brick faces included), differ only as the GLSL prefilter's
 * (dense) and the CPU's (bricked) coefficients do. */
TEST(bspline_prefilter_cpu_equals_glsl_to_rounding)
{
    vxl_renderer *rs[2] = {NULL, NULL};
    REQUIRE(make_pair(rs));
    enum { N = 3000 };
    static float pts[N * 3], out[2][N * 3];
    const float dims[3] = {NX, NY, NZ};
    uint32_t seed = 777;
    for (int i = 0; i < N * 3; i++) {
        seed = seed * 1664525u + 1013904223u;
        pts[i] = (float)(seed >> 8) / 16777216.0f * dims[i % 3] - 0.5f;
    }
    vxl_render_params p = phantom_scene(16, 16, VXL_FILTER_CUBIC, VXL_CLASSIFY_POST);
    for (int i = 0; i < 2; i++)
        CHECKF(vxl_probe_gradients(rs[i], &p, pts, N, out[i]) == VXL_OK, "%s", vxl_last_error());
    CHECK(page_brick_of(rs[1], &p) == 8); /* really bricked: coefficients from bspline_bricks.c */
    int differ = 0, first = -1;
    double gmax = 0, err = 0;
    for (int i = 0; i < N * 3; i++) {
        gmax = fmax(gmax, fabs(out[0][i]));
        err = fmax(err, fabs(out[1][i] - out[0][i]));
        if (memcmp(&out[0][i], &out[1][i], sizeof(float))) {
            differ++;
            if (first < 0) first = i;
        }
    }
    fprintf(stderr, "    cubic: %d of %d components differ, by at most %.2e (largest component %.3f)\n", differ, N * 3, err, gmax);
    CHECK(gmax > 0.1);
    CHECKF(err <= ROUNDINGS * gmax, "%.3g of the largest component; first differing: %d, dense %.9g, bricked %.9g",
           err / gmax, first, first < 0 ? 0.0 : out[0][first], first < 0 ? 0.0 : out[1][first]);
    vxl_renderer_destroy(rs[0]);
    vxl_renderer_destroy(rs[1]);
}

/* The precomputed filter stores gradient / largest |gradient|: dense finds
 * that maximum with the GLSL blur and Sobel, bricked on the CPU. At voxel
 * centres (no interpolation) the probe gives stored * maximum, so the two
 * agree to float rounding of the maximum and the stored value. */
TEST(gradient_max_cpu_equals_glsl_to_rounding)
{
    vxl_renderer *rs[2] = {NULL, NULL};
    REQUIRE(make_pair(rs));
    enum { N = NX * NY * NZ };
    static float pts[N * 3], out[2][N * 3];
    for (int i = 0; i < N; i++) {
        pts[3 * i] = (float)(i % NX);
        pts[3 * i + 1] = (float)(i / NX % NY);
        pts[3 * i + 2] = (float)(i / (NX * NY));
    }
    vxl_render_params p = phantom_scene(16, 16, VXL_FILTER_PRECOMPUTED, VXL_CLASSIFY_POST);
    p.gradient_store = VXL_GRADIENT_STORE_32F;
    for (int i = 0; i < 2; i++)
        CHECKF(vxl_probe_gradients(rs[i], &p, pts, N, out[i]) == VXL_OK, "%s", vxl_last_error());
    CHECK(page_brick_of(rs[1], &p) == 8);
    double gmax = 0, err = 0;
    for (int i = 0; i < N * 3; i++) {
        gmax = fmax(gmax, fabs(out[0][i]));
        err = fmax(err, fabs(out[1][i] - out[0][i]));
    }
    fprintf(stderr, "    precomputed: largest component %.4f, off by at most %.2e (%.2g of it)\n", gmax, err,
            err / gmax);
    CHECK(gmax > 0.01);
    CHECKF(err <= ROUNDINGS * gmax, "%.3g of the largest component", err / gmax);
    vxl_renderer_destroy(rs[0]);
    vxl_renderer_destroy(rs[1]);
}

/* ---- the skipping grid: brick_minmax.comp (dense) and paging.c's
 * vxl_bricks_minmax_cpu (bricked, at set_volume) ---- */

/* odd sizes: every axis ends in a partial brick (skip bricks of 8 voxels) */
#define GX 21
#define GY 13
#define GZ 11

/* The volume of one data type, its raw values from field_noise, with NaN
 * and infinities sprinkled into the float one (neutralised at load).
 * norm gets each voxel's normalised value as volume.c defines it. */
static vxl_volume *make_typed(uint32_t dtype, double *norm)
{
    enum { N = GX * GY * GZ };
    static uint8_t u8[N];
    static int16_t i16[N];
    static float f32[N];
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < N; i++) {
        double u = field_noise(i % GX, i / GX % GY, i / (GX * GY), NULL);
        u8[i] = (uint8_t)(u * 256);
        i16[i] = (int16_t)(u * 65536 - 32768);
        f32[i] = (float)(u * 2000 - 1000);
        if (i % 97 == 5) f32[i] = NAN;
        if (i % 211 == 7) f32[i] = i % 2 ? INFINITY : -INFINITY;
        if (isfinite(f32[i])) lo = fmin(lo, f32[i]), hi = fmax(hi, f32[i]);
    }
    for (int i = 0; i < N; i++) { /* volume.c: integers over their type's range; floats over the finite range */
        double x = f32[i];
        x = isnan(x) ? lo : fmin(fmax(x, lo), hi);
        norm[i] = dtype == VXL_DTYPE_U8 ? u8[i] / 255.0
                  : dtype == VXL_DTYPE_I16 ? (i16[i] + 32768.0) / 65535.0
                                           : (float)((x - lo) / (hi - lo));
    }
    const void *data = dtype == VXL_DTYPE_U8 ? (const void *)u8 : dtype == VXL_DTYPE_I16 ? (const void *)i16 : f32;
    const vxl_volume_desc d = {.struct_size = sizeof d, .dtype = dtype, .dims = {GX, GY, GZ}, .data = data};
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, NULL, &v) == VXL_OK ? v : NULL;
}

/* The grid of r: n floats into out, the brick edge into *brick; 0 on failure */
static int read_grid(vxl_renderer *r, float *out, size_t n, uint32_t *brick)
{
    uint32_t dims[3];
    if (vxl_probe_skip_grid(r, dims, brick, out, n) != VXL_OK) return 0;
    return 2 * (size_t)dims[0] * dims[1] * dims[2] == n;
}

/* Dense storage builds the skipping grid from the volume texture with
 * brick_minmax.comp; bricked storage from the CPU voxels with
 * vxl_bricks_minmax_cpu, before anything is on the GL side. Both must give
 * the same floats, and both must follow the one rule: a brick's min and max
 * cover the brick and a one-voxel apron each way, clamped to the volume
 * (every voxel a trilinear sample inside the brick's box reaches). The
 * check against that rule, computed here from the source values, is what
 * fails if both kernels drift together (no apron, a wider one, unclamped). */
/* One brick edge B (both storages are told it through VOXLIGHT_BRICK_SIZE). */
static void check_minmax_kernels_agree(vxl_test_ctx *T_, const int B)
{
    const uint32_t dtypes[3] = {VXL_DTYPE_U8, VXL_DTYPE_I16, VXL_DTYPE_F32};
    const int BX = (GX + B - 1) / B, BY = (GY + B - 1) / B, BZ = (GZ + B - 1) / B, NG = 2 * BX * BY * BZ;
    static double norm[GX * GY * GZ];
    char edge[8];
    snprintf(edge, sizeof edge, "%d", B);
    vxl_os_set_env("VOXLIGHT_BRICK_SIZE", edge);
    for (int t = 0; t < 3; t++) {
        vxl_renderer *rs[2] = {make_stored(VXL_STORAGE_DENSE), make_stored(VXL_STORAGE_BRICKED)};
        vxl_volume *v = make_typed(dtypes[t], norm);
        REQUIRE(rs[0] && rs[1] && v);
        float grid[2][2 * ((GX + 3) / 4) * ((GY + 3) / 4) * ((GZ + 3) / 4)]; /* room for B >= 4 */
        uint32_t brick[2] = {0, 0};
        vxl_render_params p = phantom_scene(16, 16, VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
        for (int i = 0; i < 2; i++) {
            CHECKF(vxl_renderer_set_volume(rs[i], v) == VXL_OK, "%s", vxl_renderer_error(rs[i]));
            CHECK(page_brick_of(rs[i], &p) == (i ? 8u : 0u)); /* renders: dense builds its grid on the GPU */
            CHECKF(read_grid(rs[i], grid[i], NG, &brick[i]), "%s", vxl_renderer_error(rs[i]));
        }
        vxl_volume_destroy(v);
        CHECK(brick[0] == (uint32_t)B && brick[1] == (uint32_t)B);
        int differ = 0, first = -1;
        for (int i = 0; i < NG; i++)
            if (memcmp(&grid[0][i], &grid[1][i], sizeof(float)) && differ++ == 0) first = i;
        CHECKF(!differ, "%s: %d of %d floats differ; first %d: GLSL %.9g, CPU %.9g", vxl_dtype_name(dtypes[t]),
               differ, NG, first, first < 0 ? 0.0 : grid[0][first], first < 0 ? 0.0 : grid[1][first]);
        double err = 0, spread = 0;
        for (int i = 0; i < NG / 2; i++) {
            const int c[3] = {i % BX, i / BX % BY, i / (BX * BY)}, n[3] = {GX, GY, GZ};
            int lo[3], hi[3];
            for (int a = 0; a < 3; a++) {
                lo[a] = c[a] * B - 1 < 0 ? 0 : c[a] * B - 1;
                hi[a] = c[a] * B + B > n[a] - 1 ? n[a] - 1 : c[a] * B + B;
            }
            double mn = INFINITY, mx = -INFINITY;
            for (int z = lo[2]; z <= hi[2]; z++)
                for (int y = lo[1]; y <= hi[1]; y++)
                    for (int x = lo[0]; x <= hi[0]; x++) {
                        double u = norm[x + GX * (y + GY * z)];
                        mn = fmin(mn, u);
                        mx = fmax(mx, u);
                    }
            err = fmax(err, fmax(fabs(grid[1][2 * i] - mn), fabs(grid[1][2 * i + 1] - mx)));
            spread = fmax(spread, mx - mn);
        }
        /* one float rounding of a value in [0, 1]; a voxel more or less
         * in a brick's reach moves its noise min or max by ~1/(voxels) */
        CHECKF(err <= 1e-7, "%s: the grid is off the brick-plus-apron rule by %.3g", vxl_dtype_name(dtypes[t]), err);
        CHECK(spread > 0.5);
        vxl_renderer_destroy(rs[0]);
        vxl_renderer_destroy(rs[1]);
    }
    vxl_os_set_env("VOXLIGHT_BRICK_SIZE", NULL);
}

TEST(brick_minmax_cpu_equals_glsl_bit_for_bit)
{
    check_minmax_kernels_agree(T_, 8); /* the paged storages' edge */
    check_minmax_kernels_agree(T_, 4); /* dense storage's edge for volumes up to 512^3 */
}

/* Without the override, dense storage (its grid built on the GPU) takes 4^3
 * bricks for a volume whose 4^3 grid has at most 2^21 bricks, bricked
 * storage (its grid from the CPU index) 8^3; the images are the same, since
 * skipping only leaves out samples that add nothing. */
TEST(dense_storage_skips_with_finer_bricks)
{
    vxl_os_set_env("VOXLIGHT_BRICK_SIZE", NULL);
    static double norm[GX * GY * GZ];
    vxl_renderer *rs[2] = {make_stored(VXL_STORAGE_DENSE), make_stored(VXL_STORAGE_BRICKED)};
    vxl_volume *v = make_typed(VXL_DTYPE_U8, norm);
    REQUIRE(rs[0] && rs[1] && v);
    float grid[2 * ((GX + 3) / 4) * ((GY + 3) / 4) * ((GZ + 3) / 4)];
    const uint32_t want[2] = {4, 8};
    for (int i = 0; i < 2; i++) {
        vxl_render_params p = phantom_scene(16, 16, VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
        CHECKF(vxl_renderer_set_volume(rs[i], v) == VXL_OK, "%s", vxl_renderer_error(rs[i]));
        CHECK(page_brick_of(rs[i], &p) == (i ? 8u : 0u)); /* renders */
        uint32_t dims[3], brick = 0;
        CHECKF(vxl_probe_skip_grid(rs[i], dims, &brick, grid, sizeof grid / sizeof grid[0]) == VXL_OK, "%s",
               vxl_renderer_error(rs[i]));
        CHECKF(brick == want[i], "storage %d: brick edge %u, want %u", i, brick, want[i]);
        CHECK(dims[0] == (GX + brick - 1) / brick && dims[2] == (GZ + brick - 1) / brick);
    }
    vxl_volume_destroy(v);
    vxl_renderer_destroy(rs[0]);
    vxl_renderer_destroy(rs[1]);
}

/* The source tree's shaders/, found by walking up from this program's
 * folder (BUILD/tests/, or BUILD/windows-x64/tests/): found from any working
 * directory; 0 when not found. */
static int source_shader_dir(char *out, size_t n)
{
    char found[4096], exe[4096];
    if (vxl_dynlib_path_of((const void *)&source_shader_dir, found, sizeof found) ||
        !vxl_real_path(found, exe, sizeof exe))
        return 0;
    for (int up = 0; up < 5; up++) {
        const char *slash = vxl_path_last_separator(exe);
        if (!slash) return 0;
        exe[slash - exe] = '\0';
        if (snprintf(out, n, "%s/shaders/lib", exe) < (int)n && vxl_is_dir(out))
            return snprintf(out, n, "%s/shaders", exe) < (int)n;
    }
    return 0;
}

/* VOXLIGHT_SHADER_DIR / shader_dir names the shaders/ folder and resolves
 * every name (programs in compute/ and render/, includes from lib/) as the
 * embedded copies do: the same image, bit for bit, for a filter that
 * includes the shared stencils and for the precomputed passes. */
TEST(shader_dir_reads_the_layout_the_library_embeds)
{
    char dir[PATH_MAX];
    REQUIRE(source_shader_dir(dir, sizeof dir));
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.backend = software_backend();
    vxl_renderer *re = NULL, *rd = NULL;
    REQUIRE(vxl_renderer_create(&o, &re) == VXL_OK);
    o.shader_dir = dir;
    REQUIRE(vxl_renderer_create(&o, &rd) == VXL_OK);
    vxl_volume *v = make_volume_f32(NX, NY, NZ, field_noise, NULL);
    REQUIRE(v && vxl_renderer_set_volume(re, v) == VXL_OK && vxl_renderer_set_volume(rd, v) == VXL_OK);
    vxl_volume_destroy(v);
    const uint32_t filters[2] = {VXL_FILTER_SOBEL26, VXL_FILTER_PRECOMPUTED};
    static float a[32 * 32 * 4], b[32 * 32 * 4];
    for (int f = 0; f < 2; f++) {
        vxl_render_params p = phantom_scene(32, 32, filters[f], VXL_CLASSIFY_POST);
        CHECKF(vxl_render(re, &p, a, NULL) == VXL_OK, "embedded: %s", vxl_renderer_error(re));
        CHECKF(vxl_render(rd, &p, b, NULL) == VXL_OK, "from %s: %s", dir, vxl_renderer_error(rd));
        CHECKF(!memcmp(a, b, sizeof a) && alpha_sum(a, 32 * 32) > 1, "%s: the images differ or are empty",
               vxl_filter_name(filters[f]));
    }
    vxl_renderer_destroy(re);
    vxl_renderer_destroy(rd);
}

int main(void)
{
    RUN(bspline_prefilter_cpu_equals_glsl_to_rounding);
    RUN(gradient_max_cpu_equals_glsl_to_rounding);
    RUN(brick_minmax_cpu_equals_glsl_bit_for_bit);
    RUN(dense_storage_skips_with_finer_bricks);
    RUN(shader_dir_reads_the_layout_the_library_embeds);
    return TEST_SUMMARY();
}
