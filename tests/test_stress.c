/* test_stress.c - the numerical-stability stress suite.
 *
 * A matrix of adversarial volumes and views (the table in stress_cases.h),
 * each crossed with every gradient filter (0..VXL_FILTER_COUNT-1), every
 * classification mode (0..VXL_CLASSIFY_COUNT-1), shading and
 * reuse_gradients settings, gradient-magnitude opacity, and both software
 * backends (OSMesa and EGL on Mesa). Every render must:
 *   - return VXL_OK, or for deliberately invalid inputs the expected error
 *     code with a non-empty message, after which the renderer still works;
 *   - give finite colour in [0,1] with alpha >= every colour channel
 *     (premultiplied), and depth that is +inf or finite and >= 0;
 *   - stay within the sample bound: max_ray_samples <= sample_bound <=
 *     16384 + 3 (vxl_renderer_get_stats), and finish: a watchdog aborts the
 *     binary, naming the render, if one runs longer than WATCHDOG_S.
 * Some cases also expect something visible, or nothing, or an image equal to
 * the one without a scene depth. Sanitizer reports come from running the
 * build-asan binary.
 *
 * Modes. The default run renders, for every case, filter and classify mode,
 * the shaded image (shading on, reuse off). Shading off (with and without
 * reuse), shading with reuse, and the gradient-opacity modes are crossed with
 * one filter per case and classify mode, rotating through the filters from
 * case to case; reuse and gradient opacity pair each filter with one classify
 * mode. The table as a whole thus reaches every filter with every mode while
 * the number of distinct shader programs stays small: on llvmpipe each
 * program costs ~0.25 s of JIT compilation per backend and per
 * texture-binding state (format and power-of-two-ness of every bound
 * texture), which dominates the run time. --full renders every mode for every
 * filter and classify mode.
 *
 * The two backends render concurrently, one thread each (each renderer has
 * its own GL thread), which also exercises two renderers used at once.
 *
 * Usage: test_stress [--full] [--only SUBSTRING] [--skip SUBSTRING] [--backend osmesa|egl|sparse] [--serial]
 *   --full    larger images and volumes, every mode, and each render repeated
 *             over variants (views, steps, sample distances, gradient stores,
 *             jitter); run by `./build.sh stress`. Takes minutes.
 *   --only    run only the cases whose name contains SUBSTRING;
 *   --skip    and not those whose name contains SUBSTRING (for triage).
 *   --serial  one backend after the other.
 * Environment: STRESS_TIMES=1 prints the time of each case; STRESS_SLOW=S
 * prints every render slower than S seconds.
 */
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "harness.h"
#include "test_util.h"
#include "stress_cases.h"

#define MAX_PRINTED_FAILURES 8 /* per case; the rest are counted */
#define WATCHDOG_S 180         /* a render running longer than this is a hang */

/* "sparse" is OSMesa with sparse storage in page bricks of 8: every case
 * through the page table, the derived filters' brick pools included. On a
 * machine without OSMesa, "osmesa" does not run and "sparse" is on EGL
 * (main sets this from software_backend()). */
enum { BACKEND_OSMESA, BACKEND_EGL, BACKEND_SPARSE, BACKEND_N };
static uint32_t backend_ids[BACKEND_N] = {VXL_BACKEND_OSMESA, VXL_BACKEND_EGL, VXL_BACKEND_OSMESA};
static const char *const backend_names[BACKEND_N] = {"osmesa", "egl", "sparse"};
static vxl_renderer *R[BACKEND_N];
static int backend_enabled[BACKEND_N] = {1, 1, 1};

static stress_env ENV;
static const char *only_filter, *skip_filter;
static int serial;

/* ------------------------------------------------------------------ modes */

typedef struct stress_mode {
    const char *name;
    uint32_t shading, reuse, gopacity;
} stress_mode;

static const stress_mode modes[] = {
    {"shade", 1, 0, VXL_GOPACITY_OFF},
    {"noshade", 0, 0, VXL_GOPACITY_OFF},
    {"noshade+reuse", 0, 1, VXL_GOPACITY_OFF},
    {"shade+reuse", 1, 1, VXL_GOPACITY_OFF},
    {"shade+gop_boundary", 1, 0, VXL_GOPACITY_BOUNDARY},
    {"shade+reuse+gop_iso", 1, 1, VXL_GOPACITY_ISO},
    {"noshade+gop_boundary", 0, 0, VXL_GOPACITY_BOUNDARY},
    {"noshade+gop_iso", 0, 0, VXL_GOPACITY_ISO},
};
#define MODE_COUNT (int)(sizeof modes / sizeof modes[0])
#define DEFAULT_GOP_MODES 6 /* the default run uses modes[0..5] */

/* Which (filter, classify, mode) renders a case gets; see the top comment. */
static int mode_selected(size_t case_idx, uint32_t f, uint32_t cl, int m)
{
    if (ENV.full) return 1;
    if (m == 0) return 1;                /* shaded: every filter x classify mode */
    if (m >= DEFAULT_GOP_MODES) return 0;
    uint32_t rot = (uint32_t)((case_idx * 5 + cl * 3 + (size_t)m) % VXL_FILTER_COUNT);
    if (f != rot) return 0;
    if (m == 3) return cl == (f + 2) % VXL_CLASSIFY_COUNT; /* reuse: each filter with one classify mode */
    if (m == 4) return cl == f % VXL_CLASSIFY_COUNT;
    if (m == 5) return cl == (f + 1) % VXL_CLASSIFY_COUNT;
    return 1; /* shading off: one program per classify mode whatever the filter */
}

/* ----------------------------------------------------- shared bookkeeping */

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static unsigned long long n_renders, n_error_renders, n_cases_run;
static unsigned long long n_by_backend[BACKEND_N];
static double slowest_render_s;
static char slowest_label[256];

/* The watchdog thread: aborts with the label of any render in flight for
 * longer than WATCHDOG_S. */
static double render_started[BACKEND_N];
static char current_label[BACKEND_N][256];

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static double cpu_s(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) * 1e-6;
}

