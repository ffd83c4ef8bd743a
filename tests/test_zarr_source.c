/* test_zarr_source.c - the OME-Zarr brick source (csrc/io/zarr_source.c):
 * stores streamed chunk by chunk serve, at every level, exactly what the
 * whole read of that multiscale level gives (csrc/io/zarr_read.c in the
 * helper), for every codec, both Zarr versions, integer and float types,
 * t/c choice, skipped anisotropic levels and floor-sized levels; the index
 * equals the min-max over the level-0 texels with a one-voxel apron;
 * memory stays bounded while every chunk is read, from two threads at
 * once; chunks decompressing to more than their metadata says, a missing
 * codec library and a cancelled index pass are clear errors; AUTO streams
 * only over half the budget. Stores: tests/zarr_source_write.py. */
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "os.h"
#include "loader_test_util.h"
#include "volume.h"
#include "voxlight.h"

static char g_dir[64];

/* Data value of texel i of a buffer in v's texture format. */
static double value_at(const vxl_volume *v, const void *buf, uint64_t i)
{
    double t;
    if (v->texture_bits == 8) t = ((const uint8_t *)buf)[i] / 255.0;
    else if (v->texture_bits == 16) t = ((const uint16_t *)buf)[i] / 65535.0;
    else t = ((const float *)buf)[i];
    return v->tex_lo + t * (v->tex_hi - v->tex_lo);
}

static float index_float(uint32_t bits, const void *buf, uint64_t i)
{
    if (bits == 8) return (float)(((const uint8_t *)buf)[i] / 255.0);
    if (bits == 16) return (float)(((const uint16_t *)buf)[i] / 65535.0);
    return ((const float *)buf)[i];
}

static vxl_volume *load(const char *path, uint32_t streaming, uint32_t frame, uint64_t budget)
{
    vxl_load_options opt = {.struct_size = sizeof opt, .streaming = streaming, .frame = frame,
                            .memory_budget_bytes = budget};
    vxl_volume *v = NULL;
    if (vxl_volume_load(path, &opt, &v)) return NULL;
    return v;
}

/* Level `level` of the source, whole, into a new buffer. */
static void *read_level(vxl_brick_source *s, uint32_t level)
{
    const uint32_t *d = s->level_dims[level], lo[3] = {0, 0, 0};
    void *buf = malloc((size_t)d[0] * d[1] * d[2] * (s->texture_bits / 8));
    vxl_err e = {0};
    if (buf && s->ops->read(s, level, lo, d, buf, &e)) {
        fprintf(stderr, "  read level %u: %s\n", level, e.msg);
        free(buf);
        return NULL;
    }
    return buf;
}

/* The index as the skipping grid computes it: per brick, min and max over
 * the brick plus a one-voxel apron, of the level-0 texels. */
static int index_matches(vxl_test_ctx *T_, const vxl_brick_source *s, const void *texels, const char *name)
{
    const uint32_t B = s->index_brick, *d = s->level_dims[0], *g = s->index_dims;
    uint64_t bad = 0;
    for (uint32_t bz = 0; bz < g[2]; bz++)
        for (uint32_t by = 0; by < g[1]; by++)
            for (uint32_t bx = 0; bx < g[0]; bx++) {
                const uint32_t b[3] = {bx, by, bz};
                uint32_t lo[3], hi[3];
                for (int a = 0; a < 3; a++) {
                    lo[a] = b[a] * B > 0 ? b[a] * B - 1 : 0;
                    hi[a] = b[a] * B + B < d[a] ? b[a] * B + B : d[a] - 1;
                }
                float mn = 1e30f, mx = -1e30f;
                for (uint32_t z = lo[2]; z <= hi[2]; z++)
                    for (uint32_t y = lo[1]; y <= hi[1]; y++)
                        for (uint32_t x = lo[0]; x <= hi[0]; x++) {
                            const float f = index_float(s->texture_bits, texels, ((uint64_t)z * d[1] + y) * d[0] + x);
                            mn = f < mn ? f : mn;
                            mx = f > mx ? f : mx;
                        }
                const float *got = s->minmax + 2 * (bx + (uint64_t)g[0] * (by + (uint64_t)g[1] * bz));
                bad += got[0] != mn || got[1] != mx;
            }
    CHECKF(!bad, "%s: %llu of %u index bricks differ", name, (unsigned long long)bad, g[0] * g[1] * g[2]);
    return !bad;
}

