/* test_channels.c - multi-channel volumes (docs/channels.md;
 * csrc/volume/channel_volume.c, csrc/frame/frame_channels.c,
 * csrc/channels/channels.c, csrc/channels/channel_pages.c,
 * shaders/lib/channels.glsl): channels with disjoint blobs, where hiding
 * one removes exactly its blob and solo shows only one, in every storage
 * mode; every storage mode draws the same image (paged pools against dense
 * textures), with the GL bytes worked out here; sparse storage pages only
 * what the drawn channels can see and pages in a channel shown; the budget
 * refuses the pools before allocating; additive blending equals the sum of
 * the channels drawn one at a time, lit and unlit, with two texture groups
 * (six channels); a channel's window changes only its own pixels; skipping
 * over the union changes nothing; a clip plane cuts every channel; the
 * scalar is the chosen channel, bit for bit a one-channel volume; what
 * cannot go with channels is refused with a message; NIfTI 5D (dim[5]
 * channels, dim[4] frames) and NRRD channel axes load as channels by the
 * channels mode and render as the same voxels in memory. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "loader_test_util.h"
#include "nifti_writer.h"
#include "test_util.h"

#define N 24
#define W 32
#define NPIX (W * W)

/* A ball of radius r at (cx, cy, cz), value peak inside, 0 outside: uint16. */
static void ball(uint16_t *dst, double cx, double cy, double cz, double r, uint16_t peak)
{
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) {
                double d = sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz));
                dst[x + N * (y + N * z)] = d < r ? (uint16_t)(peak * (1.0 - 0.5 * d / r)) : 0;
            }
}

/* A planar volume of `count` channels (each N^3 uint16 from data). */
static vxl_volume *channels_volume(const uint16_t *data, uint32_t count, uint32_t scalar_channel)
{
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U16, .dims = {N, N, N}, .data = data,
                         .channels = count};
    vxl_load_options lo = {.struct_size = sizeof lo, .scalar_channel = scalar_channel};
    vxl_volume *v = NULL;
    return vxl_volume_create(&d, &lo, &v) == VXL_OK ? v : NULL;
}

static vxl_render_params base_params(void)
{
    vxl_render_params p;
    memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.width = p.height = W;
    p.azimuth_deg = 20;
    p.elevation_deg = 10;
    p.shading_off = 1;
    return p;
}

/* Styles for channels 0..count-1, each with the data range as window and an
 * opacity scale low enough that nothing saturates (sums stay below 1). */
static void styles(vxl_channel_style *s, uint32_t count)
{
    memset(s, 0, sizeof *s * count);
    for (uint32_t c = 0; c < count; c++) {
        s[c].struct_size = sizeof *s;
        s[c].channel = c;
        s[c].opacity_scale = 0.4f;
    }
}

/* A renderer in one storage mode holding a planar volume of `count`
 * channels, and a frame drawing them all with styles(). The paged modes cut
 * the 24^3 volume into bricks of 8 (27 bricks, many constant) so the pools
 * hold varying bricks, shared constant slots and bricks at the edges. */
typedef struct fixture {
    vxl_volume *v;
    vxl_renderer *r;
    vxl_channel_style st[VXL_MAX_CHANNELS];
    vxl_render_params p;
} fixture;

#define PAGE_BRICK 8
/* Two storages holding the same texels at different places (dense
 * textures and pools; pools of other slot layouts) differ only where the
 * trilinear weights, computed from other coordinates, round differently. */
#define DENSE_TOLERANCE 1e-5 /* measured: 2.2e-7 (2 channels), 3.1e-7 (6, lit) */
static const uint32_t g_storages[4] = {VXL_STORAGE_DENSE, VXL_STORAGE_BRICKED, VXL_STORAGE_SPARSE,
                                       VXL_STORAGE_COMPRESSED};

static int fixture_open_bricks(fixture *x, const uint16_t *data, uint32_t count, uint32_t storage, uint32_t brick)
{
    memset(x, 0, sizeof *x);
    x->v = channels_volume(data, count, 0);
    x->r = make_stored_renderer(storage, storage == VXL_STORAGE_DENSE ? 0 : brick, 0, 0);
    styles(x->st, count);
    x->p = base_params();
    x->p.channel_count = count;
    x->p.channels = x->st;
    if (x->v && x->r && vxl_renderer_set_volume(x->r, x->v) == VXL_OK) return 1;
    fprintf(stderr, "  fixture (%s storage): %s\n", vxl_storage_name(storage),
            x->r ? vxl_renderer_error(x->r) : vxl_last_error());
    return 0;
}

static int fixture_open(fixture *x, const uint16_t *data, uint32_t count, uint32_t storage)
{
    return fixture_open_bricks(x, data, count, storage, PAGE_BRICK);
}

static void fixture_close(fixture *x)
{
    vxl_renderer_destroy(x->r);
    vxl_volume_destroy(x->v);
}