static void *watchdog(void *arg)
{
    (void)arg;
    for (;;) {
        sleep(1);
        pthread_mutex_lock(&lock);
        double t = now_s();
        for (int b = 0; b < BACKEND_N; b++)
            if (render_started[b] > 0 && t - render_started[b] > WATCHDOG_S) {
                fprintf(stderr, "\ntest_stress: WATCHDOG: render running for %.0f s (limit %d s): %s\n",
                        t - render_started[b], WATCHDOG_S, current_label[b]);
                printf("%d passed, %d failed\n", vxl_tests_passed, vxl_tests_failed + 1);
                fflush(stdout);
                _exit(3);
            }
        pthread_mutex_unlock(&lock);
    }
    return NULL;
}

/* One backend's share of one case. */
typedef struct case_run {
    vxl_test_ctx *T;
    const stress_case *c;
    size_t idx;
    int *failures; /* shared by the case's backends, under lock */
} case_run;

static void fail(case_run *cr, const char *label, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void fail(case_run *cr, const char *label, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    pthread_mutex_lock(&lock);
    cr->T->failed_checks++;
    if ((*cr->failures)++ < MAX_PRINTED_FAILURES) fprintf(stderr, "  FAIL %s: %s\n", label, msg);
    pthread_mutex_unlock(&lock);
}

/* ------------------------------------------------------------ assertions */

/* Checks every pixel; on failure describes the first bad one in why. hdr:
 * the PATH model's colour, an unclamped Monte Carlo sum beside the march's
 * alpha, needs only be finite and >= 0 (voxlight.h's VXL_SHADING_PATH). */
static int pixels_sane_as(const float *rgba, const float *depth, uint32_t w, uint32_t h, int hdr, char *why, size_t n)
{
    for (size_t i = 0; i < (size_t)w * h; i++) {
        const float *p = rgba + 4 * i;
        int bad = 0;
        for (int c = 0; c < 4; c++)
            if (!isfinite(p[c]) || p[c] < 0 || (p[c] > 1 && (!hdr || c == 3))) bad = 1;
        for (int c = 0; c < 3; c++)
            if (!bad && !hdr && p[c] > p[3] + 1e-6f) bad = 2;
        if (depth && (isnan(depth[i]) || depth[i] < 0)) bad = 3; /* covers -inf too */
        if (bad) {
            snprintf(why, n, "%s at pixel (%zu,%zu): rgba (%g, %g, %g, %g), depth %g",
                     bad == 1   ? "colour not finite or outside [0,1]"
                     : bad == 2 ? "colour exceeds alpha (not premultiplied)"
                                : "depth NaN or negative",
                     i % w, i / w, p[0], p[1], p[2], p[3], depth ? depth[i] : 0.0);
            return 0;
        }
    }
    return 1;
}

static int pixels_sane(const float *rgba, const float *depth, uint32_t w, uint32_t h, char *why, size_t n)
{
    return pixels_sane_as(rgba, depth, w, h, 0, why, n);
}

/* A frame of p's shading model without a depth: pixels_sane_as's rules. */
static int frame_is_sane(const vxl_render_params *p, const float *rgba, size_t npix)
{
    char why[256];
    return pixels_sane_as(rgba, NULL, (uint32_t)npix, 1, !p->shading_off && p->shading_model == VXL_SHADING_PATH, why,
                          sizeof why);
}

static double alpha_total(const float *rgba, uint32_t w, uint32_t h)
{
    double s = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) s += rgba[4 * i + 3];
    return s;
}

static int timed_render(int b, const vxl_render_params *p, float *img, float *dep, const char *label, double *dt)
{
    pthread_mutex_lock(&lock);
    snprintf(current_label[b], sizeof current_label[b], "%s", label);
    render_started[b] = now_s();
    pthread_mutex_unlock(&lock);
    double t0 = now_s();
    int rc = vxl_render(R[b], p, img, dep);
    *dt = now_s() - t0;
    pthread_mutex_lock(&lock);
    render_started[b] = 0;
    n_renders++;
    n_by_backend[b]++;
    if (*dt > slowest_render_s) {
        slowest_render_s = *dt;
        snprintf(slowest_label, sizeof slowest_label, "%s", label);
    }
    pthread_mutex_unlock(&lock);
    const char *slow = getenv("STRESS_SLOW");
    if (slow && *dt > atof(slow)) fprintf(stderr, "    slow %.3f s: %s\n", *dt, label);
    return rc;
}

/* The plain render every renderer must still manage after an error. */
static void check_still_works(case_run *cr, int b, const char *label)
{
    float img[4 * 24 * 24], dep[24 * 24];
    if (cr->c->flags & F_BAD_VOLUME) { /* the volume was the problem: a good one must work */
        static const stress_vol good = {VXL_DTYPE_F32, {8, 8, 8}, fill_ball, AFF_NONE, 0, 0, 0};
        vxl_volume *v = NULL;
        int rc = stress_make_volume(&good, &ENV, &v);
        if (rc == VXL_OK) rc = vxl_renderer_set_volume(R[b], v);
        vxl_volume_destroy(v);
        if (rc != VXL_OK) {
            fail(cr, label, "renderer broken after an error: set_volume returned %s", vxl_error_name(rc));
            return;
        }
    }
    vxl_render_params p = default_params(24, 24);
    p.azimuth_deg = 30;
    p.elevation_deg = 20;
    double dt;
    int rc = timed_render(b, &p, img, dep, label, &dt);
    char why[256];
    if (rc != VXL_OK)
        fail(cr, label, "renderer broken after an error: a plain render returned %s: %s", vxl_error_name(rc),
             vxl_renderer_error(R[b]));
    else if (!pixels_sane(img, dep, 24, 24, why, sizeof why))
        fail(cr, label, "renderer broken after an error: a plain render: %s", why);
}

static float ramp256[256 * 4]; /* the smooth ramp of sv_tf_table kind 3 */

typedef struct buffers {
    float *img, *dep, *ref;
} buffers;

/* One render of the matrix, with every assertion. Returns 1 if the render
 * failed with an error code (expected or not). */