/* Source level k against the whole read of store level L: every voxel (a
 * floor-sized level's missing last plane reads the one before it). */
static int level_matches(vxl_test_ctx *T_, const vxl_volume *v, uint32_t k, const char *store, int L, int c,
                         uint32_t frame, int exact)
{
    char path[512];
    snprintf(path, sizeof path, "%s#level=%d&c=%d", store, L, c);
    vxl_volume *w = load(path, VXL_STREAMING_OFF, frame, 0);
    CHECKF(w != NULL, "%s: %s", path, vxl_last_error());
    if (!w) return 0;
    const vxl_brick_source *s = v->source;
    const uint32_t *d = s->level_dims[k];
    int dims_ok = 1;
    for (int a = 0; a < 3; a++)
        dims_ok &= d[a] == (v->dims[a] + (1u << k) - 1) >> k && (w->dims[a] == d[a] || w->dims[a] + 1 == d[a]);
    CHECKF(dims_ok, "%s: source level %u is %ux%ux%u, the store level %ux%ux%u", path, k, d[0], d[1], d[2],
           w->dims[0], w->dims[1], w->dims[2]);
    void *got = dims_ok ? read_level((vxl_brick_source *)s, k) : NULL;
    CHECKF(!dims_ok || got, "%s: level %u not read", path, k);
    uint64_t bad = 0, first = 0;
    double want_first = 0, got_first = 0;
    const double span = v->tex_hi - v->tex_lo, tol = v->texture_bits == 32 ? 1e-6 * span : 0;
    for (uint32_t z = 0; got && z < d[2]; z++)
        for (uint32_t y = 0; y < d[1]; y++)
            for (uint32_t x = 0; x < d[0]; x++) {
                const uint64_t i = ((uint64_t)z * d[1] + y) * d[0] + x;
                const uint32_t wx = x < w->dims[0] ? x : w->dims[0] - 1, wy = y < w->dims[1] ? y : w->dims[1] - 1,
                               wz = z < w->dims[2] ? z : w->dims[2] - 1;
                double want = voxel(w, ((uint64_t)wz * w->dims[1] + wy) * w->dims[0] + wx);
                if (!exact) want = want < v->tex_lo ? v->tex_lo : want > v->tex_hi ? v->tex_hi : want;
                const double g = value_at(v, got, i);
                if (!(fabs(g - want) <= tol) && !bad++) {
                    first = i;
                    want_first = want;
                    got_first = g;
                }
            }
    CHECKF(!bad, "%s: level %u: %llu values differ, first at %llu: %g, expected %g", path, k,
           (unsigned long long)bad, (unsigned long long)first, got_first, want_first);
    /* a brick of one voxel at the far corner: past a floor-sized level's
     * extent on every axis, it reads the array's last voxel */
    if (got) {
        const uint32_t lo[3] = {d[0] - 1, d[1] - 1, d[2] - 1}, one[3] = {1, 1, 1};
        float corner[1];
        vxl_err e = {0};
        const uint32_t bpv = s->texture_bits / 8;
        const uint64_t last = (uint64_t)d[0] * d[1] * d[2] - 1;
        CHECKF(s->ops->read((vxl_brick_source *)s, k, lo, one, corner, &e) == VXL_OK &&
                   !memcmp(corner, (const uint8_t *)got + last * bpv, bpv),
               "%s: level %u: the corner voxel read alone differs (%s)", path, k, e.msg);
    }
    /* the geometry of a streamed volume is its level 0's */
    if (k == 0) {
        int geo = 1;
        for (int i = 0; i < 16; i++) geo &= fabs(v->affine[i] - w->affine[i]) < 1e-12;
        geo &= v->frame_count == w->frame_count && v->frame == w->frame;
        CHECKF(geo, "%s: affine or frames differ from the whole read", path);
        if (got) index_matches(T_, s, got, path);
    }
    free(got);
    vxl_volume_destroy(w);
    return got && !bad;
}

typedef struct manifest_line {
    char name[128], path[384];
    uint32_t frame;
    int c, levels[8], n_levels, exact;
} manifest_line;