/* A frame; a failure prints the renderer's message (the checks say where). */
static int render(vxl_renderer *r, const vxl_render_params *p, float *rgba)
{
    const int rc = vxl_render(r, p, rgba, NULL);
    if (rc) fprintf(stderr, "  render: %s\n", vxl_renderer_error(r));
    return rc;
}

static double max_diff(const float *a, const float *b, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; i++) m = fmax(m, fabs((double)a[i] - b[i]));
    return m;
}

static uint16_t g_two[2 * N * N * N];  /* channel 0: a ball at x 7, channel 1: a ball at x 17 (disjoint) */
static uint16_t g_over[2 * N * N * N]; /* two overlapping balls */
static uint16_t g_six[6 * N * N * N];  /* six balls around the centre */
static uint16_t g_sparse[6 * N * N * N]; /* six small balls in separate bricks: most bricks empty */

static float A[NPIX * 4], B[NPIX * 4], C[NPIX * 4], S[NPIX * 4];

static void check_hiding(vxl_test_ctx *T_, uint32_t storage)
{
    fixture x;
    REQUIRE(fixture_open(&x, g_two, 2, storage));
    REQUIRE(render(x.r, &x.p, A) == VXL_OK); /* both */
    x.st[1].hidden = 1;
    REQUIRE(render(x.r, &x.p, B) == VXL_OK); /* channel 0 alone */
    x.st[1].hidden = 0;
    x.st[1].solo = 1;
    REQUIRE(render(x.r, &x.p, C) == VXL_OK); /* channel 1 alone */
    CHECK(image_is_sane(A, NULL, NPIX) && image_is_sane(B, NULL, NPIX) && image_is_sane(C, NULL, NPIX));
    int only0 = 0, only1 = 0, bad = 0;
    for (int i = 0; i < NPIX; i++) {
        const float a1 = C[4 * i + 3], a0 = B[4 * i + 3];
        if (a0 > 0 && a1 == 0) only0++;
        if (a1 > 0 && a0 == 0) only1++;
        /* where channel 1 shows nothing, hiding it changes nothing */
        if (a1 == 0)
            for (int k = 0; k < 4; k++) bad += A[4 * i + k] != B[4 * i + k];
        /* where channel 1's blob shows, hiding it leaves only channel 0 */
        if (a1 > 0 && a0 == 0) bad += B[4 * i + 3] != 0 || A[4 * i + 3] == 0;
    }
    const char *sn = vxl_storage_name(storage);
    CHECKF(only0 > 20 && only1 > 20, "%s: blob pixels: %d, %d", sn, only0, only1);
    CHECKF(bad == 0, "%s: %d pixels changed where they should not", sn, bad);
    /* the default colours: channel 0 red, channel 1 green */
    double g0 = 0, r1 = 0;
    for (int i = 0; i < NPIX; i++) {
        g0 += B[4 * i + 1] + B[4 * i + 2];
        r1 += C[4 * i + 0] + C[4 * i + 2];
    }
    CHECKF(g0 == 0 && r1 == 0, "%s: pure channel colours: %g %g", sn, g0, r1);
    fixture_close(&x);
}

TEST(hiding_a_channel_removes_exactly_its_blob)
{
    for (int k = 0; k < 4; k++) check_hiding(T_, g_storages[k]);
}

/* The sum of the channels drawn one at a time (solo) against all drawn. */
static void check_additive(vxl_test_ctx *T_, const uint16_t *data, uint32_t count, int shaded, uint32_t storage)
{
    fixture x;
    REQUIRE(fixture_open(&x, data, count, storage));
    x.p.shading_off = !shaded;
    REQUIRE(render(x.r, &x.p, A) == VXL_OK);
    memset(S, 0, sizeof S);
    for (uint32_t c = 0; c < count; c++) {
        for (uint32_t k = 0; k < count; k++) x.st[k].solo = k == c;
        REQUIRE(render(x.r, &x.p, B) == VXL_OK);
        for (int i = 0; i < NPIX * 4; i++) S[i] += B[i];
    }
    double peak = 0;
    for (int i = 0; i < NPIX; i++) peak = fmax(peak, S[4 * i + 3]);
    CHECKF(peak > 0.05 && peak < 1.0, "the sum's largest alpha %g (overlap visible, nothing clamped)", peak);
    const double d = max_diff(A, S, NPIX * 4);
    CHECKF(d < 1e-5, "%u channels%s, %s storage: additive blending differs from the sum of the channels by %g", count,
           shaded ? " lit" : "", vxl_storage_name(storage), d);
    CHECK(image_is_sane(A, NULL, NPIX));
    fixture_close(&x);
}

TEST(additive_blending_is_the_sum_of_the_channels)
{
    check_additive(T_, g_over, 2, 0, VXL_STORAGE_DENSE);
    check_additive(T_, g_over, 2, 1, VXL_STORAGE_DENSE);
    check_additive(T_, g_six, 6, 1, VXL_STORAGE_DENSE); /* two texture groups */
    check_additive(T_, g_six, 6, 1, VXL_STORAGE_BRICKED); /* two pools behind one page table */
}