static int render_one(case_run *cr, int b, const vxl_render_params *p, int variant, const char *label, buffers *bu,
                      stress_view_ctx *vc)
{
    const stress_case *c = cr->c;
    uint32_t w = p->width ? p->width : 512, h = p->height ? p->height : 512;
    size_t npix = (size_t)w * h;
    if (npix <= (size_t)ENV.max_image * ENV.max_image)
        for (size_t i = 0; i < npix * 4; i++) bu->img[i] = -12345.0f; /* stale output must not pass */
    double dt;
    int rc = timed_render(b, p, bu->img, bu->dep, label, &dt);
    if (c->expect_rc != VXL_OK) {
        pthread_mutex_lock(&lock);
        n_error_renders++;
        pthread_mutex_unlock(&lock);
        const char *msg = vxl_renderer_error(R[b]), *last = vxl_last_error();
        if (rc != c->expect_rc)
            fail(cr, label, "expected %s, got %s (%s)", vxl_error_name(c->expect_rc), vxl_error_name(rc),
                 rc ? msg : "no error");
        else if (!msg || !*msg || !last || !*last)
            fail(cr, label, "error %s without a message", vxl_error_name(rc));
        return rc != VXL_OK;
    }
    if (rc != VXL_OK) {
        const char *msg = vxl_renderer_error(R[b]);
        if (rc > 0 && rc < 32 && (c->alt_rc_mask & (1u << rc)) && msg && *msg) return 1; /* a clean refusal */
        fail(cr, label, "vxl_render returned %s: %s", vxl_error_name(rc), msg);
        return 1;
    }
    char why[256];
    if (!pixels_sane_as(bu->img, bu->dep, w, h, !p->shading_off && p->shading_model == VXL_SHADING_PATH, why,
                        sizeof why))
        fail(cr, label, "%s", why);

    vxl_render_stats st;
    memset(&st, 0, sizeof st);
    st.struct_size = sizeof st;
    rc = vxl_renderer_get_stats(R[b], &st);
    if (rc != VXL_OK) fail(cr, label, "get_stats: %s", vxl_error_name(rc));
    else {
        if (!(st.max_ray_samples <= st.sample_bound && st.sample_bound <= 16384 + 3))
            fail(cr, label, "unbounded: longest ray %u samples, bound %u (limit %u)", st.max_ray_samples,
                 st.sample_bound, 16384 + 3);
        if (st.rays > (uint64_t)w * h) fail(cr, label, "%u rays for %ux%u pixels", st.rays, w, h);
        if (st.samples > (uint64_t)st.rays * st.max_ray_samples)
            fail(cr, label, "%llu samples from %u rays of at most %u", (unsigned long long)st.samples, st.rays,
                 st.max_ray_samples);
        if (!(isfinite(st.effective_step) && st.effective_step > 0))
            fail(cr, label, "effective step %g", st.effective_step);
    }

    double asum = alpha_total(bu->img, w, h);
    /* gradient-magnitude opacity may rightly hide everything (a constant
     * volume has no boundary), and another view may see a thin volume edge-on
     * between pixel centres: visibility is asked of plain opacity in the
     * case's own view */
    if ((c->flags & F_VISIBLE) && p->gradient_opacity == VXL_GOPACITY_OFF && !stress_variant_moves_camera(variant) &&
        !(asum > 0))
        fail(cr, label, "nothing visible (alpha sum %g)", asum);
    if (c->flags & F_EMPTY) {
        int ok = asum == 0;
        for (size_t i = 0; i < npix; i++)
            if (!(isinf(bu->dep[i]) && bu->dep[i] > 0)) ok = 0;
        if (!ok) fail(cr, label, "expected an empty image (alpha sum %g)", asum);
    }
    if (c->flags & F_TF_MATCHES_256) {
        vxl_render_params q = *p;
        q.tf_rgba = ramp256;
        q.tf_size = 256;
        rc = timed_render(b, &q, bu->ref, NULL, label, &dt);
        double e = rc == VXL_OK ? image_rmse(bu->ref, bu->img, npix * 4) : 0;
        if (rc != VXL_OK) fail(cr, label, "the render with the 256-entry ramp: %s", vxl_error_name(rc));
        else if (!(e < 5e-3))
            fail(cr, label, "a %u-entry ramp and the 256-entry ramp give different images: rmse %g", p->tf_size, e);
    }
    if (c->flags & F_NEAR_INVARIANT) {
        vxl_render_params q = *p;
        vc_near_override = 0.1;
        c->view(&q, vc);
        vc_near_override = 0;
        rc = timed_render(b, &q, bu->ref, NULL, label, &dt);
        double e = rc == VXL_OK ? image_rmse(bu->ref, bu->img, npix * 4) : 0;
        if (rc != VXL_OK) fail(cr, label, "the render with the near plane at 0.1: %s", vxl_error_name(rc));
        else if (!(e < 2e-3))
            fail(cr, label, "the near plane changed the image of a volume far beyond it: rmse %g against near 0.1",
                 e);
    }
    if (c->flags & F_SAME_AS_NO_DEPTH) {
        vxl_render_params q = *p;
        q.scene_depth = NULL;
        rc = timed_render(b, &q, bu->ref, NULL, label, &dt);
        if (rc != VXL_OK) fail(cr, label, "the render without scene depth: %s", vxl_error_name(rc));
        else if (memcmp(bu->ref, bu->img, npix * 4 * sizeof(float)) != 0)
            fail(cr, label, "a scene depth beyond everything changed the image (rmse %g)",
                 image_rmse(bu->ref, bu->img, npix * 4));
    }
    return 0;
}

/* The mode as rendered (a case may set its own gradient opacity). */
static void mode_label(const vxl_render_params *p, char *out, size_t n)
{
    static const char *const gop[VXL_GOPACITY_COUNT] = {"", "+gop_boundary", "+gop_iso"};
    snprintf(out, n, "%s%s%s", p->shading_off ? "noshade" : "shade", p->reuse_gradients ? "+reuse" : "",
             p->gradient_opacity < VXL_GOPACITY_COUNT ? gop[p->gradient_opacity] : "+gop_invalid");
}