static int read_manifest(manifest_line *m, int max)
{
    char p[128], line[1024];
    snprintf(p, sizeof p, "%s/manifest.tsv", g_dir);
    FILE *f = fopen(p, "r");
    if (!f) return 0;
    int n = 0;
    while (n < max && fgets(line, sizeof line, f)) {
        manifest_line *l = &m[n];
        char levels[64];
        if (sscanf(line, "%127s %383s %u %d %63s %d", l->name, l->path, &l->frame, &l->c, levels, &l->exact) != 6)
            continue;
        l->n_levels = 0;
        for (char *t = strtok(levels, ","); t && l->n_levels < 8; t = strtok(NULL, ","))
            l->levels[l->n_levels++] = atoi(t);
        n++;
    }
    fclose(f);
    return n;
}

static char *store_path(const char *name)
{
    static char p[256]; /* tests run one at a time */
    snprintf(p, sizeof p, "%s/%s.zarr", g_dir, name);
    return p;
}

TEST(every_level_equals_the_whole_read_of_that_level)
{
    manifest_line m[32];
    const int n = read_manifest(m, 32);
    REQUIRE(n >= 11);
    int codecs_seen = 0;
    for (int i = 0; i < n; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s#c=%d", m[i].path, m[i].c);
        vxl_volume *v = load(path, VXL_STREAMING_ON, m[i].frame, 0);
        CHECKF(v && v->source && !v->texels, "%s: not streamed: %s", path, vxl_last_error());
        if (!v || !v->source) {
            vxl_volume_destroy(v);
            continue;
        }
        CHECKF(v->source->n_levels == (uint32_t)m[i].n_levels, "%s: %u levels, expected %d", path,
               v->source->n_levels, m[i].n_levels);
        int ok = 1;
        for (int k = 0; k < m[i].n_levels && k < (int)v->source->n_levels; k++)
            ok &= level_matches(T_, v, (uint32_t)k, m[i].path, m[i].levels[k], m[i].c, m[i].frame, m[i].exact);
        codecs_seen += ok;
        vxl_volume_destroy(v);
    }
    CHECK(codecs_seen == n);
}

TEST(geometry_is_in_mm_and_info_reports_the_stream)
{
    vxl_volume *v = load(store_path("v2_gzip_u16"), VXL_STREAMING_ON, 0, 0);
    REQUIRE(v);
    vxl_volume_info info = {.struct_size = sizeof info};
    CHECK(vxl_volume_get_info(v, &info) == VXL_OK);
    /* scale 1 micrometer on every axis = 0.001 mm */
    CHECKF(fabs(info.spacing[0] - 0.001) < 1e-15 && fabs(info.affine[5] - 0.001) < 1e-15, "spacing %g",
           info.spacing[0]);
    CHECK(info.dims[0] == 37 && info.dims[1] == 29 && info.dims[2] == 21);
    CHECK(info.dtype == VXL_DTYPE_U16 && info.texture_bits == 16);
    CHECK(info.value_min >= 0 && info.value_max <= 65535 && info.value_min < info.value_max);
    vxl_volume_destroy(v);
}

/* Reads level 0 in boxes of 24^3 (crossing chunks), as the loader thread. */
typedef struct reader_job {
    vxl_brick_source *s;
    const uint8_t *expect; /* level 0, whole */
    int phase, ok;
    uint64_t peak;
} reader_job;

static void *read_boxes(void *arg)
{
    reader_job *j = arg;
    vxl_brick_source *s = j->s;
    const uint32_t *d = s->level_dims[0], B = 24, bpv = s->texture_bits / 8;
    uint8_t *buf = malloc((size_t)B * B * B * bpv);
    j->ok = buf != NULL;
    for (uint32_t bz = 0; buf && bz < d[2]; bz += B)
        for (uint32_t by = 0; by < d[1]; by += B)
            for (uint32_t bx = 0; bx < d[0]; bx += B) {
                if ((bx / B + by / B + bz / B) % 2 != (uint32_t)j->phase) continue;
                const uint32_t lo[3] = {bx, by, bz};
                const uint32_t size[3] = {d[0] - bx < B ? d[0] - bx : B, d[1] - by < B ? d[1] - by : B,
                                          d[2] - bz < B ? d[2] - bz : B};
                vxl_err e = {0};
                if (s->ops->read(s, 0, lo, size, buf, &e)) {
                    j->ok = 0;
                    continue;
                }
                for (uint32_t z = 0; z < size[2]; z++)
                    for (uint32_t y = 0; y < size[1]; y++)
                        j->ok &= !memcmp(buf + ((size_t)z * size[1] + y) * size[0] * bpv,
                                         j->expect + (((size_t)(bz + z) * d[1] + by + y) * d[0] + bx) * bpv,
                                         (size_t)size[0] * bpv);
                const uint64_t r = __atomic_load_n(&s->resident_bytes, __ATOMIC_RELAXED);
                j->peak = r > j->peak ? r : j->peak;
            }
    free(buf);
    return NULL;
}