TEST(a_clip_plane_cuts_every_channel)
{
    fixture x;
    REQUIRE(fixture_open(&x, g_two, 2, VXL_STORAGE_DENSE));
    x.p.shading_off = 0;
    x.st[1].solo = 1;
    REQUIRE(render(x.r, &x.p, C) == VXL_OK); /* channel 1 alone, uncut */
    x.st[1].solo = 0;
    x.st[1].hidden = 1;
    REQUIRE(render(x.r, &x.p, B) == VXL_OK); /* channel 0 alone, uncut */
    x.st[1].hidden = 0;
    /* keep x <= 12 (identity affine: world = voxel): channel 1's blob (x 12.5..21.5) is cut away */
    vxl_cutaway cut = {.struct_size = sizeof cut, .clip_plane_count = 1};
    cut.clip_planes[0].plane[0] = -1;
    cut.clip_planes[0].plane[3] = 12;
    x.p.cutaway = &cut;
    REQUIRE(render(x.r, &x.p, A) == VXL_OK);
    int left = 0, bad = 0;
    for (int i = 0; i < NPIX; i++) {
        if (C[4 * i + 3] > 0 && B[4 * i + 3] == 0) bad += A[4 * i + 3] != 0;
        left += A[4 * i + 3] > 0;
    }
    CHECKF(bad == 0, "%d pixels of the cut channel remain", bad);
    CHECKF(left > 20, "channel 0's blob: %d pixels", left);
    CHECK(image_is_sane(A, NULL, NPIX));
    fixture_close(&x);
}

TEST(a_channels_window_changes_only_that_channel)
{
    fixture x;
    REQUIRE(fixture_open(&x, g_two, 2, VXL_STORAGE_DENSE));
    REQUIRE(render(x.r, &x.p, A) == VXL_OK);
    x.st[1].has_window = 1;
    x.st[1].window_low = 0;
    x.st[1].window_high = 20000; /* half the range: channel 1 brighter and more opaque */
    REQUIRE(render(x.r, &x.p, B) == VXL_OK);
    x.st[1].solo = 1;
    REQUIRE(render(x.r, &x.p, C) == VXL_OK); /* channel 1 alone, new window */
    x.st[1].solo = 0;
    x.st[1].hidden = 1;
    REQUIRE(render(x.r, &x.p, S) == VXL_OK); /* channel 0 alone */
    int changed = 0, bad = 0;
    for (int i = 0; i < NPIX; i++) {
        if (C[4 * i + 3] == 0) {
            for (int k = 0; k < 4; k++) bad += A[4 * i + k] != B[4 * i + k];
        } else {
            changed += B[4 * i + 3] > A[4 * i + 3];
        }
        for (int k = 0; k < 4; k++) bad += fabs((double)B[4 * i + k] - (S[4 * i + k] + C[4 * i + k])) > 1e-5;
    }
    CHECKF(changed > 20, "channel 1's pixels that changed: %d", changed);
    CHECKF(bad == 0, "%d pixel values changed outside channel 1", bad);
    fixture_close(&x);
}

/* The six small balls (g_sparse) drawn lit, channel 2 hidden, through a
 * table transparent over its first half: the background is empty (the
 * occupancy rule widens by entries around a brick's range, so a ramp from
 * 0 would occupy every brick). */
static int open_six_balls(fixture *x, uint32_t storage)
{
    static const float tf[8 * 4] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                                    1, 1, 1, 0.3f, 1, 1, 1, 0.4f, 1, 1, 1, 0.5f, 1, 1, 1, 0.6f};
    if (!fixture_open(x, g_sparse, 6, storage)) return 0;
    x->st[2].hidden = 1;
    for (int c = 0; c < 6; c++) {
        x->st[c].tf_rgba = tf;
        x->st[c].tf_size = 8;
    }
    x->p.shading_off = 0;
    return 1;
}

/* The image (into out) and the channels' GL bytes (*bytes) of the six
 * small balls, skipping checked against no skipping. */
static void check_skipping(vxl_test_ctx *T_, uint32_t storage, float *out, uint64_t *bytes)
{
    fixture x;
    REQUIRE(open_six_balls(&x, storage));
    REQUIRE(render(x.r, &x.p, A) == VXL_OK);
    vxl_render_stats s1 = renderer_stats(x.r);
    x.p.no_skip = 1;
    REQUIRE(render(x.r, &x.p, B) == VXL_OK);
    vxl_render_stats s2 = renderer_stats(x.r);
    const char *sn = vxl_storage_name(storage);
    CHECKF(max_diff(A, B, NPIX * 4) == 0, "%s: skipping changed the image by %g", sn, max_diff(A, B, NPIX * 4));
    CHECKF(s1.samples < s2.samples, "%s: samples with skipping %llu, without %llu", sn, (unsigned long long)s1.samples,
           (unsigned long long)s2.samples);
    CHECKF(s1.bricks_occupied == 5 && s1.bricks_total == 27, "%s: occupied %u of %u: the five drawn balls' bricks", sn,
           s1.bricks_occupied, s1.bricks_total);
    CHECK(alpha_sum(A, NPIX) > 1);
    memcpy(out, A, sizeof A);
    *bytes = s1.channel_bytes;
    fixture_close(&x);
}