/* (stress_mode_params): each render mode, a MatCap and a cutaway,
 * with one filter per case in rotation. A projection or an iso-surface may
 * rightly show nothing, or something, where DVR does the opposite (a
 * transparent maximum, a surface of opacity 1 in a transparent table), so
 * only the invariants every render keeps are asked, and the scene-depth
 * invariance. Returns the number of failed renders. */
static int render_modes(case_run *cr, int b, stress_view_ctx *vc, buffers *bu)
{
    stress_case c = *cr->c;
    c.flags &= F_SAME_AS_NO_DEPTH;
    case_run run = *cr;
    run.c = &c;
    int errors = 0;
    char label[320];
    for (int m = 0; m < SM_COUNT; m++) {
        vxl_render_params p = stress_base_params(&ENV);
        p.filter = (uint32_t)((cr->idx + (size_t)m) % VXL_FILTER_COUNT);
        p.iso_value = (float)(0.5 * vc->value_min + 0.5 * vc->value_max);
        cr->c->view(&p, vc);
        vxl_matcap mc;
        vxl_cutaway cut;
        stress_mode_params(&p, m, cr->c->expect_rc == VXL_OK, vc, &mc, &cut);
        const char *fname = vxl_filter_name(p.filter);
        snprintf(label, sizeof label, "[%s] filter=%s mode=%s backend=%s", c.name, fname ? fname : "?",
                 stress_mode_render_name(m), backend_names[b]);
        errors += render_one(&run, b, &p, 0, label, bu, vc);
    }
    return errors;
}

/* the case's volume once more as an overlay in slot 0, shrunk to
 * 0.6 and turned about its centre (so the ray walks the union of two boxes
 * and samples a grid at an angle to its own), OVER or MAX and nearest,
 * linear or cubic in rotation from case to case, shaded in every other
 * case. A valid case's settings overlays refuse are reset, as the modes
 * do; an invalid case keeps them. ADD is left to test_overlays.c: its glow
 * rightly exceeds alpha, which pixels_sane forbids. Returns the number of
 * failed renders. */
static int render_overlay(case_run *cr, int b, stress_view_ctx *vc, buffers *bu, const vxl_volume *v)
{
    const stress_case *c = cr->c;
    stress_case only_depth = *c; /* as the modes: only the invariants and the scene-depth invariance */
    only_depth.flags &= F_SAME_AS_NO_DEPTH;
    case_run run = *cr;
    run.c = &only_depth;
    vxl_volume_info info = {.struct_size = sizeof info};
    vxl_volume_get_info(v, &info);
    const double a = 0.5, ca = cos(a), sa = sin(a);
    double m[16] = {0.6 * ca, 0.6 * sa, 0, 0, -0.6 * sa, 0.6 * ca, 0, 0, 0, 0, 0.6, 0, 0, 0, 0, 1}, mv[16];
    for (int r = 0; r < 3; r++) { /* voxel c stays where it is */
        m[12 + r] = vc->c[r];
        for (int k = 0; k < 3; k++) m[12 + r] -= m[k * 4 + r] * vc->c[k];
    }
    vxl_overlay_style s = {.struct_size = sizeof s, .slot = 0, .blend = cr->idx % 2 ? VXL_BLEND_MAX : VXL_BLEND_OVER,
                           .interpolation = (uint32_t)(cr->idx % VXL_INTERP_COUNT), .interpolation_set = 1,
                           .has_model = 1, .shading_off = (uint32_t)(cr->idx % 2)};
    for (int col = 0; col < 4; col++) /* model = affine * m */
        for (int r = 0; r < 4; r++) {
            mv[col * 4 + r] = 0;
            for (int k = 0; k < 4; k++) mv[col * 4 + r] += info.affine[k * 4 + r] * m[col * 4 + k];
            s.model[col * 4 + r] = (float)mv[col * 4 + r];
        }
    char label[320];
    snprintf(label, sizeof label, "[%s] overlay blend=%s interpolation=%u backend=%s", c->name, vxl_blend_name(s.blend),
             s.interpolation, backend_names[b]);
    int rc = vxl_renderer_set_overlay(R[b], 0, v);
    if (rc != VXL_OK) { /* a clean refusal (an affine that cannot be inverted) is no failure */
        if (rc == VXL_ERR_INVALID_ARGUMENT && *vxl_renderer_error(R[b])) return 0;
        fail(cr, label, "set_overlay returned %s: %s", vxl_error_name(rc), vxl_renderer_error(R[b]));
        return 1;
    }
    vxl_render_params p = stress_base_params(&ENV);
    p.iso_value = (float)(0.5 * vc->value_min + 0.5 * vc->value_max);
    c->view(&p, vc);
    if (c->expect_rc == VXL_OK) {
        p.mode = VXL_MODE_DVR;
        p.classify = p.classify == VXL_CLASSIFY_PREINT ? VXL_CLASSIFY_POST : p.classify;
        p.gradient_opacity = VXL_GOPACITY_OFF;
        p.technique = VXL_TECHNIQUE_RAYCAST;
        s.preset = p.preset;
        s.tf_rgba = p.tf_rgba;
        s.tf_size = p.tf_size;
        s.has_window = p.has_window;
        s.window_low = p.window_low;
        s.window_high = p.window_high;
        s.opacity_scale = p.opacity_scale;
    }
    p.overlay_count = 1;
    p.overlays = &s;
    int errors = render_one(&run, b, &p, 0, label, bu, vc);
    vxl_renderer_set_overlay(R[b], 0, NULL);
    return errors;
}

/* Multi-channel volumes (docs/channels.md): every channel of the case's
 * volume drawn in one march, one hidden, lit in every other case and by
 * additive blending in every other one (so two cases make two programs),
 * with the case's camera and defaults for each channel's window, on every
 * backend (the sparse one pages the channels as it pages the scalar). Only
 * the invariants are checked. Nothing for volumes without channels. */
