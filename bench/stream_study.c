/* stream_study.c - data larger than memory (docs/streaming.md
 * "Benchmark"): for one file, the times a user waits and the memory it
 * takes, under a memory budget split as the CLI splits it (half for the
 * volume's CPU side, the other half for the GL side of a streamed volume).
 *
 *   open      vxl_volume_load; for a gzip file, the first open (which writes
 *             the bricked cache, into a fresh folder unless --cache-dir) and
 *             the second (which reads it)
 *   first     set_volume plus the first progressive frame (the coarse one)
 *   refined   from the start of the first frame until a progressive frame
 *             reports refine_pending 0 (the loader thread refining meanwhile)
 *   F12       a fresh renderer's first progressive = 0 frame (waits for
 *             every brick it needs)
 *   read      bytes read from the file or cache over the whole run
 *   peak RSS  VmHWM of /proc/self/status at the end (CPU and GL sides, as
 *             the software GL keeps textures in this process)
 *
 * Prints one CSV row (with --out, appended under a header when the file is
 * new) and one markdown row (with --md, likewise). Times on a loaded machine
 * mean nothing; the lead runs it on a quiet one. Command:
 *   make -j1 build/voxlight-streambench && ./build/voxlight-streambench FILE
 *     [--memory-budget 2G] [--size 512] [--streaming auto|on|off] [--cache-dir DIR]
 *     [--label NAME] [--max-refine-s 600] [--out CSV] [--md MD] */
#include <errno.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench_util.h"

typedef struct bench_args {
    const char *file, *cache_dir, *label, *out, *md;
    uint64_t budget;
    uint32_t size, streaming;
    double max_refine_s;
} bench_args;

typedef struct bench_result {
    double open_first_ms, open_cached_ms; /* cached: -1 when no cache applies */
    double first_ms, refined_ms, f12_ms, f12_load_ms;
    uint32_t first_level, refine_frames, refined; /* refined: 0 when max_refine_s ran out */
    uint64_t bytes_read, peak_rss_kb, open_rss_kb;
    vxl_volume_info info;
} bench_result;

/* VmHWM (peak resident set) in kB; 0 when unreadable. */
static uint64_t peak_rss_kb(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    uint64_t kb = 0;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "VmHWM:", 6)) kb = strtoull(line + 6, NULL, 10);
    if (f) fclose(f);
    return kb;
}

static int parse_size(const char *s, uint64_t *out)
{
    char *end;
    double v = strtod(s, &end);
    const double mult = *end == 'G' || *end == 'g' ? 1073741824.0 : *end == 'M' || *end == 'm' ? 1048576.0
                        : *end == 'K' || *end == 'k' ? 1024.0 : *end == 0 ? 1.0 : 0;
    if (!(v > 0) || !mult || (*end && end[1])) return 0;
    *out = (uint64_t)(v * mult);
    return 1;
}

static int is_gzip(const char *path)
{
    unsigned char m[2] = {0};
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(m, 1, 2, f) : 0;
    if (f) fclose(f);
    return n == 2 && m[0] == 0x1f && m[1] == 0x8b;
}

static int remove_entry(const char *p, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(p);
}

static int load(const bench_args *a, const char *cache_dir, vxl_volume **v, double *ms)
{
    vxl_load_options lo = {.struct_size = sizeof lo, .memory_budget_bytes = a->budget / 2,
                           .streaming = a->streaming, .cache_dir = cache_dir};
    const double t = now_ms();
    int rc = vxl_volume_load(a->file, &lo, v);
    *ms = now_ms() - t;
    if (rc) fprintf(stderr, "voxlight-streambench: %s\n", vxl_last_error());
    return rc;
}

static int make_renderer(const bench_args *a, const vxl_volume *v, vxl_renderer **r)
{
    vxl_volume_info in = {.struct_size = sizeof in};
    vxl_volume_get_info(v, &in);
    /* the CLI's split: a streamed volume's GL side gets the other half */
    vxl_renderer_options o = {.struct_size = sizeof o, .memory_budget_bytes = in.streamed ? a->budget / 2 : a->budget};
    if (vxl_renderer_create(&o, r) || vxl_renderer_set_volume(*r, v)) {
        fprintf(stderr, "voxlight-streambench: %s\n", *r ? vxl_renderer_error(*r) : vxl_last_error());
        return 1;
    }
    return 0;
}