/* ... in every storage mode; sparse storage pages only the bricks the
 * drawn channels can see (the five balls' of 27, where bricked holds every
 * ball's), and draws bricked storage's image bit for bit. */
TEST(skipping_over_the_union_changes_nothing)
{
    static float img[4][NPIX * 4];
    uint64_t bytes[4];
    for (int k = 0; k < 4; k++) check_skipping(T_, g_storages[k], img[k], &bytes[k]);
    const double d = max_diff(img[1], img[2], NPIX * 4);
    fprintf(stderr, "    channel bytes: bricked %llu, sparse %llu; images differ by %.3g\n", (unsigned long long)bytes[1],
            (unsigned long long)bytes[2], d);
    CHECKF(d <= DENSE_TOLERANCE, "sparse differs from bricked by %g", d);
    CHECKF(bytes[2] < bytes[1], "sparse holds %llu bytes of channels, bricked %llu", (unsigned long long)bytes[2],
           (unsigned long long)bytes[1]);
}

/* Sparse storage's pools follow what is drawn: showing the hidden channel
 * pages its ball's brick in (the pools grow by that slot) and the image is
 * bricked storage's, before and after, within DENSE_TOLERANCE. */
TEST(sparse_storage_pages_in_a_channel_shown)
{
    fixture b, sp;
    REQUIRE(open_six_balls(&b, VXL_STORAGE_BRICKED) && open_six_balls(&sp, VXL_STORAGE_SPARSE));
    uint64_t bytes[2];
    for (int shown = 0; shown < 2; shown++) {
        b.st[2].hidden = sp.st[2].hidden = !shown;
        REQUIRE(render(b.r, &b.p, A) == VXL_OK && render(sp.r, &sp.p, B) == VXL_OK);
        bytes[shown] = renderer_stats(sp.r).channel_bytes;
        const double d = max_diff(A, B, NPIX * 4);
        CHECKF(d <= DENSE_TOLERANCE, "channel 2 %s: sparse differs from bricked by %g", shown ? "shown" : "hidden", d);
        CHECK(alpha_sum(B, NPIX) > 1);
    }
    /* one slot more: (P + 2)^3 texels of 6 channels of 2 bytes */
    CHECKF(bytes[1] == bytes[0] + 10 * 10 * 10 * 6 * 2, "sparse channel bytes hidden %llu, shown %llu",
           (unsigned long long)bytes[0], (unsigned long long)bytes[1]);
    CHECKF(bytes[1] == renderer_stats(b.r).channel_bytes, "shown: every ball's brick, as bricked");
    fixture_close(&b);
    fixture_close(&sp);
}

/* What the paged modes should hold for `count` planar channels of N^3 in
 * bricks of P, worked out here from the definition: a brick (its ghost
 * voxel each way included, clamped to the volume) where some channel
 * varies has a slot; the others share one slot per distinct tuple of
 * constants. Bytes: slots of (P + 2)^3 texels of 2 bytes a channel, and an
 * RGBA32F page-table texel per brick. */
static uint64_t expected_pool_bytes(const uint16_t *data, uint32_t count, int P, uint32_t *varying, uint32_t *constant)
{
    const int G = (N + P - 1) / P, E = P + 2;
    uint16_t tuples[27][VXL_MAX_CHANNELS]; /* G^3 <= 27 for P >= 8 */
    *varying = *constant = 0;
    for (int b = 0; b < G * G * G; b++) {
        const int bx = b % G, by = b / G % G, bz = b / (G * G);
        int varies = 0;
        for (uint32_t c = 0; c < count; c++) {
            const uint16_t *ch = data + (size_t)c * N * N * N;
            int first = 1;
            for (int z = bz * P - 1; z <= bz * P + P; z++)
                for (int y = by * P - 1; y <= by * P + P; y++)
                    for (int x = bx * P - 1; x <= bx * P + P; x++) {
                        const int cx = x < 0 ? 0 : x >= N ? N - 1 : x, cy = y < 0 ? 0 : y >= N ? N - 1 : y,
                                  cz = z < 0 ? 0 : z >= N ? N - 1 : z;
                        const uint16_t val = ch[cx + N * (cy + N * cz)];
                        if (first) tuples[*constant][c] = val;
                        varies |= val != tuples[*constant][c];
                        first = 0;
                    }
        }
        if (varies) {
            ++*varying;
            continue;
        }
        int seen = 0;
        for (uint32_t k = 0; k < *constant && !seen; k++) seen = !memcmp(tuples[k], tuples[*constant], count * 2);
        *constant += !seen;
    }
    return (uint64_t)(*varying + *constant) * E * E * E * 2 * count + (uint64_t)G * G * G * 16;
}

