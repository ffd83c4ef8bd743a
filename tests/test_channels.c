/* test_channels.c - multi-channel volumes (docs/channels.md;
 * csrc/volume/channel_volume.c, csrc/frame/frame_channels.c,
 * csrc/channels/channels.c, shaders/lib/channels.glsl): channels with
 * disjoint blobs, where hiding one removes exactly its blob and solo shows
 * only one; additive blending equals the sum of the channels drawn one at a
 * time, lit and unlit, with two texture groups (six channels); a channel's
 * window changes only its own pixels; skipping over the union changes
 * nothing; a clip plane cuts every channel; the scalar is the chosen
 * channel, bit for bit a one-channel volume; what cannot go with channels
 * is refused with a message; NIfTI
 * 5D (dim[5] channels, dim[4] frames) and NRRD channel axes load as
 * channels by the channels mode and render as the same voxels in memory. */
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

TEST(hiding_a_channel_removes_exactly_its_blob)
{
    vxl_volume *v = channels_volume(g_two, 2, 0);
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(v && r);
    REQUIRE(vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_channel_style st[2];
    styles(st, 2);
    vxl_render_params p = base_params();
    p.channel_count = 2;
    p.channels = st;
    REQUIRE(render(r, &p, A) == VXL_OK); /* both */
    st[1].hidden = 1;
    REQUIRE(render(r, &p, B) == VXL_OK); /* channel 0 alone */
    st[1].hidden = 0;
    st[1].solo = 1;
    REQUIRE(render(r, &p, C) == VXL_OK); /* channel 1 alone */
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
    CHECKF(only0 > 20 && only1 > 20, "blob pixels: %d, %d", only0, only1);
    CHECKF(bad == 0, "%d pixels changed where they should not", bad);
    /* the default colours: channel 0 red, channel 1 green */
    double g0 = 0, r1 = 0;
    for (int i = 0; i < NPIX; i++) {
        g0 += B[4 * i + 1] + B[4 * i + 2];
        r1 += C[4 * i + 0] + C[4 * i + 2];
    }
    CHECKF(g0 == 0 && r1 == 0, "pure channel colours: %g %g", g0, r1);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
}

/* The sum of the channels drawn one at a time (solo) against all drawn. */
static void check_additive(vxl_test_ctx *T_, const uint16_t *data, uint32_t count, int shaded)
{
    vxl_volume *v = channels_volume(data, count, 0);
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(v && r);
    REQUIRE(vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_channel_style st[VXL_MAX_CHANNELS];
    styles(st, count);
    vxl_render_params p = base_params();
    p.shading_off = !shaded;
    p.channel_count = count;
    p.channels = st;
    REQUIRE(render(r, &p, A) == VXL_OK);
    memset(S, 0, sizeof S);
    for (uint32_t c = 0; c < count; c++) {
        for (uint32_t k = 0; k < count; k++) st[k].solo = k == c;
        REQUIRE(render(r, &p, B) == VXL_OK);
        for (int i = 0; i < NPIX * 4; i++) S[i] += B[i];
    }
    double peak = 0;
    for (int i = 0; i < NPIX; i++) peak = fmax(peak, S[4 * i + 3]);
    CHECKF(peak > 0.05 && peak < 1.0, "the sum's largest alpha %g (overlap visible, nothing clamped)", peak);
    const double d = max_diff(A, S, NPIX * 4);
    CHECKF(d < 1e-5, "%u channels%s: additive blending differs from the sum of the channels by %g", count,
           shaded ? " lit" : "", d);
    CHECK(image_is_sane(A, NULL, NPIX));
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
}

TEST(additive_blending_is_the_sum_of_the_channels)
{
    check_additive(T_, g_over, 2, 0);
    check_additive(T_, g_over, 2, 1);
    check_additive(T_, g_six, 6, 1); /* two texture groups */
}

TEST(a_clip_plane_cuts_every_channel)
{
    vxl_volume *v = channels_volume(g_two, 2, 0);
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(v && r);
    REQUIRE(vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_channel_style st[2];
    styles(st, 2);
    vxl_render_params p = base_params();
    p.shading_off = 0;
    p.channel_count = 2;
    p.channels = st;
    st[1].solo = 1;
    REQUIRE(render(r, &p, C) == VXL_OK); /* channel 1 alone, uncut */
    st[1].solo = 0;
    st[1].hidden = 1;
    REQUIRE(render(r, &p, B) == VXL_OK); /* channel 0 alone, uncut */
    st[1].hidden = 0;
    /* keep x <= 12 (identity affine: world = voxel): channel 1's blob (x 12.5..21.5) is cut away */
    vxl_cutaway cut = {.struct_size = sizeof cut, .clip_plane_count = 1};
    cut.clip_planes[0].plane[0] = -1;
    cut.clip_planes[0].plane[3] = 12;
    p.cutaway = &cut;
    REQUIRE(render(r, &p, A) == VXL_OK);
    int left = 0, bad = 0;
    for (int i = 0; i < NPIX; i++) {
        if (C[4 * i + 3] > 0 && B[4 * i + 3] == 0) bad += A[4 * i + 3] != 0;
        left += A[4 * i + 3] > 0;
    }
    CHECKF(bad == 0, "%d pixels of the cut channel remain", bad);
    CHECKF(left > 20, "channel 0's blob: %d pixels", left);
    CHECK(image_is_sane(A, NULL, NPIX));
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
}

TEST(a_channels_window_changes_only_that_channel)
{
    vxl_volume *v = channels_volume(g_two, 2, 0);
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(v && r);
    REQUIRE(vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_channel_style st[2];
    styles(st, 2);
    vxl_render_params p = base_params();
    p.channel_count = 2;
    p.channels = st;
    REQUIRE(render(r, &p, A) == VXL_OK);
    st[1].has_window = 1;
    st[1].window_low = 0;
    st[1].window_high = 20000; /* half the range: channel 1 brighter and more opaque */
    REQUIRE(render(r, &p, B) == VXL_OK);
    st[1].solo = 1;
    REQUIRE(render(r, &p, C) == VXL_OK); /* channel 1 alone, new window */
    st[1].solo = 0;
    st[1].hidden = 1;
    REQUIRE(render(r, &p, S) == VXL_OK); /* channel 0 alone */
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
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
}

TEST(skipping_over_the_union_changes_nothing)
{
    vxl_volume *v = channels_volume(g_sparse, 6, 0);
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(v && r);
    REQUIRE(vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_channel_style st[6];
    styles(st, 6);
    st[2].hidden = 1;
    /* a table transparent over its first half: the background is empty
     * (the occupancy rule widens by entries around a brick's range, so a
     * ramp from 0 would occupy every brick) */
    static const float tf[8 * 4] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                                    1, 1, 1, 0.3f, 1, 1, 1, 0.4f, 1, 1, 1, 0.5f, 1, 1, 1, 0.6f};
    for (int c = 0; c < 6; c++) {
        st[c].tf_rgba = tf;
        st[c].tf_size = 8;
    }
    vxl_render_params p = base_params();
    p.shading_off = 0;
    p.channel_count = 6;
    p.channels = st;
    REQUIRE(render(r, &p, A) == VXL_OK);
    vxl_render_stats s1 = renderer_stats(r);
    p.no_skip = 1;
    REQUIRE(render(r, &p, B) == VXL_OK);
    vxl_render_stats s2 = renderer_stats(r);
    CHECKF(max_diff(A, B, NPIX * 4) == 0, "skipping changed the image by %g", max_diff(A, B, NPIX * 4));
    CHECKF(s1.samples < s2.samples, "samples with skipping %llu, without %llu", (unsigned long long)s1.samples,
           (unsigned long long)s2.samples);
    CHECKF(s1.bricks_occupied == 5 && s1.bricks_total == 27, "occupied %u of %u: the five drawn balls' bricks",
           s1.bricks_occupied, s1.bricks_total);
    CHECK(alpha_sum(A, NPIX) > 1);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
}

TEST(max_blend_takes_the_dominant_channel)
{
    /* the same ball twice, channel 1 with twice the opacity: max draws
     * channel 1 alone (its opacity is the larger at every sample) */
    static uint16_t same[2 * N * N * N];
    ball(same, 12, 12, 12, 7, 40000);
    ball(same + N * N * N, 12, 12, 12, 7, 40000);
    vxl_volume *v = channels_volume(same, 2, 0);
    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(v && r);
    REQUIRE(vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_channel_style st[2];
    styles(st, 2);
    st[1].opacity_scale = 3.0f;
    vxl_render_params p = base_params();
    p.channel_count = 2;
    p.channels = st;
    p.channel_blend = VXL_CHANNEL_BLEND_MAX;
    REQUIRE(render(r, &p, A) == VXL_OK);
    st[1].solo = 1;
    REQUIRE(render(r, &p, B) == VXL_OK);
    CHECKF(max_diff(A, B, NPIX * 4) < 1e-6, "max differs from the dominant channel by %g", max_diff(A, B, NPIX * 4));
    CHECK(alpha_sum(A, NPIX) > 1);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
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
    vxl_volume *v = channels_volume(g_two, 2, 0);
    REQUIRE(v);
    /* paged storage holds the scalar, and refuses drawing the channels */
    vxl_channel_style st2[2];
    styles(st2, 2);
    vxl_render_params q = base_params();
    for (uint32_t mode = VXL_STORAGE_BRICKED; mode <= VXL_STORAGE_COMPRESSED; mode++) {
        vxl_renderer *rb = make_stored_renderer(mode, 0, 0, 0);
        REQUIRE(rb);
        q.channel_count = 0;
        CHECK(vxl_renderer_set_volume(rb, v) == VXL_OK && render(rb, &q, A) == VXL_OK);
        q.channel_count = 2;
        q.channels = st2;
        CHECK(render(rb, &q, A) == VXL_ERR_INVALID_ARGUMENT && strstr(vxl_renderer_error(rb), "needs dense storage"));
        vxl_renderer_destroy(rb);
    }

    vxl_renderer *r = make_renderer(software_backend());
    REQUIRE(r && vxl_renderer_set_volume(r, v) == VXL_OK);
    vxl_channel_style st[2];
    styles(st, 2);
    vxl_render_params p = base_params();
    p.channel_count = 2;
    p.channels = st;
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
    vxl_renderer_destroy(r);
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
    vxl_volume_destroy(v);
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
    RUN(what_cannot_go_with_channels_is_refused);
    RUN(interleaved_and_planar_layouts_agree);
    RUN(nifti_5d_and_nrrd_channel_axes_load_as_channels);
    rmdir(g_dir);
    return TEST_SUMMARY();
}