static int render(vxl_renderer *r, vxl_render_params *p, uint32_t progressive, float *img, vxl_render_stats *st)
{
    p->progressive = progressive;
    if (vxl_render(r, p, img, NULL)) {
        fprintf(stderr, "voxlight-streambench: %s\n", vxl_renderer_error(r));
        return 1;
    }
    st->struct_size = sizeof *st;
    return vxl_renderer_get_stats(r, st);
}

/* The progressive frames, first to refined; then the F12 frame on a fresh
 * renderer. */
static int frames(const bench_args *a, const vxl_volume *v, bench_result *res)
{
    float *img = malloc((size_t)a->size * a->size * 4 * sizeof *img);
    vxl_renderer *r = NULL;
    vxl_render_params p = base_params(a->size);
    p.preset = VXL_PRESET_BONE;
    vxl_render_stats st;
    if (!img) return 1;
    const double t0 = now_ms();
    int rc = make_renderer(a, v, &r) || render(r, &p, 1, img, &st);
    if (!rc) {
        res->first_ms = now_ms() - t0;
        res->first_level = st.stream_level;
        res->refine_frames = 1;
        res->bytes_read += st.bytes_read;
        while (!rc && st.refine_pending > 0 && now_ms() - t0 < a->max_refine_s * 1e3) {
            rc = render(r, &p, 1, img, &st);
            res->refine_frames++;
            res->bytes_read += st.bytes_read;
        }
        res->refined = st.refine_pending == 0;
        res->refined_ms = now_ms() - t0;
    }
    vxl_renderer_destroy(r);
    r = NULL;
    if (!rc) {
        const double t1 = now_ms();
        rc = make_renderer(a, v, &r) || render(r, &p, 0, img, &st);
        res->f12_ms = now_ms() - t1;
        res->f12_load_ms = st.load_ms;
        res->bytes_read += st.bytes_read;
    }
    vxl_renderer_destroy(r);
    free(img);
    return rc;
}