/* The same volume in every storage mode: the paged modes hold the channels
 * in the same pools behind the same page table, so their images are equal
 * bit for bit; against dense textures they differ only where the trilinear
 * weights, computed from pool coordinates instead of the volume's, round
 * differently: within DENSE_TOLERANCE. */
static void check_storages(vxl_test_ctx *T_, const uint16_t *data, uint32_t count, uint32_t brick)
{
    static float img[4][NPIX * 4];
    uint64_t bytes[4] = {0}, scalar[4] = {0};
    for (int k = 0; k < 4; k++) {
        fixture x;
        REQUIRE(fixture_open_bricks(&x, data, count, g_storages[k], brick));
        x.p.shading_off = 0;
        x.st[1].hidden = 1;
        REQUIRE(render(x.r, &x.p, img[k]) == VXL_OK);
        const vxl_render_stats s = renderer_stats(x.r);
        bytes[k] = s.channel_bytes;
        scalar[k] = s.resident_bytes;
        CHECKF(s.storage == g_storages[k], "storage %u, asked %u", s.storage, g_storages[k]);
        CHECK(image_is_sane(img[k], NULL, NPIX) && alpha_sum(img[k], NPIX) > 1);
        fixture_close(&x);
    }
    const double d = max_diff(img[0], img[1], NPIX * 4);
    fprintf(stderr, "    %u channels, bricks of %u: paged against dense differ by at most %.3g\n", count, brick, d);
    CHECKF(d <= DENSE_TOLERANCE, "%u channels: bricked differs from dense by %g", count, d);
    CHECKF(!memcmp(img[1], img[2], sizeof img[1]), "%u channels: sparse differs from bricked", count);
    CHECKF(!memcmp(img[1], img[3], sizeof img[1]), "%u channels: compressed differs from bricked", count);
    uint32_t varying, constant;
    const uint64_t pools = expected_pool_bytes(data, count, (int)brick, &varying, &constant);
    const int grid = (N + (int)brick - 1) / (int)brick;
    fprintf(stderr, "    %u channels of %d^3: dense %llu bytes; paged (bricks of %u) %llu bytes: %u varying bricks and "
                    "%u constant slots of %d\n",
            count, N, (unsigned long long)bytes[0], brick, (unsigned long long)bytes[1], varying, constant,
            grid * grid * grid);
    fprintf(stderr, "    the scalar beside them: dense %llu, bricked %llu, sparse %llu, compressed %llu bytes\n",
            (unsigned long long)scalar[0], (unsigned long long)scalar[1], (unsigned long long)scalar[2],
            (unsigned long long)scalar[3]);
    CHECKF(bytes[0] == 2ull * count * N * N * N, "dense channels: %llu bytes", (unsigned long long)bytes[0]);
    /* llvmpipe's 3D texture limit (2048) lays every slot along x: no slot is padding */
    for (int k = 1; k < 4; k++)
        CHECKF(bytes[k] == pools, "%s: %llu bytes of channel pools, expected %llu", vxl_storage_name(g_storages[k]),
               (unsigned long long)bytes[k], (unsigned long long)pools);
}

TEST(every_storage_draws_the_same_channels)
{
    check_storages(T_, g_two, 2, PAGE_BRICK);
    check_storages(T_, g_six, 6, PAGE_BRICK); /* two groups, two pools */
    check_storages(T_, g_six, 6, 16);         /* 24 = 16 + 8: the last brick of each axis reaches past the volume */
}

/* The channels' pools are charged with the scalar's pool to one budget:
 * one byte short of both, set_volume refuses naming the channels, before
 * anything is allocated, and the renderer keeps the volume it had. */
TEST(the_budget_refuses_channel_pools_before_allocating)
{
    fixture x;
    REQUIRE(fixture_open(&x, g_six, 6, VXL_STORAGE_BRICKED));
    REQUIRE(render(x.r, &x.p, A) == VXL_OK);
    const vxl_render_stats s = renderer_stats(x.r);
    CHECK(s.channel_bytes > 0 && s.resident_bytes > 0);
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U16, .dims = {N, N, N}, .data = g_two};
    vxl_volume *one = NULL;
    REQUIRE(vxl_volume_create(&d, NULL, &one) == VXL_OK);
    vxl_render_params p = base_params();
    for (int enough = 0; enough < 2; enough++) {
        vxl_renderer *r = make_stored_renderer(VXL_STORAGE_BRICKED, PAGE_BRICK,
                                               s.resident_bytes + s.channel_bytes - (enough ? 0 : 1), 0);
        REQUIRE(r && vxl_renderer_set_volume(r, one) == VXL_OK && render(r, &p, B) == VXL_OK);
        const int rc = vxl_renderer_set_volume(r, x.v);
        if (enough) {
            CHECKF(rc == VXL_OK, "at exactly the scalar's and the channels' bytes: %s", vxl_renderer_error(r));
        } else {
            CHECKF(rc == VXL_ERR_LIMIT && strstr(vxl_renderer_error(r), "6 channels (bricked storage)") &&
                       strstr(vxl_renderer_error(r), "memory budget"),
                   "one byte short: %d %s", rc, vxl_renderer_error(r));
            REQUIRE(render(r, &p, C) == VXL_OK); /* the one-channel volume is still there */
            CHECK(!memcmp(B, C, sizeof B));
        }
        vxl_renderer_destroy(r);
    }
    vxl_volume_destroy(one);
    fixture_close(&x);
}