static int render_channels(case_run *cr, int b, stress_view_ctx *vc, buffers *bu, const vxl_volume *v)
{
    vxl_volume_info info = {.struct_size = sizeof info};
    vxl_volume_get_info(v, &info);
    if (!info.channel_count) return 0;
    const stress_case *c = cr->c;
    stress_case only_depth = *c;
    only_depth.flags &= F_SAME_AS_NO_DEPTH;
    case_run run = *cr;
    run.c = &only_depth;
    vxl_channel_style st[VXL_MAX_CHANNELS];
    memset(st, 0, sizeof st);
    for (uint32_t k = 0; k < info.channel_count; k++) {
        st[k].struct_size = sizeof st[k];
        st[k].channel = k;
        st[k].hidden = k == 1;
    }
    vxl_render_params p = stress_base_params(&ENV);
    c->view(&p, vc);
    p.mode = VXL_MODE_DVR;
    p.classify = VXL_CLASSIFY_POST;
    p.gradient_opacity = VXL_GOPACITY_OFF;
    p.technique = VXL_TECHNIQUE_RAYCAST;
    p.shading_model = VXL_SHADING_PHONG;
    p.shading_off = (uint32_t)(info.channel_count <= 4);
    p.channel_blend = info.channel_count > 4 ? VXL_CHANNEL_BLEND_ADD : VXL_CHANNEL_BLEND_MAX;
    p.channel_count = info.channel_count;
    p.channels = st;
    char label[320];
    snprintf(label, sizeof label, "[%s] channels=%u blend=%s backend=%s", c->name, info.channel_count,
             vxl_channel_blend_name(p.channel_blend), backend_names[b]);
    return render_one(&run, b, &p, 0, label, bu, vc);
}

/* labels: a 24x20x16 label volume laid over the case's volume by
 * its own affine (the case's, scaled to the box: another grid), ids 1..5 in
 * bands inside an ellipsoid (3 hidden, 2 and 4 translucent) and a block of
 * id 65535, drawn in every label mode (surface, mask, tint), shaded in
 * every other case. A valid case's settings labels refuse (modes, slicing)
 * are reset, as the modes do; an invalid case keeps them. A label affine
 * the library cannot use (the case's is not invertible) is a clean
 * refusal. Returns the number of failed renders. */
static int render_labels(case_run *cr, int b, stress_view_ctx *vc, buffers *bu, const vxl_volume *v)
{
    enum { LX = 24, LY = 20, LZ = 16 };
    uint16_t ids[LX * LY * LZ];
    for (int z = 0; z < LZ; z++)
        for (int y = 0; y < LY; y++)
            for (int x = 0; x < LX; x++) {
                double u = (x + 0.5) / LX - 0.5, w = (y + 0.5) / LY - 0.5, t = (z + 0.5) / LZ - 0.5;
                uint16_t id = u * u / 0.2 + w * w / 0.16 + t * t / 0.2 <= 1 ? (uint16_t)(1 + (x + 2 * y + 3 * z) / 4 % 5) : 0;
                ids[x + LX * (y + LY * z)] = x >= 2 && x < 6 && y >= 2 && y < 5 && z < 3 ? 65535 : id;
            }
    vxl_volume_info info = {.struct_size = sizeof info};
    vxl_volume_get_info(v, &info);
    const uint32_t ld[3] = {LX, LY, LZ};
    const stress_case *c = cr->c;
    case_run run = *cr;
    stress_case only_depth = *c; /* as the modes: only the invariants and the scene-depth invariance */
    only_depth.flags &= F_SAME_AS_NO_DEPTH;
    run.c = &only_depth;
    vxl_volume_desc d = {.struct_size = sizeof d, .dtype = VXL_DTYPE_U16, .dims = {LX, LY, LZ}, .has_affine = 1, .data = ids};
    for (int col = 0; col < 4; col++) /* label voxel i -> case voxel (i + 0.5) * dims / ld - 0.5 -> world */
        for (int r = 0; r < 4; r++) {
            double sum = col < 3 ? info.affine[col * 4 + r] * info.dims[col] / ld[col] : info.affine[12 + r];
            for (int k = 0; col == 3 && k < 3; k++) sum += info.affine[k * 4 + r] * (0.5 * info.dims[k] / ld[k] - 0.5);
            d.affine[col * 4 + r] = sum;
        }
    char label[320];
    snprintf(label, sizeof label, "[%s] labels backend=%s", c->name, backend_names[b]);
    vxl_volume *lab = NULL;
    int rc = vxl_volume_create(&d, NULL, &lab);
    if (rc == VXL_OK) rc = vxl_renderer_set_labels(R[b], lab);
    vxl_volume_destroy(lab);
    if (rc != VXL_OK) { /* a clean refusal (an affine that cannot be inverted) is no failure */
        if (rc == VXL_ERR_INVALID_ARGUMENT && *vxl_last_error()) return 0;
        fail(cr, label, "the label volume: %s: %s", vxl_error_name(rc), vxl_last_error());
        return 1;
    }
    vxl_label_entry e[6];
    memset(e, 0, sizeof e);
    for (int k = 0; k < 6; k++) {
        e[k].struct_size = sizeof e[k];
        e[k].id = k < 5 ? k + 1 : 65535;
        e[k].color[0] = 0.2f * (float)k;
        e[k].color[1] = 1.0f - 0.15f * (float)k;
        e[k].color[2] = 0.5f;
        e[k].color[3] = k == 1 ? 0.5f : k == 3 ? 0.3f : 1.0f;
        e[k].visible = k != 2;
    }
    int errors = 0;
    for (uint32_t m = 0; m < VXL_LABEL_MODE_COUNT; m++) {
        vxl_label_style s = {.struct_size = sizeof s, .mode = m, .entry_count = 6, .entries = e};
        vxl_render_params p = stress_base_params(&ENV);
        p.iso_value = (float)(0.5 * vc->value_min + 0.5 * vc->value_max);
        p.shading_off = (uint32_t)(cr->idx % 2);
        c->view(&p, vc);
        if (c->expect_rc == VXL_OK) {
            p.mode = VXL_MODE_DVR;
            p.technique = VXL_TECHNIQUE_RAYCAST;
        }
        p.labels = &s;
        snprintf(label, sizeof label, "[%s] labels=%s classify=%u backend=%s", c->name, vxl_label_mode_name(m),
                 p.classify, backend_names[b]);
        errors += render_one(&run, b, &p, 0, label, bu, vc);
    }
    vxl_renderer_set_labels(R[b], NULL);
    return errors;
}

