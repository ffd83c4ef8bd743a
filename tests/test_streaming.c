/* test_streaming.c - the GL side of streamed volumes
 * (docs/streaming.md): a streamed copy (vxl_volume_stream_copy) renders what
 * the whole volume renders in sparse storage (same bricks, PSNR >= 60 dB,
 * for several classifications and cameras); progressive frames start
 * coarse, mix levels per brick as fine bricks arrive and converge to the
 * F12 frame; a budget too small for full resolution falls back to a
 * coarser level; the renderer outlives the
 * volume it streams from; destroying a renderer while it loads is clean
 * (run under the ASan build); a failing read is a clear error, not a crash,
 * and the next frame recovers; what needs every voxel refuses. A wrapper
 * around the source's read (a slow disk, a failing disk, bytes counted)
 * stands in for a file source. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "brick_source.h" /* the wrapper replaces the source's read */
#include "harness.h"
#include "test_util.h"
#include "volume.h"
#include "voxlight_dev.h"

#define W 64
#define H 64

/* ------------------------------------------------ a wrapped source */

static const vxl_brick_source_ops *inner_ops;
static atomic_int read_delay_us;  /* per read of level 0 */
static atomic_int fail_reads;     /* 1: every read fails */
static atomic_int reads;
static atomic_int gate_below;  /* reads of a level below this wait at the gate ... */
static atomic_int gate_passes; /* ... unless a pass is left: each brick takes one */
static pthread_mutex_t gate_lock = PTHREAD_MUTEX_INITIALIZER;
static uint32_t gate_passed[4096][4]; /* the bricks (level, origin) that took one: a second read of one passes */
static uint32_t gate_n;

static int gate_open_for(uint32_t level, const uint32_t lo[3])
{
    pthread_mutex_lock(&gate_lock);
    int open = 0;
    for (uint32_t i = 0; i < gate_n && !open; i++)
        open = gate_passed[i][0] == level && !memcmp(gate_passed[i] + 1, lo, 3 * sizeof *lo);
    if (!open && atomic_load(&gate_passes) > 0 && gate_n < 4096) {
        atomic_fetch_sub(&gate_passes, 1);
        gate_passed[gate_n][0] = level;
        memcpy(gate_passed[gate_n++] + 1, lo, 3 * sizeof *lo);
        open = 1;
    }
    pthread_mutex_unlock(&gate_lock);
    return open;
}

/* Holds the loader's reads of fine levels back, so a test decides exactly
 * how many fine bricks arrive whatever the number of loader threads (a
 * brick wanted again while in flight may be read twice: it passes free).
 * Bounded (20 s), so a failing test cannot hang its destroy. */
static void gate(uint32_t level, const uint32_t lo[3])
{
    for (int i = 0; i < 20000 && (int)level < atomic_load(&gate_below) && !gate_open_for(level, lo); i++)
        nanosleep(&(struct timespec){0, 1000000L}, NULL);
}

static int wrapped_read(vxl_brick_source *s, uint32_t level, const uint32_t lo[3], const uint32_t size[3], void *out,
                        vxl_err *e)
{
    atomic_fetch_add(&reads, 1);
    if (atomic_load(&fail_reads)) { /* as a file source fails (vxl_fail is the library's own) */
        e->code = VXL_ERR_IO;
        snprintf(e->msg, sizeof e->msg, "test disk: sector not found");
        return VXL_ERR_IO;
    }
    gate(level, lo);
    if (level == 0 && atomic_load(&read_delay_us)) nanosleep(&(struct timespec){0, atomic_load(&read_delay_us) * 1000L}, NULL);
    int rc = inner_ops->read(s, level, lo, size, out, e);
    if (!rc) /* as a file source counts what it read */
        __atomic_fetch_add(&s->bytes_read, (uint64_t)size[0] * size[1] * size[2] * (s->texture_bits / 8), __ATOMIC_RELAXED);
    return rc;
}

static void wrapped_close(vxl_brick_source *s) { inner_ops->close(s); }

static const vxl_brick_source_ops wrapped_ops = {wrapped_read, wrapped_close};