TEST(max_blend_takes_the_dominant_channel)
{
    /* the same ball twice, channel 1 with twice the opacity: max draws
     * channel 1 alone (its opacity is the larger at every sample) */
    static uint16_t same[2 * N * N * N];
    ball(same, 12, 12, 12, 7, 40000);
    ball(same + N * N * N, 12, 12, 12, 7, 40000);
    fixture x;
    REQUIRE(fixture_open(&x, same, 2, VXL_STORAGE_DENSE));
    x.st[1].opacity_scale = 3.0f;
    x.p.channel_blend = VXL_CHANNEL_BLEND_MAX;
    REQUIRE(render(x.r, &x.p, A) == VXL_OK);
    x.st[1].solo = 1;
    REQUIRE(render(x.r, &x.p, B) == VXL_OK);
    CHECKF(max_diff(A, B, NPIX * 4) < 1e-6, "max differs from the dominant channel by %g", max_diff(A, B, NPIX * 4));
    CHECK(alpha_sum(A, NPIX) > 1);
    fixture_close(&x);
}

TEST(the_scalar_is_the_chosen_channel)
{
    for (uint32_t sc = 0; sc < 2; sc++) {
        vxl_volume *v = channels_volume(g_two, 2, sc);
        vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U16, .dims = {N, N, N},
                             .data = g_two + sc * N * N * N};
        vxl_volume *one = NULL;
        REQUIRE(v && vxl_volume_create(&d, NULL, &one) == VXL_OK);
        vxl_volume_info info;
        memset(&info, 0, sizeof info);
        info.struct_size = sizeof info;
        REQUIRE(vxl_volume_get_info(v, &info) == VXL_OK);
        CHECK(info.channel_count == 2 && info.scalar_channel == sc);
        CHECK(info.channel_bytes == 2ull * 2 * N * N * N);
        CHECK(info.channel_min[0] == 0 && info.channel_max[0] == 40000 && info.channel_max[1] == 30000);
        vxl_renderer *r = make_renderer(software_backend());
        REQUIRE(r);
        vxl_render_params p = base_params();
        p.shading_off = 0;
        REQUIRE(vxl_renderer_set_volume(r, v) == VXL_OK);
        REQUIRE(render(r, &p, A) == VXL_OK);
        REQUIRE(vxl_renderer_set_volume(r, one) == VXL_OK);
        REQUIRE(render(r, &p, B) == VXL_OK);
        CHECKF(memcmp(A, B, sizeof A) == 0, "scalar channel %u differs from the channel as a volume", sc);
        vxl_renderer_destroy(r);
        vxl_volume_destroy(v);
        vxl_volume_destroy(one);
    }
}

TEST(what_cannot_go_with_channels_is_refused)
{
    fixture x;
    REQUIRE(fixture_open(&x, g_two, 2, VXL_STORAGE_DENSE));
    vxl_renderer *r = x.r;
    vxl_channel_style *st = x.st;
    vxl_render_params p = x.p;
    p.mode = VXL_MODE_MIP;
    CHECK(render(r, &p, A) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(r), "DVR"));
    p.mode = VXL_MODE_DVR;
    p.classify = VXL_CLASSIFY_PRE;
    CHECK(render(r, &p, A) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(r), "post"));
    p.classify = VXL_CLASSIFY_POST;
    st[1].channel = 0;
    CHECK(render(r, &p, A) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(r), "twice"));
    st[1].channel = 2;
    CHECK(render(r, &p, A) == VXL_ERR_STATE && strstr(vxl_renderer_error(r), "channels 0..1"));
    st[1].channel = 1;
    st[1].has_color = 1;
    st[1].color[0] = 2;
    CHECK(render(r, &p, A) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(r), "color"));
    st[1].color[0] = 0;
    p.channel_blend = 7;
    CHECK(render(r, &p, A) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(r), "channel_blend"));
    p.channel_blend = 0;
    CHECK(render(r, &p, A) == VXL_OK);
    /* a volume without channels */
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U16, .dims = {N, N, N}, .data = g_two};
    vxl_volume *one = NULL;
    REQUIRE(vxl_volume_create(&d, NULL, &one) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(r, one) == VXL_OK);
    CHECK(render(r, &p, A) == VXL_ERR_STATE && strstr(vxl_renderer_error(r), "not multi-channel"));
    vxl_volume_destroy(one);
    /* descriptions */
    vxl_volume *bad = NULL;
    d.channels = 9;
    CHECK(vxl_volume_create(&d, NULL, &bad) == VXL_ERR_INVALID_ARGUMENT && !bad);
    d.channels = 3;
    d.components = 3;
    CHECK(vxl_volume_create(&d, NULL, &bad) == VXL_ERR_INVALID_ARGUMENT && !bad);
    d.components = 0;
    vxl_load_options lo = {.struct_size = sizeof lo, .scalar_channel = 3};
    CHECK(vxl_volume_create(&d, &lo, &bad) == VXL_ERR_INVALID_ARGUMENT && !bad);
    fixture_close(&x);
}