static int run(const bench_args *a, bench_result *res)
{
    char tmp[] = "/tmp/voxlight-streambench-XXXXXX";
    const int gz = is_gzip(a->file);
    const char *cache = a->cache_dir;
    if (gz && !cache) { /* a fresh cache folder: the first open is a real first open */
        if (!mkdtemp(tmp)) return fprintf(stderr, "voxlight-streambench: mkdtemp: %s\n", strerror(errno)), 1;
        cache = tmp;
    }
    vxl_volume *v = NULL;
    int rc = load(a, cache, &v, &res->open_first_ms);
    res->open_cached_ms = -1;
    if (!rc && gz) { /* the second open reads the cache the first wrote */
        vxl_volume_destroy(v);
        v = NULL;
        rc = load(a, cache, &v, &res->open_cached_ms);
    }
    res->open_rss_kb = peak_rss_kb();
    if (!rc) rc = frames(a, v, res);
    if (!rc) {
        res->info.struct_size = sizeof res->info;
        vxl_volume_get_info(v, &res->info);
        /* the loads' own reads (index, cache) plus the frames' */
        if (res->info.bytes_read > res->bytes_read) res->bytes_read = res->info.bytes_read;
    }
    vxl_volume_destroy(v);
    res->peak_rss_kb = peak_rss_kb();
    if (cache == tmp) nftw(tmp, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    return rc;
}

static void print_rows(const bench_args *a, const bench_result *r)
{
    const char *label = a->label ? a->label : a->file;
    char cached[32], dims[64];
    snprintf(cached, sizeof cached, r->open_cached_ms < 0 ? "-" : "%.0f", r->open_cached_ms);
    snprintf(dims, sizeof dims, "%ux%ux%u", r->info.dims[0], r->info.dims[1], r->info.dims[2]);
    const char *head = "label,dims,budget_mb,streamed,levels,open_first_ms,open_cached_ms,first_frame_ms,first_level,"
                       "refined_ms,refined,refine_frames,f12_ms,f12_load_ms,bytes_read_mb,open_rss_mb,peak_rss_mb\n";
    char row[1024];
    snprintf(row, sizeof row, "%s,%s,%.0f,%u,%u,%.0f,%s,%.0f,%u,%.0f,%u,%u,%.0f,%.0f,%.1f,%.0f,%.0f\n", label, dims,
             a->budget / 1048576.0, r->info.streamed, r->info.level_count, r->open_first_ms, cached, r->first_ms,
             r->first_level, r->refined_ms, r->refined, r->refine_frames, r->f12_ms, r->f12_load_ms,
             r->bytes_read / 1048576.0, r->open_rss_kb / 1024.0, r->peak_rss_kb / 1024.0);
    const char *mhead = "| file | dims | budget | streamed | open (first / cached) ms | first frame ms (level) | "
                        "refined ms (frames) | F12 ms | read MiB | peak RSS MiB |\n"
                        "|---|---|---|---|---|---|---|---|---|---|\n";
    char mrow[1024];
    snprintf(mrow, sizeof mrow,
             "| %s | %s | %.0f MiB | %s | %.0f / %s | %.0f (%u) | %s%.0f (%u) | %.0f | %.1f | %.0f |\n",
             label, dims, a->budget / 1048576.0, r->info.streamed ? "yes" : "no", r->open_first_ms, cached,
             r->first_ms, r->first_level, r->refined ? "" : ">", r->refined_ms, r->refine_frames, r->f12_ms,
             r->bytes_read / 1048576.0, r->peak_rss_kb / 1024.0);
    fputs(head, stdout);
    fputs(row, stdout);
    fputs(mhead, stdout);
    fputs(mrow, stdout);
    const char *paths[2] = {a->out, a->md}, *heads[2] = {head, mhead}, *rows[2] = {row, mrow};
    for (int i = 0; i < 2; i++) {
        if (!paths[i]) continue;
        const int fresh = access(paths[i], F_OK) != 0;
        FILE *f = fopen(paths[i], "a");
        if (!f) {
            fprintf(stderr, "voxlight-streambench: cannot write %s: %s\n", paths[i], strerror(errno));
            continue;
        }
        if (fresh) fputs(heads[i], f);
        fputs(rows[i], f);
        fclose(f);
    }
}

int main(int argc, char **argv)
{
    bench_args a = {.budget = 2ull << 30, .size = 512, .streaming = VXL_STREAMING_AUTO, .max_refine_s = 600};
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        int ok = 1;
        if (o[0] != '-' && !a.file) {
            a.file = o;
            continue;
        }
        if (!val) ok = 0;
        else if (!strcmp(o, "--memory-budget")) ok = parse_size(val, &a.budget);
        else if (!strcmp(o, "--size")) a.size = (uint32_t)atoi(val), ok = a.size >= 16 && a.size <= 4096;
        else if (!strcmp(o, "--streaming")) ok = !vxl_streaming_from_name(val, &a.streaming);
        else if (!strcmp(o, "--cache-dir")) a.cache_dir = val;
        else if (!strcmp(o, "--label")) a.label = val;
        else if (!strcmp(o, "--max-refine-s")) a.max_refine_s = atof(val), ok = a.max_refine_s > 0;
        else if (!strcmp(o, "--out")) a.out = val;
        else if (!strcmp(o, "--md")) a.md = val;
        else ok = 0;
        if (!ok) a.file = NULL, i = argc;
        i++;
    }
    if (!a.file) {
        fprintf(stderr, "usage: voxlight-streambench FILE [--memory-budget 2G] [--size 16..4096] "
                        "[--streaming auto|on|off] [--cache-dir DIR] [--label NAME] [--max-refine-s S] "
                        "[--out CSV] [--md MD]\n");
        return 2;
    }
    bench_result r;
    memset(&r, 0, sizeof r);
    if (run(&a, &r)) return 1;
    print_rows(&a, &r);
    return 0;
}