/* A streamed copy of whole with n_levels levels whose reads go through the wrapper. */
static vxl_volume *streamed(const vxl_volume *whole, uint32_t n_levels)
{
    vxl_volume *v = NULL;
    if (vxl_volume_stream_copy(whole, n_levels, &v) != VXL_OK) return NULL;
    inner_ops = v->source->ops;
    v->source->ops = &wrapped_ops;
    atomic_store(&read_delay_us, 0);
    atomic_store(&fail_reads, 0);
    atomic_store(&gate_below, 0);
    atomic_store(&gate_passes, 0);
    gate_n = 0; /* no loader runs between tests */
    return v;
}

/* ------------------------------------------------ volumes and renderers */

/* 8-bit Gaussian balls on a zero background, 93x78x70 (partial page
 * bricks at the far faces), so many bricks are constant and, under a
 * narrow window, few are visible. */
static vxl_volume *balls_u8(void)
{
    enum { NX = 93, NY = 78, NZ = 70 };
    static uint8_t d[NX * NY * NZ];
    const double c[4][4] = {{24, 20, 18, 3}, {64, 56, 50, 4}, {62, 18, 56, 2.5}, {28, 60, 40, 3.5}};
    for (int z = 0; z < NZ; z++)
        for (int y = 0; y < NY; y++)
            for (int x = 0; x < NX; x++) {
                double v = 0;
                for (int b = 0; b < 4; b++) {
                    double dx = x - c[b][0], dy = y - c[b][1], dz = z - c[b][2];
                    v += exp(-(dx * dx + dy * dy + dz * dz) / (2 * c[b][3] * c[b][3]));
                }
                v = v > 1 ? 1 : v;
                d[x + NX * (y + NY * z)] = v < 0.02 ? 0 : (uint8_t)lround(v * 255);
            }
    vxl_volume_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.struct_size = sizeof desc;
    desc.dtype = VXL_DTYPE_U8;
    desc.dims[0] = NX;
    desc.dims[1] = NY;
    desc.dims[2] = NZ;
    desc.data = d;
    vxl_volume *v = NULL;
    vxl_volume_create(&desc, NULL, &v);
    return v;
}

static vxl_renderer *make_in(uint32_t storage, uint32_t page_brick, uint64_t budget)
{
    return make_stored_renderer(storage, page_brick, budget, 0);
}

static vxl_render_stats stats_of(vxl_renderer *r) { return renderer_stats(r); }

/* The balls, a streamed copy of them with n_levels levels, and a renderer
 * (storage auto, page bricks of 8, budget; 0 = default) holding it. */
typedef struct fixture {
    vxl_volume *whole, *v;
    vxl_renderer *r;
} fixture;

static int fixture_open(fixture *x, uint32_t n_levels, uint64_t budget)
{
    x->whole = balls_u8();
    x->v = x->whole ? streamed(x->whole, n_levels) : NULL;
    x->r = make_in(VXL_STORAGE_AUTO, 8, budget);
    return x->v && x->r && vxl_renderer_set_volume(x->r, x->v) == VXL_OK;
}

static void fixture_close(fixture *x)
{
    vxl_renderer_destroy(x->r);
    vxl_volume_destroy(x->v);
    vxl_volume_destroy(x->whole);
}

static float img[W * H * 4]; /* the image every test renders into */