TEST(interleaved_and_planar_layouts_agree)
{
    static uint16_t inter[2 * N * N * N];
    for (int i = 0; i < N * N * N; i++) {
        inter[2 * i] = g_two[i];
        inter[2 * i + 1] = g_two[N * N * N + i];
    }
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U16, .dims = {N, N, N}, .data = inter,
                         .channels = 2, .channels_interleaved = 1};
    vxl_volume *vi = NULL, *vp = channels_volume(g_two, 2, 0);
    REQUIRE(vp && vxl_volume_create(&d, NULL, &vi) == VXL_OK);
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(r);
    vxl_channel_style st[2];
    styles(st, 2);
    vxl_render_params p = base_params();
    p.channel_count = 2;
    p.channels = st;
    REQUIRE(vxl_renderer_set_volume(r, vi) == VXL_OK && render(r, &p, A) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(r, vp) == VXL_OK && render(r, &p, B) == VXL_OK);
    CHECK(memcmp(A, B, sizeof A) == 0);
    CHECK(alpha_sum(A, NPIX) > 1);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(vi);
    vxl_volume_destroy(vp);
}

static char g_dir[64];

/* Renders v's channels (all listed, lit) into out. */
static int render_channels(vxl_renderer *r, const vxl_volume *v, uint32_t count, float *out)
{
    vxl_channel_style st[VXL_MAX_CHANNELS];
    styles(st, count);
    vxl_render_params p = base_params();
    p.shading_off = 0;
    p.channel_count = count;
    p.channels = st;
    if (vxl_renderer_set_volume(r, v) != VXL_OK) return -1;
    return render(r, &p, out);
}