TEST(memory_stays_bounded_reading_every_chunk_from_two_threads)
{
    /* 96^3 uint16 in 216 chunks of 8 KiB: 1.7 MiB of voxels; a 1 MiB budget
     * gives a 64 KiB chunk cache */
    const char *path = store_path("v2_zstd_u16_many_chunks");
    vxl_volume *whole = load(path, VXL_STREAMING_OFF, 0, 0);
    vxl_volume *v = load(path, VXL_STREAMING_ON, 0, 1u << 20);
    CHECKF(whole && v && v->source, "%s", vxl_last_error());
    if (!whole || !v || !v->source) {
        vxl_volume_destroy(whole);
        vxl_volume_destroy(v);
        return;
    }
    vxl_brick_source *s = v->source;
    const uint64_t index = (uint64_t)s->index_dims[0] * s->index_dims[1] * s->index_dims[2] * 2 * sizeof(float);
    const uint64_t level0 = (uint64_t)96 * 96 * 96 * 2, read_at_open = s->bytes_read;
    CHECK(read_at_open > 0);
    reader_job jobs[2] = {{s, whole->texels, 0, 0, 0}, {s, whole->texels, 1, 0, 0}};
    pthread_t th;
    REQUIRE(pthread_create(&th, NULL, read_boxes, &jobs[0]) == 0);
    read_boxes(&jobs[1]);
    pthread_join(th, NULL);
    CHECK(jobs[0].ok && jobs[1].ok);
    const uint64_t peak = jobs[0].peak > jobs[1].peak ? jobs[0].peak : jobs[1].peak;
    /* the cache (64 KiB), the index and the metadata (the store struct,
     * about 150 KiB), never the level */
    CHECKF(peak <= (64u << 10) + index + (256u << 10) && peak < level0, "resident %llu bytes (index %llu)",
           (unsigned long long)peak, (unsigned long long)index);
    CHECK(s->bytes_read > read_at_open);
    vxl_volume_destroy(whole);
    vxl_volume_destroy(v);
}

TEST(chunks_decompressing_past_their_size_are_errors_naming_the_file)
{
    /* level 0: met by the index pass at open */
    vxl_volume *v = load(store_path("bad_gzip_level0"), VXL_STREAMING_ON, 0, 0);
    CHECK(v == NULL);
    CHECKF(strstr(vxl_last_error(), "bad_gzip_level0.zarr/0/1/1/1") && strstr(vxl_last_error(), "more than"), "%s",
           vxl_last_error());
    vxl_volume_destroy(v);
    /* level 2: met when that level is read */
    v = load(store_path("bad_zstd_level2"), VXL_STREAMING_ON, 0, 0);
    CHECKF(v && v->source, "%s", vxl_last_error());
    if (v && v->source) {
        const uint32_t lo[3] = {0, 0, 0}, size[3] = {4, 4, 4};
        uint16_t buf[64];
        vxl_err e = {0};
        CHECK(v->source->ops->read(v->source, 2, lo, size, buf, &e) == VXL_ERR_FORMAT);
        CHECKF(strstr(e.msg, "bad_zstd_level2.zarr/2/0/0/0") && strstr(e.msg, "more than"), "%s", e.msg);
        /* the source stays usable */
        CHECK(v->source->ops->read(v->source, 0, lo, size, buf, &e) == VXL_OK);
    }
    vxl_volume_destroy(v);
}