/* The scenes a streamed volume must render as the whole one does. */
#define SCENES 6
static vxl_render_params scene(int k)
{
    vxl_render_params p = phantom_scene(W, H, VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
    if (k == 0) p.window_low = 230, p.window_high = 250; /* (data units) the balls' cores: few bricks visible */
    if (k != 0) p.window_low = 5, p.window_high = 80; /* their tails: more */
    /* k == 1: the whole balls, a classification that needs more bricks */
    if (k == 2) p.azimuth_deg = 130, p.elevation_deg = -40;   /* the camera moved */
    if (k == 3) p.classify = VXL_CLASSIFY_PRE;                /* pre-classification runs over the pool */
    if (k == 4) p.classify = VXL_CLASSIFY_PREINT, p.no_skip = 1;
    if (k == 5) p.shading_model = VXL_SHADING_SHADOWED;     /* the illumination volume samples the pool */
    return p;
}

/* ------------------------------------------------ tests */

TEST(streamed_renders_what_the_whole_volume_renders)
{
    vxl_volume *whole = balls_u8();
    REQUIRE(whole);
    vxl_volume *v = streamed(whole, 3);
    vxl_renderer *a = make_in(VXL_STORAGE_SPARSE, 8, 0), *b = make_in(VXL_STORAGE_AUTO, 8, 0),
                 *d = make_in(VXL_STORAGE_DENSE, 0, 0);
    REQUIRE(v && a && b && d);
    REQUIRE(vxl_renderer_set_volume(a, whole) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(d, whole) == VXL_OK);
    REQUIRE(vxl_renderer_set_volume(b, v) == VXL_OK);
    static float ia[W * H * 4], id[W * H * 4];
    float *ib = img;
    uint32_t first_resident = 0;
    for (int k = 0; k < SCENES; k++) {
        vxl_render_params p = scene(k);
        REQUIRE(vxl_render(a, &p, ia, NULL) == VXL_OK);
        REQUIRE(vxl_render(d, &p, id, NULL) == VXL_OK);
        int rc = vxl_render(b, &p, ib, NULL);
        CHECKF(rc == VXL_OK, "scene %d: %s", k, vxl_last_error());
        vxl_render_stats sa = stats_of(a), sb = stats_of(b);
        double psnr = image_psnr(ia, ib, W * H * 4), dense = image_psnr(id, ib, W * H * 4);
        fprintf(stderr, "  scene %d: streamed vs sparse %.1f dB, vs dense %.1f dB, %u of %u bricks (whole: %u), %llu bytes read\n",
                k, psnr, dense, sb.pages_resident, sb.pages_total, sa.pages_resident, (unsigned long long)sb.bytes_read);
        CHECKF(psnr >= 60, "scene %d: %.1f dB", k, psnr);
        CHECKF(dense >= 60, "scene %d: %.1f dB against dense", k, dense);
        CHECK(alpha_sum(ib, W * H) > 1);
        CHECK(sb.storage == VXL_STORAGE_SPARSE);
        CHECK(sb.stream_level == 0 && sb.lod_level == 0 && sb.refine_pending == 0);
        /* the index finds the same constant and visible bricks as the CPU pass */
        CHECK(sb.pages_total == sa.pages_total && sb.pages_constant == sa.pages_constant);
        CHECK(sb.pages_resident == sa.pages_resident);
        CHECK(sb.load_ms >= 0);
        if (k == 0) first_resident = sb.pages_resident;
        if (k == 1) /* the new classification read the bricks it newly sees, and only those */
            CHECK(sb.pages_resident > first_resident && sb.bytes_read > 0 &&
                  sb.bytes_read <= (uint64_t)(sb.pages_resident - first_resident) * 1000);
    }
    /* the gradient probe reads every data brick (no frame to bound them) */
    const float pts[9] = {12, 10, 9.5f, 30.25f, 9, 27.5f, 20, 20, 18};
    float ga[9], gb[9];
    vxl_render_params q = scene(1);
    CHECK(vxl_probe_gradients(a, &q, pts, 3, ga) == VXL_OK);
    CHECKF(vxl_probe_gradients(b, &q, pts, 3, gb) == VXL_OK, "%s", vxl_last_error());
    for (int i = 0; i < 9; i++) CHECKF(fabsf(ga[i] - gb[i]) <= 1e-6f * (1 + fabsf(ga[i])), "%d: %g %g", i, ga[i], gb[i]);
    /* bytes read are per frame: a frame that needs no new brick reads none */
    vxl_render_params p = scene(1);
    REQUIRE(vxl_render(b, &p, ib, NULL) == VXL_OK);
    CHECK(stats_of(b).bytes_read == 0);
    vxl_renderer_destroy(a);
    vxl_renderer_destroy(b);
    vxl_renderer_destroy(d);
    vxl_volume_destroy(v);
    vxl_volume_destroy(whole);
}

TEST(the_first_frame_reads_bytes_and_the_float_volume_matches)
{
    const double prm[4] = {22, 20, 18, 7};
    vxl_volume *whole = make_volume_f32(45, 40, 37, field_blob, prm);
    REQUIRE(whole);
    vxl_volume *v = streamed(whole, 2);
    vxl_renderer *a = make_in(VXL_STORAGE_SPARSE, 16, 0), *b = make_in(VXL_STORAGE_SPARSE, 16, 0);
    REQUIRE(v && a && b);
    REQUIRE(vxl_renderer_set_volume(a, whole) == VXL_OK && vxl_renderer_set_volume(b, v) == VXL_OK);
    static float ia[W * H * 4];
    float *ib = img;
    vxl_render_params p = default_params(W, H);
    REQUIRE(vxl_render(a, &p, ia, NULL) == VXL_OK);
    REQUIRE(vxl_render(b, &p, ib, NULL) == VXL_OK);
    vxl_render_stats s = stats_of(b);
    double psnr = image_psnr(ia, ib, W * H * 4);
    fprintf(stderr, "  float blob: %.1f dB, %u bricks, %llu bytes read\n", psnr, s.pages_resident,
            (unsigned long long)s.bytes_read);
    CHECK(psnr >= 60);
    /* each resident brick read once, ghost included (clamped at the edges) */
    CHECK(s.bytes_read > 0 && s.bytes_read <= (uint64_t)s.pages_resident * 18 * 18 * 18 * 4);
    CHECK(s.bytes_read >= (uint64_t)s.pages_resident * 8 * 8 * 8 * 4);
    vxl_renderer_destroy(a);
    vxl_renderer_destroy(b);
    vxl_volume_destroy(v);
    vxl_volume_destroy(whole);
}

TEST(a_volume_over_the_texture_limit_streams)
{
    const double prm[4] = {1.0 / 2100, 0.01, 0.01, 0};
    vxl_volume *whole = make_volume_f32(2100, 24, 24, field_ramp, prm); /* over llvmpipe's 2048 */
    REQUIRE(whole);
    vxl_volume *v = streamed(whole, 0);
    vxl_renderer *a = make_in(VXL_STORAGE_SPARSE, 32, 0), *b = make_in(VXL_STORAGE_AUTO, 32, 0);
    REQUIRE(v && a && b);
    REQUIRE(vxl_renderer_set_volume(a, whole) == VXL_OK && vxl_renderer_set_volume(b, v) == VXL_OK);
    enum { WW = 256 }; /* 8 voxels a pixel along the volume */
    static float ia[WW * WW * 4], ib[WW * WW * 4];
    vxl_render_params p = phantom_scene(WW, WW, VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST);
    p.window_low = 0.3f;
    p.window_high = 1.0f;
    p.azimuth_deg = p.elevation_deg = 0;
    REQUIRE(vxl_render(a, &p, ia, NULL) == VXL_OK);
    CHECKF(vxl_render(b, &p, ib, NULL) == VXL_OK, "%s", vxl_last_error());
    const double psnr = image_psnr(ia, ib, WW * WW * 4);
    fprintf(stderr, "  2100x24x24: %.1f dB, %u bricks, alpha %.1f\n", psnr, stats_of(b).pages_resident, alpha_sum(ib, WW * WW));
    CHECK(psnr >= 60 && alpha_sum(ib, WW * WW) > 10);
    vxl_renderer_destroy(a);
    vxl_renderer_destroy(b);
    vxl_volume_destroy(v);
    vxl_volume_destroy(whole);
}

TEST(progressive_frames_start_coarse_and_converge_to_the_f12_frame)
{
    fixture x;
    REQUIRE(fixture_open(&x, 3, 0));
    vxl_renderer *r = x.r, *f12 = make_in(VXL_STORAGE_AUTO, 8, 0);
    REQUIRE(f12 && vxl_renderer_set_volume(f12, x.v) == VXL_OK);
    static float ref[W * H * 4];
    vxl_render_params p = scene(1);
    REQUIRE(vxl_render(f12, &p, ref, NULL) == VXL_OK);
    vxl_render_stats sf = stats_of(f12);
    CHECK(sf.refine_pending == 0 && sf.stream_level == 0 && sf.load_ms > 0);
    atomic_store(&read_delay_us, 3000); /* a slow disk: full resolution arrives over many frames */
    p.progressive = 1;
    REQUIRE(vxl_render(r, &p, img, NULL) == VXL_OK);
    vxl_render_stats s = stats_of(r);
    fprintf(stderr, "  first progressive frame: level %u, %u bricks pending, waited %.1f ms\n", s.stream_level,
            s.refine_pending, s.load_ms);
    CHECK(s.stream_level > 0 && s.refine_pending > 0);
    CHECK(alpha_sum(img, W * H) > 1); /* something is drawn at once */
    uint32_t frames = 1, last_level = s.stream_level, rose = 0;
    while (s.refine_pending && frames < 2000) {
        nanosleep(&(struct timespec){0, 10 * 1000000L}, NULL);
        REQUIRE(vxl_render(r, &p, img, NULL) == VXL_OK);
        s = stats_of(r);
        rose += s.stream_level > last_level;
        last_level = s.stream_level;
        frames++;
    }
    fprintf(stderr, "  converged after %u frames\n", frames);
    CHECK(s.refine_pending == 0 && s.stream_level == 0);
    CHECK(rose == 0); /* never coarser than the frame before */
    double psnr = image_psnr(img, ref, W * H * 4);
    CHECKF(psnr >= 60, "%.1f dB", psnr);
    atomic_store(&read_delay_us, 0);
    vxl_renderer_destroy(f12);
    fixture_close(&x);
}

/* Per pixel, the largest difference over the channels. */
static float pixel_diff(const float *a, const float *b, int i)
{
    float d = 0;
    for (int c = 0; c < 4; c++) d = fmaxf(d, fabsf(a[4 * i + c] - b[4 * i + c]));
    return d;
}

/* Renders progressive frames until cond or 2000 frames, counting in rose
 * the frames whose refine_pending or coarsest level drawn rose. */
#define REFINE_UNTIL(r, p, out, s, cond, rose)                                           \
    for (int n_ = 0; !(cond) && n_ < 2000; n_++) {                                      \
        const vxl_render_stats prev_ = (s);                                             \
        nanosleep(&(struct timespec){0, 2 * 1000000L}, NULL);                          \
        REQUIRE(vxl_render((r), (p), (out), NULL) == VXL_OK);                           \
        (s) = stats_of(r);                                                              \
        (rose) += (s).refine_pending > prev_.refine_pending || (s).stream_level > prev_.stream_level; \
    }

/* The F12 frame of level 2: the smallest budget from `budget` up (x1.25)
 * that draws it. 0 when none does (or a finer level comes first). */
static int level2_frame(vxl_volume *v, const vxl_render_params *p, uint64_t budget, float *out)
{
    for (int i = 0; i < 16; i++, budget += budget / 4) {
        vxl_renderer *r = make_in(VXL_STORAGE_AUTO, 8, budget);
        if (!r || vxl_renderer_set_volume(r, v) != VXL_OK) {
            vxl_renderer_destroy(r);
            continue;
        }
        const int rc = vxl_render(r, p, out, NULL);
        const uint32_t level = stats_of(r).stream_level;
        vxl_renderer_destroy(r);
        if (rc == VXL_OK) return level == 2;
    }
    return 0;
}

TEST(progressive_frames_mix_levels_per_brick)
{
    fixture x;
    REQUIRE(fixture_open(&x, 3, 0));
    vxl_renderer *r = x.r, *f12 = make_in(VXL_STORAGE_AUTO, 8, 0);
    REQUIRE(f12 && vxl_renderer_set_volume(f12, x.v) == VXL_OK);
    static float ref[W * H * 4], lvl2[W * H * 4], coarse[W * H * 4];
    vxl_render_params p = scene(1);
    REQUIRE(vxl_render(f12, &p, ref, NULL) == VXL_OK);
    const uint32_t visible = stats_of(f12).pages_resident;
    /* the F12 frame of level 2 (a budget only it fits, as in the fallback test) */
    const uint64_t budget2 = (uint64_t)visible * 1000 * 2 / 3;
    REQUIRE(level2_frame(x.v, &p, budget2, lvl2));

    /* nothing finer than level 2 arrives: every brick of level 0 reads its
     * level-2 ancestor (4x coarser), which is the level-2 F12 frame */
    atomic_store(&gate_below, 2);
    p.progressive = 1;
    REQUIRE(vxl_render(r, &p, img, NULL) == VXL_OK);
    vxl_render_stats s = stats_of(r);
    double psnr = image_psnr(img, lvl2, W * H * 4);
    fprintf(stderr, "  level 2 only: drawn %u, %u pending, %.1f dB against level 2's F12 frame\n", s.stream_level,
            s.refine_pending, psnr);
    CHECK(s.lod_level == 0 && s.stream_level == 2 && s.refine_pending == visible);
    CHECKF(psnr >= 60, "%.1f dB", psnr);
    /* so do the paths that read the pool through the table: pre-classified
     * pool, pre-integration, the illumination volume, MIP and ISO; and
     * cubic smoothing, whose coefficients are voxels (paged_fetch: the
     * ancestor interpolated at each voxel, a smoothing of level 2 as the
     * level-2 frame's spline is) */
    for (int v = 0; v < 6; v++) {
        vxl_render_params q = scene(v < 3 ? v + 3 : 1);
        if (v == 3) q.mode = VXL_MODE_MIP;
        if (v == 4) q.mode = VXL_MODE_ISO, q.iso_value = 60;
        if (v == 5) q.filter = VXL_FILTER_CUBIC_SMOOTH;
        q.illumination_size = 8; /* the least, so the small budget does not halve it */
        CHECKF(level2_frame(x.v, &q, budget2, lvl2), "variant %d: no level-2 F12 frame", v);
        q.progressive = 1;
        int rc = vxl_render(r, &q, img, NULL);
        CHECKF(rc == VXL_OK, "variant %d: %s", v, vxl_last_error());
        s = stats_of(r);
        const double db = image_psnr(img, lvl2, W * H * 4);
        fprintf(stderr, "  variant %d: drawn %u, %.1f dB against level 2's F12 frame, alpha %.1f\n", v, s.stream_level, db,
                alpha_sum(img, W * H));
        CHECK(s.stream_level == 2 && alpha_sum(img, W * H) > 1);
        CHECKF(db >= (v == 5 ? 40 : 60), "variant %d: %.1f dB", v, db); /* paged_fetch read the slot as level 0: 30 dB */
    }
    REQUIRE(vxl_render(r, &p, img, NULL) == VXL_OK);
    s = stats_of(r);

    /* level 1 arrives, level 0 not: every brick reads its level-1 parent */
    int rose = 0;
    atomic_store(&gate_below, 1);
    REFINE_UNTIL(r, &p, img, s, s.stream_level == 1, rose);
    CHECK(s.stream_level == 1 && s.refine_pending == visible);
    memcpy(coarse, img, sizeof coarse);

    /* a third of level 0's visible bricks arrive (the nearest to the eye) */
    const uint32_t k = visible / 3;
    atomic_store(&gate_passes, (int)k);
    REFINE_UNTIL(r, &p, img, s, s.refine_pending == visible - k, rose);
    CHECKF(s.refine_pending == visible - k && s.stream_level == 1, "%u pending, level %u", s.refine_pending, s.stream_level);
    /* part of the image is the F12 frame, the rest still level 1's */
    uint32_t fine = 0, still = 0, differ = 0;
    for (int i = 0; i < W * H; i++) {
        if (pixel_diff(ref, coarse, i) < 0.02f) continue; /* the levels agree there */
        differ++;
        fine += pixel_diff(img, ref, i) < 1e-3f;
        still += pixel_diff(img, coarse, i) < 1e-3f;
    }
    const double to_f12 = image_psnr(img, ref, W * H * 4), coarse_to_f12 = image_psnr(coarse, ref, W * H * 4);
    fprintf(stderr, "  %u of %u bricks: of %u pixels where the levels differ, %u are the F12 frame's, %u level 1's "
            "(%.1f dB to F12, level 1 %.1f dB)\n", k, visible, differ, fine, still, to_f12, coarse_to_f12);
    CHECK(fine > 0 && still > 0);
    CHECK(to_f12 > coarse_to_f12);

    /* the rest arrives: the frame refines brick by brick to the F12 frame */
    atomic_store(&gate_below, 0);
    REFINE_UNTIL(r, &p, img, s, s.refine_pending == 0, rose);
    psnr = image_psnr(img, ref, W * H * 4);
    fprintf(stderr, "  refined: %.1f dB against F12\n", psnr);
    CHECK(s.refine_pending == 0 && s.stream_level == 0);
    CHECK(rose == 0); /* neither pending bricks nor the coarsest level drawn ever rose */
    CHECKF(psnr >= 60, "%.1f dB", psnr);
    vxl_renderer_destroy(f12);
    fixture_close(&x);
}

TEST(a_small_budget_falls_back_to_a_coarser_level)
{
    fixture x;
    REQUIRE(fixture_open(&x, 3, 0));
    vxl_render_params p = scene(1);
    REQUIRE(vxl_render(x.r, &p, img, NULL) == VXL_OK);
    const vxl_render_stats full = stats_of(x.r);
    /* two thirds of the pool full resolution needs (bricks of 10^3 bytes
     * with their ghost): level 1, an eighth of the bricks, fits */
    const uint64_t budget = (uint64_t)full.pages_resident * 1000 * 2 / 3;
    vxl_renderer *small = make_in(VXL_STORAGE_AUTO, 8, budget);
    REQUIRE(small);
    REQUIRE(vxl_renderer_set_volume(small, x.v) == VXL_OK);
    int rc = vxl_render(small, &p, img, NULL);
    CHECKF(rc == VXL_OK, "%s", vxl_last_error());
    vxl_render_stats s = stats_of(small);
    fprintf(stderr, "  budget %.1f KiB: level %u (drawn %u), %.1f KiB resident, full resolution wanted %.1f KiB\n",
            budget / 1024.0, s.lod_level, s.stream_level, s.resident_bytes / 1024.0, s.lod_wanted_bytes / 1024.0);
    CHECK(s.lod_level >= 1 && s.stream_level == s.lod_level && s.refine_pending == 0);
    CHECK(s.lod_wanted_bytes > budget);
    CHECK(s.resident_bytes <= budget);
    CHECK(alpha_sum(img, W * H) > 1);
    vxl_renderer_destroy(small);
    /* a budget even the coarsest level misses fails, naming it */
    vxl_renderer *tiny = make_in(VXL_STORAGE_AUTO, 8, 6000);
    REQUIRE(tiny);
    rc = vxl_renderer_set_volume(tiny, x.v);
    if (rc == VXL_OK) rc = vxl_render(tiny, &p, img, NULL);
    CHECK(rc == VXL_ERR_LIMIT);
    CHECK(strstr(vxl_last_error(), "budget") != NULL);
    vxl_renderer_destroy(tiny);
    fixture_close(&x);
}

TEST(the_renderer_outlives_the_volume_and_destroy_while_loading_is_clean)
{
    fixture x;
    REQUIRE(fixture_open(&x, 3, 0));
    vxl_renderer *r = x.r;
    vxl_volume_destroy(x.v); /* the renderer holds the source */
    x.v = NULL;
    vxl_render_params p = scene(0);
    CHECK(vxl_render(r, &p, img, NULL) == VXL_OK);
    CHECK(alpha_sum(img, W * H) > 1);
    /* a slow disk and a progressive frame: the loader is mid-read at destroy */
    vxl_volume *v2 = streamed(x.whole, 3);
    REQUIRE(v2);
    REQUIRE(vxl_renderer_set_volume(r, v2) == VXL_OK);
    atomic_store(&read_delay_us, 20000);
    p.progressive = 1;
    CHECK(vxl_render(r, &p, img, NULL) == VXL_OK);
    CHECK(stats_of(r).refine_pending > 0);
    const int before = atomic_load(&reads);
    vxl_renderer_destroy(r); /* joins the loader after its read in progress */
    x.r = NULL;
    const int after = atomic_load(&reads);
    nanosleep(&(struct timespec){0, 50 * 1000000L}, NULL);
    CHECK(atomic_load(&reads) == after); /* nothing reads after destroy */
    CHECK(after - before <= 1);
    vxl_volume_destroy(v2);
    atomic_store(&read_delay_us, 0);
    fixture_close(&x);
}

TEST(a_failing_read_is_a_clear_error_and_the_next_frame_recovers)
{
    fixture x;
    REQUIRE(fixture_open(&x, 3, 0));
    vxl_renderer *r = x.r;
    vxl_render_params p = scene(0);
    atomic_store(&fail_reads, 1);
    int rc = vxl_render(r, &p, img, NULL);
    CHECK(rc == VXL_ERR_IO);
    CHECK(strstr(vxl_last_error(), "sector not found") != NULL);
    CHECK(strstr(vxl_renderer_error(r), "reading a brick") != NULL);
    p.progressive = 1; /* the viewport fails the same way, without waiting forever */
    CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_IO);
    atomic_store(&fail_reads, 0);
    p.progressive = 0;
    rc = vxl_render(r, &p, img, NULL);
    CHECKF(rc == VXL_OK, "%s", vxl_last_error());
    CHECK(alpha_sum(img, W * H) > 1);
    fixture_close(&x);
}