TEST(nifti_5d_and_nrrd_channel_axes_load_as_channels)
{
    const size_t V = (size_t)N * N * N;
    char path[256];
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(r);
    /* NIfTI: dim[4] 2 frames, dim[5] 3 channels; frame t of channel c is
     * six-ball plane c + 3 t, stored at (t + 2 c) volumes in */
    static uint16_t file[6 * N * N * N], mem[3 * N * N * N];
    for (int c = 0; c < 3; c++)
        for (int t = 0; t < 2; t++) memcpy(file + (size_t)(t + 2 * c) * V, g_six + (size_t)(c + 3 * t) * V, V * 2);
    memcpy(mem, g_six + 3 * V, 3 * V * 2);
    tnw_header h;
    tnw_init(&h, 1, 512, N, N, N);
    h.dim[0] = 5;
    h.dim[4] = 2;
    h.dim[5] = 3;
    snprintf(path, sizeof path, "%s/five.nii.gz", g_dir);
    REQUIRE(tnw_write(path, &h, file, sizeof file) == 0);
    vxl_load_options lo = {.struct_size = sizeof lo, .frame = 1};
    vxl_volume *v = NULL, *ref = channels_volume(mem, 3, 0);
    CHECKF(vxl_volume_load(path, &lo, &v) == VXL_OK, "five.nii.gz: %s", vxl_last_error());
    REQUIRE(v && ref);
    vxl_volume_info in = volume_info_of(v);
    CHECKF(in.channel_count == 3 && in.frame_count == 2 && in.frame == 1, "channels %u frames %u", in.channel_count,
           in.frame_count);
    CHECKF(strstr(in.notes, "NIfTI dim[5]: 3 channels (channel 0 is the scalar)") != NULL, "notes '%s'", in.notes);
    REQUIRE(render_channels(r, v, 3, A) == VXL_OK && render_channels(r, ref, 3, B) == VXL_OK);
    CHECK(memcmp(A, B, sizeof A) == 0 && alpha_sum(A, NPIX) > 1);
    vxl_volume_destroy(v);
    /* channels off: every volume a frame, as before channels */
    lo.channels = VXL_CHANNELS_OFF;
    lo.frame = 0;
    v = NULL;
    CHECK(vxl_volume_load(path, &lo, &v) == VXL_OK && v);
    if (v) {
        in = volume_info_of(v);
        CHECK(in.channel_count == 0 && in.frame_count == 6);
        vxl_volume_destroy(v);
    }
    vxl_volume_destroy(ref);

    /* NRRD: a fastest axis of 5 (vector) interleaves 5 channels */
    static uint16_t inter[5 * N * N * N];
    for (size_t i = 0; i < V; i++)
        for (int c = 0; c < 5; c++) inter[5 * i + (size_t)c] = g_six[(size_t)c * V + i];
    char hdr[256];
    int n = snprintf(hdr, sizeof hdr,
                     "NRRD0004\ntype: uint16\ndimension: 4\nsizes: 5 %d %d %d\nkinds: vector domain domain domain\n"
                     "endian: little\nencoding: raw\n\n", N, N, N);
    snprintf(path, sizeof path, "%s/five.nrrd", g_dir);
    FILE *f = fopen(path, "wb");
    REQUIRE(f);
    CHECK(fwrite(hdr, 1, (size_t)n, f) == (size_t)n && fwrite(inter, 1, sizeof inter, f) == sizeof inter);
    fclose(f);
    v = NULL;
    ref = channels_volume(g_six, 5, 0);
    CHECKF(vxl_volume_load(path, NULL, &v) == VXL_OK, "five.nrrd: %s", vxl_last_error());
    REQUIRE(v && ref);
    in = volume_info_of(v);
    CHECKF(in.channel_count == 5 && strstr(in.notes, "NRRD channel axis: 5 channels"), "notes '%s'", in.notes);
    REQUIRE(render_channels(r, v, 5, A) == VXL_OK && render_channels(r, ref, 5, B) == VXL_OK);
    CHECK(memcmp(A, B, sizeof A) == 0);
    vxl_volume_destroy(v);
    vxl_volume_destroy(ref);
    unlink(path);
    /* a 3-entry axis is colour unless channels are asked for */
    n = snprintf(hdr, sizeof hdr,
                 "NRRD0004\ntype: uint16\ndimension: 4\nsizes: 3 %d %d %d\nkinds: RGB-color domain domain domain\n"
                 "endian: little\nencoding: raw\n\n", N, N, N);
    snprintf(path, sizeof path, "%s/three.nrrd", g_dir);
    f = fopen(path, "wb");
    REQUIRE(f);
    CHECK(fwrite(hdr, 1, (size_t)n, f) == (size_t)n && fwrite(inter, 1, 3 * V * 2, f) == 3 * V * 2);
    fclose(f);
    v = NULL;
    CHECK(vxl_volume_load(path, NULL, &v) == VXL_OK && v && volume_info_of(v).components == 3 && volume_info_of(v).channel_count == 0);
    vxl_volume_destroy(v);
    v = NULL;
    vxl_load_options on = {.struct_size = sizeof on, .channels = VXL_CHANNELS_ON, .scalar_channel = 2};
    CHECK(vxl_volume_load(path, &on, &v) == VXL_OK && v && volume_info_of(v).channel_count == 3 &&
          volume_info_of(v).scalar_channel == 2 && volume_info_of(v).components == 1);
    vxl_volume_destroy(v);
    unlink(path);
    snprintf(path, sizeof path, "%s/five.nii.gz", g_dir);
    unlink(path);
    vxl_renderer_destroy(r);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_test_channels_XXXXXX");
    if (!mkdtemp(g_dir)) {
        fprintf(stderr, "mkdtemp: %s\n", strerror(errno));
        return 1;
    }
    ball(g_two, 7, 12, 12, 4.5, 40000);
    ball(g_two + N * N * N, 17, 12, 12, 4.5, 30000);
    ball(g_over, 10, 12, 12, 6, 40000);
    ball(g_over + N * N * N, 14, 12, 12, 6, 30000);
    for (int c = 0; c < 6; c++) {
        const double a = c * 3.14159265358979 / 3;
        ball(g_six + c * N * N * N, 12 + 6 * cos(a), 12 + 6 * sin(a), 12, 4, (uint16_t)(20000 + 5000 * c));
    }
    for (int c = 0; c < 6; c++)
        ball(g_sparse + c * N * N * N, c % 2 ? 19.5 : 3.5, c % 3 ? 3.5 : 19.5, c < 3 ? 3.5 : 19.5, 2.4, 50000);
    RUN(hiding_a_channel_removes_exactly_its_blob);
    RUN(additive_blending_is_the_sum_of_the_channels);
    RUN(a_channels_window_changes_only_that_channel);
    RUN(a_clip_plane_cuts_every_channel);
    RUN(skipping_over_the_union_changes_nothing);
    RUN(max_blend_takes_the_dominant_channel);
    RUN(the_scalar_is_the_chosen_channel);
    RUN(every_storage_draws_the_same_channels);
    RUN(sparse_storage_pages_in_a_channel_shown);
    RUN(the_budget_refuses_channel_pools_before_allocating);
    RUN(what_cannot_go_with_channels_is_refused);
    RUN(interleaved_and_planar_layouts_agree);
    RUN(nifti_5d_and_nrrd_channel_axes_load_as_channels);
    rmdir(g_dir);
    return TEST_SUMMARY();
}