typedef struct backend_job {
    case_run cr;
    int b;
    const vxl_volume *v;
} backend_job;

/* Every render of one case on one backend. */
static void *run_backend(void *arg)
{
    backend_job *j = arg;
    case_run *cr = &j->cr;
    const stress_case *c = cr->c;
    int b = j->b;
    char label[320];
    stress_view_ctx vc;
    stress_view_ctx_init(&vc, &ENV, j->v);
    size_t nmax = (size_t)ENV.max_image * ENV.max_image;
    buffers bu = {malloc(nmax * 4 * sizeof(float)), malloc(nmax * sizeof(float)), malloc(nmax * 4 * sizeof(float))};
    if (!bu.img || !bu.dep || !bu.ref || !vc.depth || !vc.tf) {
        fail(cr, c->name, "out of memory");
        goto done;
    }
    snprintf(label, sizeof label, "[%s] backend=%s (set_volume)", c->name, backend_names[b]);
    int rc = vxl_renderer_set_volume(R[b], j->v);
    if (rc != VXL_OK) {
        fail(cr, label, "set_volume returned %s: %s", vxl_error_name(rc), vxl_renderer_error(R[b]));
        goto done;
    }
    int errors = 0;
    for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++)
        for (uint32_t cl = 0; cl < VXL_CLASSIFY_COUNT; cl++)
            for (int m = 0; m < MODE_COUNT; m++) {
                if (!mode_selected(cr->idx, f, cl, m)) continue;
                if (!ENV.full && (c->flags & F_ONE_FILTER) && f != cr->idx % VXL_FILTER_COUNT) continue;
                for (int var = 0; var < ENV.variant_count; var++) {
                    /* --full: every mode at the base variant; the other variants
                     * shaded, every filter, one classify mode in rotation */
                    if (var > 0 && (m != 0 || cl != (uint32_t)((cr->idx + (size_t)var) % VXL_CLASSIFY_COUNT)))
                        continue;
                    vxl_render_params p = stress_base_params(&ENV);
                    p.filter = f;
                    p.classify = cl;
                    p.shading_off = !modes[m].shading;
                    p.reuse_gradients = modes[m].reuse;
                    p.gradient_opacity = modes[m].gopacity;
                    p.iso_value = (float)(0.5 * vc.value_min + 0.5 * vc.value_max);
                    c->view(&p, &vc); /* last: the invalid-input cases may override anything */
                    if (!stress_apply_variant(&p, &vc, c, var)) continue;
                    const char *fname = vxl_filter_name(p.filter);
                    char mname[64];
                    mode_label(&p, mname, sizeof mname);
                    snprintf(label, sizeof label, "[%s] filter=%s classify=%u mode=%s backend=%s%s%s", c->name,
                             fname ? fname : "?", p.classify, mname, backend_names[b],
                             ENV.variant_count > 1 ? " variant=" : "",
                             ENV.variant_count > 1 ? stress_variant_name(var) : "");
                    errors += render_one(cr, b, &p, var, label, &bu, &vc);
                }
            }
    errors += render_modes(cr, b, &vc, &bu);
    errors += render_overlay(cr, b, &vc, &bu, j->v);
    errors += render_labels(cr, b, &vc, &bu, j->v);
    errors += render_channels(cr, b, &vc, &bu, j->v);
    if (errors) { /* after any failed render the renderer must still work */
        snprintf(label, sizeof label, "[%s] backend=%s (a plain render after %d failed ones)", c->name,
                 backend_names[b], errors);
        check_still_works(cr, b, label);
    }
done:
    free(bu.img);
    free(bu.dep);
    free(bu.ref);
    stress_view_ctx_free(&vc);
    return NULL;
}

static void run_case(vxl_test_ctx *T_, const stress_case *c, size_t idx)
{
    int failures = 0;
    case_run cr = {T_, c, idx, &failures};
    double t0 = now_s(), c0 = cpu_s();
    unsigned long long r0 = n_renders;
    vxl_volume *v = NULL;
    int rc = stress_make_volume(&c->vol, &ENV, &v);
    n_cases_run++;
    if (rc != VXL_OK) {
        const char *msg = vxl_last_error();
        char label[128];
        snprintf(label, sizeof label, "[%s] (creating the volume)", c->name);
        if ((c->flags & F_ALLOW_CREATE_ERROR) && msg && *msg)
            fprintf(stderr, "    %s: the volume was refused cleanly (%s: %s)\n", c->name, vxl_error_name(rc), msg);
        else
            fail(&cr, label, "vxl_volume_create returned %s: %s", vxl_error_name(rc), msg);
        return;
    }
    backend_job jobs[BACKEND_N];
    pthread_t th[BACKEND_N];
    int started[BACKEND_N] = {0};
    for (int b = 0; b < BACKEND_N; b++) {
        jobs[b] = (backend_job){cr, b, v};
        if (!R[b]) continue;
        if (serial || pthread_create(&th[b], NULL, run_backend, &jobs[b]) != 0) run_backend(&jobs[b]);
        else started[b] = 1;
    }
    for (int b = 0; b < BACKEND_N; b++)
        if (started[b]) pthread_join(th[b], NULL);
    vxl_volume_destroy(v);
    if (getenv("STRESS_TIMES"))
        fprintf(stderr, "    %-36s %5llu renders %7.2f s wall %7.2f s cpu\n", c->name, n_renders - r0, now_s() - t0,
                cpu_s() - c0);
    if (failures > MAX_PRINTED_FAILURES)
        fprintf(stderr, "  ... [%s]: %d failures in all (%d printed)\n", c->name, failures, MAX_PRINTED_FAILURES);
}