TEST(a_missing_codec_library_is_named_only_when_its_chunks_are_met)
{
    vxl_os_set_env("VOXLIGHT_ZARR_LIBZSTD", "/nonexistent/libzstd-missing.so.1");
    vxl_volume *v = load(store_path("v2_zstd_u16"), VXL_STREAMING_ON, 0, 0);
    CHECK(v == NULL);
    const char *msg = vxl_last_error();
    CHECKF(strstr(msg, "libzstd-missing.so.1") && strstr(msg, "zstd-compressed") &&
           strstr(msg, "apt-get install libzstd1") && strstr(msg, "v2_zstd_u16.zarr/0/"), "%s", msg);
    vxl_volume_destroy(v);
    v = load(store_path("v2_gzip_u16"), VXL_STREAMING_ON, 0, 0); /* gzip needs no library */
    CHECKF(v && v->source, "%s", vxl_last_error());
    vxl_volume_destroy(v);
    vxl_os_set_env("VOXLIGHT_ZARR_LIBZSTD", NULL);
    vxl_os_set_env("VOXLIGHT_ZARR_LIBBLOSC", "/nonexistent/libblosc-missing.so.1");
    v = load(store_path("v2_blosc_i8"), VXL_STREAMING_ON, 0, 0);
    CHECKF(!v && strstr(vxl_last_error(), "libblosc-missing.so.1") && strstr(vxl_last_error(), "blosc-compressed"),
           "%s", vxl_last_error());
    vxl_volume_destroy(v);
    vxl_os_set_env("VOXLIGHT_ZARR_LIBBLOSC", NULL);
}

static int g_calls;
static double g_last;
static int progress(void *user, double fraction, const char *stage)
{
    (void)stage;
    g_calls++;
    g_last = fraction;
    return user != NULL; /* non-NULL user: cancel */
}

TEST(the_index_pass_reports_progress_and_can_be_cancelled)
{
    int cancel = 1;
    vxl_load_options opt = {.struct_size = sizeof opt, .streaming = VXL_STREAMING_ON, .progress = progress};
    vxl_volume *v = NULL;
    g_calls = 0;
    CHECK(vxl_volume_load(store_path("v2_zstd_u16_many_chunks"), &opt, &v) == VXL_OK && v);
    CHECK(g_calls >= 2 && g_last == 1.0);
    vxl_volume_destroy(v);
    v = NULL;
    opt.progress_user = &cancel;
    g_calls = 0;
    CHECK(vxl_volume_load(store_path("v2_zstd_u16_many_chunks"), &opt, &v) == VXL_ERR_CANCELLED && !v);
    CHECK(g_calls == 1);
}

TEST(auto_streams_only_past_half_the_budget)
{
    const char *path = store_path("v2_zstd_u16_many_chunks"); /* 1.69 MiB of texels */
    vxl_volume *v = load(path, VXL_STREAMING_AUTO, 0, 4u << 20);
    CHECKF(v && v->texels && !v->source, "%s", vxl_last_error());
    vxl_volume_destroy(v);
    v = load(path, VXL_STREAMING_AUTO, 0, 3u << 20);
    CHECKF(v && v->source && !v->texels && v->dims[0] == 96, "%s", vxl_last_error());
    vxl_volume_destroy(v);
    /* the chosen channel and time must exist, as for a whole read */
    char p[512];
    snprintf(p, sizeof p, "%s#c=2", store_path("v3_zstd_u8_tczyx"));
    v = load(p, VXL_STREAMING_ON, 0, 0);
    CHECKF(!v && strstr(vxl_last_error(), "2 channels"), "%s", vxl_last_error());
    vxl_volume_destroy(v);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_zsrc_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    char cmd[256];
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/zarr_source_write.py %s", g_dir);
    if (system(cmd) != 0) {
        fprintf(stderr, "tests/zarr_source_write.py failed\n");
        remove_tree(g_dir);
        return 1;
    }
    RUN(every_level_equals_the_whole_read_of_that_level);
    RUN(geometry_is_in_mm_and_info_reports_the_stream);
    RUN(memory_stays_bounded_reading_every_chunk_from_two_threads);
    RUN(chunks_decompressing_past_their_size_are_errors_naming_the_file);
    RUN(a_missing_codec_library_is_named_only_when_its_chunks_are_met);
    RUN(the_index_pass_reports_progress_and_can_be_cancelled);
    RUN(auto_streams_only_past_half_the_budget);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