TEST(what_needs_every_voxel_refuses_a_streamed_volume)
{
    fixture x;
    REQUIRE(fixture_open(&x, 2, 0));
    vxl_renderer *r = x.r, *dense = make_in(VXL_STORAGE_DENSE, 0, 0), *bricked = make_in(VXL_STORAGE_BRICKED, 8, 0);
    vxl_volume *v = x.v;
    REQUIRE(dense && bricked);
    CHECK(vxl_renderer_set_volume(dense, v) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vxl_last_error(), "streamed") != NULL);
    CHECK(vxl_renderer_set_volume(bricked, v) == VXL_ERR_INVALID_ARGUMENT);
    for (uint32_t filter = VXL_FILTER_PRECOMPUTED; filter <= VXL_FILTER_CUBIC; filter += VXL_FILTER_CUBIC - VXL_FILTER_PRECOMPUTED) {
        vxl_render_params p = phantom_scene(W, H, filter, VXL_CLASSIFY_POST);
        CHECK(vxl_render(r, &p, img, NULL) == VXL_ERR_INVALID_ARGUMENT);
        CHECK(strstr(vxl_last_error(), "streamed") != NULL);
    }
    CHECK(vxl_renderer_set_labels(r, v) == VXL_ERR_INVALID_ARGUMENT);
    vxl_render_params p = scene(0);
    CHECK(vxl_render(r, &p, img, NULL) == VXL_OK); /* still renders */
    vxl_renderer_destroy(dense);
    vxl_renderer_destroy(bricked);
    fixture_close(&x);
}

int main(void)
{
    RUN(streamed_renders_what_the_whole_volume_renders);
    RUN(the_first_frame_reads_bytes_and_the_float_volume_matches);
    RUN(a_volume_over_the_texture_limit_streams);
    RUN(progressive_frames_start_coarse_and_converge_to_the_f12_frame);
    RUN(progressive_frames_mix_levels_per_brick);
    RUN(a_small_budget_falls_back_to_a_coarser_level);
    RUN(the_renderer_outlives_the_volume_and_destroy_while_loading_is_clean);
    RUN(a_failing_read_is_a_clear_error_and_the_next_frame_recovers);
    RUN(what_needs_every_voxel_refuses_a_streamed_volume);
    return TEST_SUMMARY();
}