static void run_group(vxl_test_ctx *T_, int group)
{
    for (size_t i = 0; i < STRESS_CASE_COUNT; i++) {
        const stress_case *c = &stress_cases[i];
        if (c->group != group) continue;
        if (only_filter && !strstr(c->name, only_filter)) continue;
        if (skip_filter && strstr(c->name, skip_filter)) continue;
        if ((c->flags & F_FULL_ONLY) && !ENV.full) continue;
        run_case(T_, c, i);
    }
}

#define GROUP_TEST(g) \
    TEST(g) { run_group(T_, GROUP_##g); }
GROUP_TEST(scene_depth)
GROUP_TEST(values)
GROUP_TEST(dtypes_and_scaling)
GROUP_TEST(shapes)
GROUP_TEST(affines)
GROUP_TEST(cameras)
GROUP_TEST(projections)
GROUP_TEST(classification)
GROUP_TEST(steps)
GROUP_TEST(lighting)
GROUP_TEST(invalid_inputs)

static vxl_renderer *make_sparse_renderer(void)
{
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.backend = backend_ids[BACKEND_SPARSE];
    o.storage = VXL_STORAGE_SPARSE;
    o.page_brick = 8;
    vxl_renderer *r = NULL;
    return vxl_renderer_create(&o, &r) == VXL_OK ? r : NULL;
}

/* every valid case streamed (vxl_volume_stream_copy: bricks read
 * on demand by the renderer's loader thread), F12 and progressive, with an
 * on-the-fly filter and a classification in rotation; the unshaded F12
 * frame equals the whole volume's in the same sparse storage (the same
 * bricks). */
TEST(streamed)
{
    vxl_renderer *rs = make_sparse_renderer(), *rw = make_sparse_renderer();
    REQUIRE(rs && rw);
    const size_t nmax = (size_t)ENV.max_image * ENV.max_image;
    float *img = malloc(nmax * 4 * sizeof(float)), *ref = malloc(nmax * 4 * sizeof(float));
    REQUIRE(img && ref);
    int cases = 0;
    for (size_t i = 0; i < STRESS_CASE_COUNT; i++) {
        const stress_case *c = &stress_cases[i];
        if (c->expect_rc != VXL_OK || ((c->flags & F_FULL_ONLY) && !ENV.full)) continue;
        if ((only_filter && !strstr(c->name, only_filter)) || (skip_filter && strstr(c->name, skip_filter))) continue;
        vxl_volume *v = NULL, *sv = NULL;
        if (stress_make_volume(&c->vol, &ENV, &v) != VXL_OK) continue; /* refused cleanly: run_case reports it */
        int rc = vxl_volume_stream_copy(v, 0, &sv);
        CHECKF(rc == VXL_OK, "[%s] stream copy: %s", c->name, vxl_last_error());
        stress_view_ctx vc;
        stress_view_ctx_init(&vc, &ENV, v);
        vxl_render_params p = stress_base_params(&ENV);
        p.filter = (uint32_t)(i % VXL_FILTER_PRECOMPUTED); /* the derived filters refuse streamed volumes */
        p.classify = (uint32_t)(i % VXL_CLASSIFY_COUNT);
        p.iso_value = (float)(0.5 * vc.value_min + 0.5 * vc.value_max);
        if (!rc && vc.depth && vc.tf) c->view(&p, &vc);
        const size_t npix = (size_t)p.width * p.height;
        const int s1 = !rc && npix <= nmax ? vxl_renderer_set_volume(rs, sv) : -1;
        const int s2 = s1 >= 0 ? vxl_renderer_set_volume(rw, v) : -1;
        CHECKF(s1 == VXL_OK || s2 != VXL_OK, "[%s] set_volume of the streamed copy: %s", c->name, vxl_renderer_error(rs));
        if (s1 == VXL_OK && s2 == VXL_OK) {
            cases++;
            p.progressive = 1;
            int r1 = vxl_render(rs, &p, img, NULL);
            const int clean = r1 != VXL_OK && (c->alt_rc_mask & (1u << r1));
            CHECKF(r1 == VXL_OK || clean, "[%s] progressive: %s", c->name, vxl_renderer_error(rs));
            CHECKF(r1 != VXL_OK || frame_is_sane(&p, img, npix), "[%s] progressive frame not sane", c->name);
            p.progressive = 0;
            int r2 = vxl_render(rs, &p, img, NULL);
            CHECKF(r2 == VXL_OK || (c->alt_rc_mask & (1u << r2)), "[%s] F12: %s", c->name, vxl_renderer_error(rs));
            CHECKF(r2 != VXL_OK || frame_is_sane(&p, img, npix), "[%s] F12 frame not sane", c->name);
            /* unshaded, as the shading of a gradient near 0 (a checker seen
             * through Sobel8) turns on the last bit of the pool's addressing */
            p.shading_off = 1;
            r2 = vxl_render(rs, &p, img, NULL);
            int r3 = vxl_render(rw, &p, ref, NULL);
            CHECKF(r2 == r3, "[%s] streamed %d, whole %d: %s", c->name, r2, r3, vxl_renderer_error(rs));
            if (r2 == VXL_OK && r3 == VXL_OK) {
                const double psnr = image_psnr(img, ref, npix * 4);
                CHECKF(image_is_sane(img, NULL, npix) && psnr >= 60, "[%s] streamed against whole: %.1f dB", c->name, psnr);
            }
        }
        stress_view_ctx_free(&vc);
        vxl_volume_destroy(sv);
        vxl_volume_destroy(v);
    }
    fprintf(stderr, "    streamed: %d cases\n", cases);
    CHECK(cases > 0 || only_filter || skip_filter);
    free(img);
    free(ref);
    vxl_renderer_destroy(rs);
    vxl_renderer_destroy(rw);
}

/* The matrix needs its backends: a missing one is a failure, not a skip. */
TEST(backends_open)
{
    for (int b = 0; b < BACKEND_N; b++) {
        if (!backend_enabled[b]) continue;
        CHECKF(R[b] != NULL, "cannot create the %s renderer", backend_names[b]);
        if (!R[b]) continue;
        vxl_renderer_info info;
        memset(&info, 0, sizeof info);
        info.struct_size = sizeof info;
        CHECK(vxl_renderer_get_info(R[b], &info) == VXL_OK && info.backend == backend_ids[b]);
        fprintf(stderr, "    %s: %s, %s, %s\n", backend_names[b], info.backend_name, info.gl_renderer,
                info.gl_version);
    }
}

TEST(case_table_is_complete)
{
    /* at least 50 cases, every group populated, unique names */
    CHECKF(STRESS_CASE_COUNT >= 50, "%zu cases", (size_t)STRESS_CASE_COUNT);
    for (int g = 0; g < GROUP_COUNT; g++) {
        int n = 0;
        for (size_t i = 0; i < STRESS_CASE_COUNT; i++) n += stress_cases[i].group == g;
        CHECKF(n > 0, "group %d is empty", g);
    }
    for (size_t i = 0; i < STRESS_CASE_COUNT; i++)
        for (size_t j = i + 1; j < STRESS_CASE_COUNT; j++)
            CHECKF(strcmp(stress_cases[i].name, stress_cases[j].name) != 0, "duplicate case %s",
                   stress_cases[i].name);
    /* the default subset still reaches every filter x classify x mode (when
     * the table is long enough to rotate through them all) */
    for (uint32_t f = 0; f < VXL_FILTER_COUNT; f++)
        for (uint32_t cl = 0; cl < VXL_CLASSIFY_COUNT; cl++)
            for (int m = 0; m < DEFAULT_GOP_MODES; m++) {
                int hit = 0;
                for (size_t i = 0; i < STRESS_CASE_COUNT && !hit; i++) {
                    const stress_case *c = &stress_cases[i];
                    int runs = c->expect_rc == VXL_OK && (ENV.full || !(c->flags & F_FULL_ONLY));
                    hit = runs && mode_selected(i, f, cl, m);
                }
                int needed = m < 3 || (m == 3 && cl == (f + 2) % VXL_CLASSIFY_COUNT) ||
                             (m == 4 && cl == f % VXL_CLASSIFY_COUNT) ||
                             (m == 5 && cl == (f + 1) % VXL_CLASSIFY_COUNT);
                if (ENV.full || needed)
                    CHECKF(hit, "filter %u classify %u mode %s never rendered", f, cl, modes[m].name);
            }
}

int main(int argc, char **argv)
{
    int full = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--full")) full = 1;
        else if (!strcmp(argv[i], "--serial")) serial = 1;
        else if (!strcmp(argv[i], "--only") && i + 1 < argc) only_filter = argv[++i];
        else if (!strcmp(argv[i], "--skip") && i + 1 < argc) skip_filter = argv[++i];
        else if (!strcmp(argv[i], "--backend") && i + 1 < argc) {
            const char *b = argv[++i];
            backend_enabled[BACKEND_OSMESA] = !strcmp(b, "osmesa");
            backend_enabled[BACKEND_EGL] = !strcmp(b, "egl");
            backend_enabled[BACKEND_SPARSE] = !strcmp(b, "sparse");
        } else {
            fprintf(stderr, "usage: %s [--full] [--only SUBSTRING] [--skip SUBSTRING] [--backend osmesa|egl|sparse] [--serial]\n",
                    argv[0]);
            return 2;
        }
    }
    backend_ids[BACKEND_SPARSE] = software_backend();
    if (!osmesa_installed() && backend_enabled[BACKEND_OSMESA] && backend_enabled[BACKEND_EGL]) {
        /* the default matrix: no OSMesa to run, EGL and sparse-on-EGL remain
         * (an explicit --backend osmesa still asks for it, and fails) */
        backend_enabled[BACKEND_OSMESA] = 0;
        fprintf(stderr, "stress: no OSMesa on this machine: backends egl and sparse (on egl)\n");
    }
    stress_env_init(&ENV, full);
    for (int i = 0; i < 256; i++) {
        float x = i / 255.0f;
        ramp256[4 * i] = ramp256[4 * i + 1] = ramp256[4 * i + 2] = x;
        ramp256[4 * i + 3] = 0.3f * x;
    }
    double t0 = now_s();
    for (int b = 0; b < BACKEND_N; b++)
        if (backend_enabled[b]) R[b] = b == BACKEND_SPARSE ? make_sparse_renderer() : make_renderer(backend_ids[b]);
    pthread_t wd;
    pthread_create(&wd, NULL, watchdog, NULL);
    pthread_detach(wd);
    fprintf(stderr,
            "stress: %s run, %ux%u images, volumes of %u, %zu cases x %d filters x %d classify modes x %s modes "
            "x %d backends%s\n",
            full ? "full" : "default", ENV.image, ENV.image, ENV.n, (size_t)STRESS_CASE_COUNT, VXL_FILTER_COUNT,
            VXL_CLASSIFY_COUNT, full ? "8" : "1-6", (int)(R[0] != NULL) + (int)(R[1] != NULL) + (int)(R[2] != NULL),
            full ? " x up to 12 variants" : "");

    RUN(backends_open);
    RUN(case_table_is_complete);
    RUN(scene_depth); /* first: the scene-depth texture then stays bound, one llvmpipe shader state fewer */
    RUN(values);
    RUN(dtypes_and_scaling);
    RUN(shapes);
    RUN(affines);
    RUN(cameras);
    RUN(projections);
    RUN(classification);
    RUN(steps);
    RUN(lighting);
    RUN(invalid_inputs);
    RUN(streamed);

    pthread_mutex_lock(&lock); /* the watchdog must not fire during teardown */
    for (int b = 0; b < BACKEND_N; b++) render_started[b] = 0;
    pthread_mutex_unlock(&lock);
    for (int b = 0; b < BACKEND_N; b++) vxl_renderer_destroy(R[b]);
    fprintf(stderr,
            "stress: %llu cases, %llu renders (osmesa %llu, egl %llu, sparse %llu; %llu deliberately invalid) in %.1f s wall, "
            "%.1f s cpu; slowest render %.3f s: %s\n",
            n_cases_run, n_renders, n_by_backend[0], n_by_backend[1], n_by_backend[2], n_error_renders, now_s() - t0, cpu_s(),
            slowest_render_s, slowest_label);
    return TEST_SUMMARY();
}
