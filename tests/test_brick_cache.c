/* test_brick_cache.c - the bricked cache of gzip-compressed volumes (issue
 * 21, csrc/io/brick_cache.h): generated .nii.gz files of several types
 * (float with NaN/Inf, i16 with slope and intercept, byte-swapped u16, ...)
 * streamed into a cache of small bricks; every level read back equals the
 * whole-volume load and its vxl_volume_downsample2 chain texel for texel,
 * the index equals vxl_bricks_minmax_cpu (at the index brick every source uses); a second open reads the cache, a
 * touched or changed source rebuilds it, damage anywhere is detected and
 * never trusted, a cancel leaves no file, cache_dir is honoured; page bricks
 * with their ghost read as one stored brick, the renderer's loader with
 * 1 and 4 threads brings every brick whole, an old format is rebuilt. Calls the
 * cache's internals, so the Makefile links their objects into this test. */
#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "brick_cache.h"
#include "brick_cache_format.h"
#include "brick_loader.h"
#include "bricks.h"
#include "harness.h"
#include "loader_test_util.h"
#include "lod.h"
#include "nifti_writer.h"
#include "paging.h"

static char tmp_root[64];

static const char *tmp_path(const char *name)
{
    static char p[8][256];
    static int k;
    k = (k + 1) % 8;
    snprintf(p[k], sizeof p[k], "%s/%s", tmp_root, name);
    return p[k];
}

/* NIfTI datatype code of a VXL_DTYPE_. */
static int nifti_code(uint32_t dtype)
{
    static const int codes[] = {0, 2, 256, 512, 4, 768, 8, 16, 64};
    return codes[dtype];
}

/* A volume with constant slabs (constant bricks), a ramp (bricks zlib
 * shrinks) and noise (bricks stored raw), in dtype; floats get NaN and Inf. */
static void *make_data(uint32_t dtype, const uint32_t d[3], uint32_t seed)
{
    const size_t n = (size_t)d[0] * d[1] * d[2], es = vxl_dtype_size(dtype);
    uint8_t *p = malloc(n * es);
    uint32_t rng = seed * 2654435761u + 1;
    for (size_t i = 0; i < n; i++) {
        const uint32_t x = (uint32_t)(i % d[0]), y = (uint32_t)(i / d[0] % d[1]), z = (uint32_t)(i / d[0] / d[1]);
        rng = rng * 1664525u + 1013904223u;
        double v = z < 9 ? 7 : x > 20 ? (double)(rng >> 24) : (double)((x + 2 * y + 3 * z + seed) % 200);
        if (dtype == VXL_DTYPE_I8 || dtype == VXL_DTYPE_I16 || dtype == VXL_DTYPE_I32) v -= 100;
        if (dtype == VXL_DTYPE_U16 || dtype == VXL_DTYPE_I16) v *= 150;
        switch (dtype) {
        case VXL_DTYPE_U8: p[i] = (uint8_t)v; break;
        case VXL_DTYPE_I8: ((int8_t *)p)[i] = (int8_t)v; break;
        case VXL_DTYPE_U16: ((uint16_t *)p)[i] = (uint16_t)v; break;
        case VXL_DTYPE_I16: ((int16_t *)p)[i] = (int16_t)v; break;
        case VXL_DTYPE_U32: ((uint32_t *)p)[i] = (uint32_t)v * 1000u; break;
        case VXL_DTYPE_I32: ((int32_t *)p)[i] = (int32_t)v * 1000; break;
        case VXL_DTYPE_F32: ((float *)p)[i] = (float)(v * 0.37 - 3); break;
        default: ((double *)p)[i] = v * 1e-3 + 1e5; break;
        }
    }
    if (dtype == VXL_DTYPE_F32) {
        float *f = (float *)p;
        f[n / 2] = NAN;
        f[n / 3] = INFINITY;
        f[n - 1] = -INFINITY;
    }
    return p;
}

typedef struct source_file {
    char path[256];
    uint32_t dtype, dims[3];
    double slope, inter;
    int swap;
} source_file;

static int write_source(source_file *s, uint32_t seed)
{
    tnw_header h;
    tnw_init(&h, 1, nifti_code(s->dtype), s->dims[0], s->dims[1], s->dims[2]);
    h.scl_slope = s->slope;
    h.scl_inter = s->inter;
    h.swap = s->swap;
    void *data = make_data(s->dtype, s->dims, seed);
    int rc = tnw_write(s->path, &h, data,
                       (size_t)s->dims[0] * s->dims[1] * s->dims[2] * vxl_dtype_size(s->dtype));
    free(data);
    return rc;
}

/* What the NIfTI loader would hand the cache: the voxels at 352 in the stream. */
static void layout_of(const source_file *s, vxl_raw_layout *l)
{
    memset(l, 0, sizeof *l);
    snprintf(l->path, sizeof l->path, "%s", s->path);
    l->offset = 352;
    l->compressed = 1;
    memcpy(l->dims, s->dims, sizeof l->dims);
    l->dtype = s->dtype;
    l->swap = s->swap;
    l->slope = s->slope;
    l->inter = s->inter;
    l->frame_count = 1;
    struct stat st;
    if (stat(s->path, &st) == 0) {
        l->file_size = (uint64_t)st.st_size;
        l->mtime_ns = (int64_t)st.st_mtim.tv_sec * 1000000000 + st.st_mtim.tv_nsec;
    }
    l->header_hash = 0x5eed;
}

/* 1 when got (a box lo, sz read from a source) equals that box of ref's texels. */
static int box_equals(const uint8_t *got, const vxl_volume *ref, const uint32_t lo[3], const uint32_t sz[3])
{
    const uint32_t *d = ref->dims, tb = ref->texture_bits / 8;
    for (uint32_t z = 0; z < sz[2]; z++)
        for (uint32_t y = 0; y < sz[1]; y++)
            if (memcmp(got + ((size_t)z * sz[1] + y) * sz[0] * tb,
                       (const uint8_t *)ref->texels + (((size_t)(lo[2] + z) * d[1] + lo[1] + y) * d[0] + lo[0]) * tb,
                       (size_t)sz[0] * tb) != 0)
                return 0;
    return 1;
}

typedef struct progress_log {
    int calls;
    double last, cancel_at; /* cancel_at > 1: never */
} progress_log;

static int on_progress(void *user, double f, const char *stage)
{
    progress_log *p = user;
    p->calls++;
    p->last = f;
    return stage && stage[0] && f >= p->cancel_at;
}

static vxl_load_options options(progress_log *log, const char *cache_dir)
{
    vxl_load_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.streaming = VXL_STREAMING_OFF;
    o.cache_dir = cache_dir;
    o.progress = log ? on_progress : NULL;
    o.progress_user = log;
    return o;
}

/* Writes s as `name` in the temp folder (voxels from seed) and loads it whole; NULL on failure. */
static vxl_volume *written_and_loaded(source_file *s, const char *name, uint32_t seed)
{
    snprintf(s->path, sizeof s->path, "%s", tmp_path(name));
    vxl_load_options o = options(NULL, NULL);
    vxl_volume *whole = NULL;
    if (write_source(s, seed) != 0 || vxl_volume_load(s->path, &o, &whole) != VXL_OK) return NULL;
    return whole;
}

static const vxl_brick_cache_tuning small = {.brick = 8, .coarsest_bytes = 64};

static int open_cache(const source_file *s, const vxl_load_options *o, vxl_brick_source **src, vxl_err *e)
{
    vxl_raw_layout l;
    layout_of(s, &l);
    return vxl_brick_cache_open_tuned(&l, o, &small, src, e);
}

static int info_of(const vxl_brick_source *s, vxl_brick_cache_info *info)
{
    vxl_err e = {0};
    return vxl_brick_cache_get_info(s, info, &e);
}

/* A source written, loaded whole and opened through a fresh cache (the
 * caller sets f->s's type and dims first). */
typedef struct fixture {
    source_file s;
    vxl_volume *whole;
    vxl_brick_source *src;
    char cache[4096];
} fixture;

static int fixture_open(fixture *f, const char *name, uint32_t seed)
{
    vxl_load_options o = options(NULL, NULL);
    vxl_err e = {0};
    vxl_brick_cache_info info;
    if (!(f->whole = written_and_loaded(&f->s, name, seed)) || open_cache(&f->s, &o, &f->src, &e) != VXL_OK ||
        info_of(f->src, &info) != VXL_OK)
        return -1;
    snprintf(f->cache, sizeof f->cache, "%s", info.path);
    return 0;
}

static void fixture_close(fixture *f)
{
    vxl_brick_source_free(f->src);
    vxl_volume_destroy(f->whole);
    unlink(f->cache);
    unlink(f->s.path);
}

/* Every level of src equals the whole load's downsample chain, read whole
 * and in odd boxes that straddle bricks; the index equals the CPU grid. */
static void check_levels(vxl_test_ctx *T_, vxl_brick_source *src, const vxl_volume *whole)
{
    vxl_bricks b;
    memset(&b, 0, sizeof b);
    vxl_err e = {0};
    REQUIRE(vxl_bricks_minmax_cpu(&b, whole, vxl_source_index_brick(whole->dims), &e) == VXL_OK);
    CHECK(src->index_brick == b.size);
    CHECK(memcmp(src->index_dims, b.dims, sizeof b.dims) == 0);
    const size_t nix = (size_t)b.dims[0] * b.dims[1] * b.dims[2] * 2;
    CHECKF(memcmp(src->minmax, b.minmax, nix * sizeof(float)) == 0, "the index differs from vxl_bricks_minmax_cpu");
    vxl_bricks_free(&b);

    CHECK(src->n_levels >= 3);
    CHECK(src->texture_bits == whole->texture_bits);
    const vxl_volume *ref = whole;
    vxl_volume *owned = NULL;
    for (uint32_t L = 0; L < src->n_levels; L++) {
        if (L) {
            vxl_volume *next = NULL;
            REQUIRE(vxl_volume_downsample2(ref, &next, &e) == VXL_OK);
            if (owned) vxl_volume_destroy(owned);
            owned = next;
            ref = next;
        }
        CHECK(memcmp(src->level_dims[L], ref->dims, sizeof ref->dims) == 0);
        const uint32_t lo0[3] = {0, 0, 0};
        uint8_t *got = malloc((size_t)ref->storage_bytes);
        int rc = src->ops->read(src, L, lo0, ref->dims, got, &e);
        CHECKF(rc == VXL_OK, "level %u: %s", L, e.msg);
        CHECKF(rc || memcmp(got, ref->texels, (size_t)ref->storage_bytes) == 0, "level %u differs from the whole load",
               L);
        /* a box from the middle to the far corner */
        uint32_t lo[3], sz[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = ref->dims[a] / 3;
            sz[a] = ref->dims[a] - lo[a];
        }
        rc = src->ops->read(src, L, lo, sz, got, &e);
        CHECKF(rc == VXL_OK && box_equals(got, ref, lo, sz), "a box of level %u differs", L);
        free(got);
    }
    if (owned) vxl_volume_destroy(owned);
    /* outside the level is refused */
    const uint32_t lo[3] = {0, 0, 0}, big[3] = {src->level_dims[0][0] + 1, 1, 1};
    uint8_t one[64];
    CHECK(src->ops->read(src, 0, lo, big, one, &e) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(src->ops->read(src, src->n_levels, lo, (const uint32_t[3]){1, 1, 1}, one, &e) == VXL_ERR_INVALID_ARGUMENT);
}

static void check_type(vxl_test_ctx *T_, uint32_t dtype, double slope, double inter, int swap)
{
    source_file s = {.dtype = dtype, .dims = {37, 29, 23}, .slope = slope, .inter = inter, .swap = swap};
    vxl_volume *whole = written_and_loaded(&s, "typed.nii.gz", dtype);
    REQUIRE(whole);
    vxl_load_options o = options(NULL, NULL);
    vxl_brick_source *src = NULL;
    vxl_err e = {0};
    int rc = open_cache(&s, &o, &src, &e);
    CHECKF(rc == VXL_OK, "dtype %u: %s", dtype, e.msg);
    if (!rc) {
        check_levels(T_, src, whole);
        vxl_volume v;
        memset(&v, 0, sizeof v);
        CHECK(vxl_brick_cache_describe(src, &v, &e) == VXL_OK);
        CHECKF(v.tex_lo == whole->tex_lo && v.tex_hi == whole->tex_hi, "dtype %u: tex range %g..%g, not %g..%g", dtype,
               v.tex_lo, v.tex_hi, whole->tex_lo, whole->tex_hi);
        CHECK(v.value_min == whole->value_min && v.value_max == whole->value_max);
        CHECK(v.nan_count == whole->nan_count && v.inf_count == whole->inf_count);
        /* the data values a streamed volume reconstructs are the whole load's */
        v.texture_bits = src->texture_bits;
        v.texels = malloc((size_t)whole->storage_bytes);
        const uint32_t lo[3] = {0, 0, 0};
        if (src->ops->read(src, 0, lo, whole->dims, v.texels, &e) == VXL_OK) {
            uint64_t differ = 0;
            for (uint64_t i = 0; i < (uint64_t)whole->dims[0] * whole->dims[1] * whole->dims[2]; i++)
                differ += voxel(&v, i) != voxel(whole, i);
            CHECKF(differ == 0, "dtype %u: %llu data values differ", dtype, (unsigned long long)differ);
        }
        free(v.texels);
        CHECK(src->bytes_read > 0);
        vxl_brick_cache_info info;
        CHECK(info_of(src, &info) == VXL_OK && info.built == 1 && strstr(info.path, "typed.nii.gz.vxlcache"));
        unlink(info.path);
    }
    vxl_brick_source_free(src);
    vxl_volume_destroy(whole);
    unlink(s.path);
}

TEST(every_level_equals_the_whole_load)
{
    check_type(T_, VXL_DTYPE_U8, 1, 0, 0);
    check_type(T_, VXL_DTYPE_I8, 1, 0, 1);
    check_type(T_, VXL_DTYPE_I16, 2.5, -100, 0);
    check_type(T_, VXL_DTYPE_U16, 1, 0, 1);
    check_type(T_, VXL_DTYPE_I32, 0.5, 3, 0);
    check_type(T_, VXL_DTYPE_F32, 1, 0, 1);
    check_type(T_, VXL_DTYPE_F64, 1, 0, 0);
}

static void cache_identity(const char *path, struct stat *st)
{
    memset(st, 0, sizeof *st);
    if (stat(path, st) != 0) st->st_ino = 0;
}

TEST(second_open_reads_the_cache_and_changes_rebuild)
{
    source_file s = {.dtype = VXL_DTYPE_I16, .dims = {33, 20, 18}, .slope = 1, .inter = 0};
    snprintf(s.path, sizeof s.path, "%s", tmp_path("reuse.nii.gz"));
    REQUIRE(write_source(&s, 1) == 0);
    progress_log log = {.cancel_at = 2};
    vxl_load_options o = options(&log, NULL);
    vxl_brick_source *a = NULL, *b = NULL;
    vxl_err e = {0};
    REQUIRE(open_cache(&s, &o, &a, &e) == VXL_OK);
    vxl_brick_cache_info info;
    REQUIRE(info_of(a, &info) == VXL_OK);
    char cpath[4096];
    snprintf(cpath, sizeof cpath, "%s", info.path);
    CHECK(info.built == 1 && log.calls > 1 && log.last == 1.0);
    struct stat st0, st1;
    cache_identity(cpath, &st0);

    /* again: read, not rebuilt (no progress, the same file untouched) */
    log.calls = 0;
    REQUIRE(open_cache(&s, &o, &b, &e) == VXL_OK);
    CHECK(info_of(b, &info) == VXL_OK && info.built == 0);
    CHECK(log.calls == 0);
    cache_identity(cpath, &st1);
    CHECK(st1.st_ino == st0.st_ino && st1.st_mtim.tv_nsec == st0.st_mtim.tv_nsec && st1.st_mtim.tv_sec == st0.st_mtim.tv_sec);
    vxl_brick_source_free(b);
    b = NULL;

    /* the source touched (new mtime): rebuilt */
    struct timespec t[2] = {{.tv_sec = 1000000, .tv_nsec = 0}, {.tv_sec = 1000000, .tv_nsec = 0}};
    REQUIRE(utimensat(AT_FDCWD, s.path, t, 0) == 0);
    REQUIRE(open_cache(&s, &o, &b, &e) == VXL_OK);
    CHECK(info_of(b, &info) == VXL_OK && info.built == 1);
    vxl_brick_source_free(b);
    b = NULL;

    /* the source rewritten with other voxels: rebuilt, and they are what is read */
    REQUIRE(write_source(&s, 2) == 0);
    REQUIRE(open_cache(&s, &o, &b, &e) == VXL_OK);
    CHECK(info_of(b, &info) == VXL_OK && info.built == 1);
    vxl_volume *whole = NULL;
    vxl_load_options plain = options(NULL, NULL);
    REQUIRE(vxl_volume_load(s.path, &plain, &whole) == VXL_OK);
    check_levels(T_, b, whole);
    vxl_volume_destroy(whole);

    /* the first source still reads its own (unlinked by the rename) file */
    uint8_t one[2];
    CHECK(a->ops->read(a, 0, (const uint32_t[3]){0, 0, 0}, (const uint32_t[3]){1, 1, 1}, one, &e) == VXL_OK);
    vxl_brick_source_free(a);
    vxl_brick_source_free(b);
    unlink(cpath);
    unlink(s.path);
}

/* Flips one byte of the file at off. */
static void flip(const char *path, uint64_t off)
{
    int fd = open(path, O_RDWR);
    uint8_t c = 0;
    if (fd < 0) return;
    if (pread(fd, &c, 1, (off_t)off) == 1) {
        c ^= 0x5a;
        if (pwrite(fd, &c, 1, (off_t)off) != 1) c = 0;
    }
    close(fd);
}

/* The table entry of the cache's first non-constant brick. */
static int first_stored_brick(const char *path, vxl_cache_entry *out)
{
    int fd = open(path, O_RDONLY);
    uint8_t head[VXL_CACHE_HEADER_BYTES];
    vxl_cache_header h;
    vxl_err e = {0};
    int found = 0;
    if (fd >= 0 && pread(fd, head, sizeof head, 0) == (ssize_t)sizeof head &&
        vxl_cache_header_decode(head, &h, path, &e) == VXL_OK)
        for (uint64_t i = 0; i < h.brick_count && !found; i++) {
            uint8_t en[VXL_CACHE_ENTRY_BYTES];
            if (pread(fd, en, sizeof en, (off_t)(h.table_offset + i * sizeof en)) != (ssize_t)sizeof en) break;
            vxl_cache_entry_decode(en, out);
            found = out->kind != VXL_CACHE_CONSTANT && i < h.brick_count / 2;
        }
    if (fd >= 0) close(fd);
    return found;
}

TEST(damage_is_detected_never_trusted)
{
    fixture f = {.s = {.dtype = VXL_DTYPE_F32, .dims = {30, 26, 21}, .slope = 1, .inter = 0}};
    REQUIRE(fixture_open(&f, "damage.nii.gz", 3) == 0);
    const source_file s = f.s;
    const vxl_volume *whole = f.whole;
    const char *cpath = f.cache;
    vxl_load_options o = options(NULL, NULL);
    vxl_brick_source *src = NULL;
    vxl_err e = {0};
    vxl_brick_cache_info info;
    struct stat st;
    REQUIRE(stat(cpath, &st) == 0);
    vxl_cache_header h;
    {
        uint8_t head[VXL_CACHE_HEADER_BYTES];
        int fd = open(cpath, O_RDONLY);
        REQUIRE(fd >= 0 && pread(fd, head, sizeof head, 0) == (ssize_t)sizeof head);
        close(fd);
        REQUIRE(vxl_cache_header_decode(head, &h, cpath, &e) == VXL_OK);
    }
    /* header, index, table, truncation: each rebuilt at open, and what is then read is right */
    const uint64_t at[4] = {40, h.index_offset + 5, h.table_offset + 30, 0};
    for (int k = 0; k < 4; k++) {
        if (k < 3) flip(cpath, at[k]);
        else REQUIRE(truncate(cpath, st.st_size - 100) == 0);
        REQUIRE(open_cache(&s, &o, &src, &e) == VXL_OK);
        CHECKF(info_of(src, &info) == VXL_OK && info.built == 1, "damage %d was not rebuilt", k);
        check_levels(T_, src, whole);
        vxl_brick_source_free(src);
        src = NULL;
    }

    /* a brick's bytes: the open cannot see it (it reads no brick), the read
     * does: an error naming the cache, which is removed, then rebuilt */
    vxl_cache_entry en;
    REQUIRE(first_stored_brick(cpath, &en));
    flip(cpath, en.offset + en.size / 2);
    REQUIRE(open_cache(&s, &o, &src, &e) == VXL_OK);
    CHECK(info_of(src, &info) == VXL_OK && info.built == 0);
    const uint32_t lo[3] = {0, 0, 0};
    float *all = malloc((size_t)whole->storage_bytes);
    int rc = src->ops->read(src, 0, lo, whole->dims, all, &e);
    CHECKF(rc == VXL_ERR_FORMAT && strstr(e.msg, cpath) && strstr(e.msg, "checksum"), "rc %d: %s", rc, e.msg);
    CHECK(access(cpath, F_OK) != 0);
    vxl_brick_source_free(src);
    src = NULL;
    REQUIRE(open_cache(&s, &o, &src, &e) == VXL_OK);
    CHECK(info_of(src, &info) == VXL_OK && info.built == 1);
    CHECK(src->ops->read(src, 0, lo, whole->dims, all, &e) == VXL_OK &&
          memcmp(all, whole->texels, (size_t)whole->storage_bytes) == 0);
    free(all);
    vxl_brick_source_free(src);
    fixture_close(&f);
}

/* Regular files in dir (names into `names`, up to n). */
static int files_in(const char *dir, char names[][256], int n)
{
    DIR *d = opendir(dir);
    int k = 0;
    struct dirent *ent;
    while (d && (ent = readdir(d)) != NULL)
        if (ent->d_name[0] != '.') {
            if (k < n) snprintf(names[k], 256, "%s", ent->d_name);
            k++;
        }
    if (d) closedir(d);
    return k;
}

TEST(cancel_leaves_no_file_and_cache_dir_is_honoured)
{
    const char *src_dir = tmp_path("src"), *cache_dir = tmp_path("caches/deeper");
    mkdir(src_dir, 0755);
    source_file s = {.dtype = VXL_DTYPE_F32, .dims = {24, 22, 40}, .slope = 1, .inter = 0};
    snprintf(s.path, sizeof s.path, "%s/vol.nii.gz", src_dir);
    REQUIRE(write_source(&s, 4) == 0);
    char names[8][256];
    for (int where = 0; where < 2; where++) {
        const char *dir = where ? cache_dir : src_dir;
        progress_log log = {.cancel_at = 0.5};
        vxl_load_options o = options(&log, where ? cache_dir : NULL);
        vxl_brick_source *src = NULL;
        vxl_err e = {0};
        int rc = open_cache(&s, &o, &src, &e);
        CHECKF(rc == VXL_ERR_CANCELLED && src == NULL, "rc %d: %s", rc, e.msg);
        CHECK(log.last >= 0.5 && log.last < 0.6);
        CHECKF(files_in(dir, names, 8) == (where ? 0 : 1), "a cancelled build left a file in %s", dir);

        log.cancel_at = 2;
        rc = open_cache(&s, &o, &src, &e);
        CHECKF(rc == VXL_OK, "%s", e.msg);
        vxl_brick_cache_info info;
        CHECK(rc || (info_of(src, &info) == VXL_OK && strncmp(info.path, dir, strlen(dir)) == 0));
        CHECK(files_in(dir, names, 8) == (where ? 1 : 2));
        if (where) {
            CHECK(strncmp(names[0], "vol.nii.gz-", 11) == 0 && strstr(names[0], ".vxlcache"));
            CHECK(files_in(src_dir, names, 8) == 1); /* nothing beside the source */
        }
        if (!rc) unlink(info.path);
        vxl_brick_source_free(src);
    }
    unlink(s.path);
}

TEST(bad_sources_fail_naming_the_file_and_leave_nothing)
{
    const char *dir = tmp_path("bad");
    mkdir(dir, 0755);
    source_file s = {.dtype = VXL_DTYPE_U8, .dims = {20, 20, 20}, .slope = 1, .inter = 0};
    snprintf(s.path, sizeof s.path, "%s/short.nii.gz", dir);
    REQUIRE(write_source(&s, 5) == 0);
    vxl_raw_layout l;
    layout_of(&s, &l);
    l.dims[2] = 21; /* the header claims more than the file holds */
    vxl_load_options o = options(NULL, NULL);
    vxl_brick_source *src = NULL;
    vxl_err e = {0};
    int rc = vxl_brick_cache_open_tuned(&l, &o, &small, &src, &e);
    CHECKF(rc == VXL_ERR_FORMAT && strstr(e.msg, s.path) && src == NULL, "rc %d: %s", rc, e.msg);
    char names[4][256];
    CHECK(files_in(dir, names, 4) == 1);
    /* a missing file */
    snprintf(l.path, sizeof l.path, "%s/missing.nii.gz", dir);
    rc = vxl_brick_cache_open_tuned(&l, &o, &small, &src, &e);
    CHECK(rc == VXL_ERR_IO && strstr(e.msg, "missing.nii.gz"));
    CHECK(files_in(dir, names, 4) == 1);
    unlink(s.path);
}

typedef struct reader_job {
    vxl_brick_source *src;
    const vxl_volume *whole;
    int bad;
} reader_job;

static void *read_boxes(void *arg)
{
    reader_job *j = arg;
    const uint32_t *d = j->whole->dims;
    uint8_t *buf = malloc((size_t)j->whole->storage_bytes);
    uint32_t rng = (uint32_t)(uintptr_t)arg;
    for (int k = 0; k < 200; k++) {
        uint32_t lo[3], sz[3];
        for (int a = 0; a < 3; a++) {
            rng = rng * 1664525u + 1013904223u;
            lo[a] = (rng >> 8) % d[a];
            sz[a] = 1 + (rng >> 20) % (d[a] - lo[a]);
        }
        vxl_err e = {0};
        if (j->src->ops->read(j->src, 0, lo, sz, buf, &e) != VXL_OK || !box_equals(buf, j->whole, lo, sz)) j->bad++;
    }
    free(buf);
    return NULL;
}

TEST(threads_read_at_once)
{
    fixture f = {.s = {.dtype = VXL_DTYPE_U16, .dims = {70, 40, 30}, .slope = 1, .inter = 0}};
    REQUIRE(fixture_open(&f, "threads.nii.gz", 6) == 0);
    reader_job jobs[3];
    pthread_t th[3];
    for (int k = 0; k < 3; k++) {
        jobs[k] = (reader_job){f.src, f.whole, 0};
        pthread_create(&th[k], NULL, read_boxes, &jobs[k]);
    }
    for (int k = 0; k < 3; k++) {
        pthread_join(th[k], NULL);
        CHECK(jobs[k].bad == 0);
    }
    fixture_close(&f);
}


/* Rewrites the cache's first zlib brick of at least 48 stored bytes as a
 * stream that inflates to 4x its brick (a zip bomb), with every checksum
 * fixed up, so only the size check can catch it. 0 on success. */
static int plant_bomb(const char *path)
{
    int fd = open(path, O_RDWR);
    uint8_t head[VXL_CACHE_HEADER_BYTES], en[VXL_CACHE_ENTRY_BYTES];
    vxl_cache_header h;
    vxl_err e = {0};
    int done = -1;
    if (fd < 0 || pread(fd, head, sizeof head, 0) != (ssize_t)sizeof head ||
        vxl_cache_header_decode(head, &h, path, &e) != VXL_OK) {
        if (fd >= 0) close(fd);
        return -1;
    }
    uint8_t *table = malloc((size_t)h.table_bytes);
    if (pread(fd, table, (size_t)h.table_bytes, (off_t)h.table_offset) != (ssize_t)h.table_bytes) h.brick_count = 0;
    for (uint64_t i = 0; i < h.brick_count && done; i++) {
        vxl_cache_entry ce;
        vxl_cache_entry_decode(table + i * VXL_CACHE_ENTRY_BYTES, &ce);
        if (ce.kind != VXL_CACHE_ZLIB || ce.size < 48) continue;
        const uLong big = (uLong)h.brick * h.brick * h.brick * (h.texture_bits / 8) * 4;
        uint8_t *zeros = calloc(1, big), *z = malloc(compressBound(big));
        uLongf zn = compressBound(big);
        if (compress2(z, &zn, zeros, big, 9) == Z_OK && zn <= ce.size &&
            pwrite(fd, z, zn, (off_t)ce.offset) == (ssize_t)zn) {
            ce.size = (uint32_t)zn;
            ce.crc = (uint32_t)crc32(crc32(0L, Z_NULL, 0), z, (uInt)zn);
            vxl_cache_entry_encode(&ce, en);
            memcpy(table + i * VXL_CACHE_ENTRY_BYTES, en, sizeof en);
            h.table_crc = (uint32_t)crc32(crc32(0L, Z_NULL, 0), table, (uInt)h.table_bytes);
            vxl_cache_header_encode(&h, head);
            if (pwrite(fd, table, (size_t)h.table_bytes, (off_t)h.table_offset) == (ssize_t)h.table_bytes &&
                pwrite(fd, head, sizeof head, 0) == (ssize_t)sizeof head)
                done = 0;
        }
        free(zeros);
        free(z);
        if (done) break;
    }
    free(table);
    close(fd);
    return done;
}

TEST(a_brick_inflating_past_its_size_is_an_error)
{
    source_file s = {.dtype = VXL_DTYPE_U16, .dims = {40, 30, 20}, .slope = 1, .inter = 0};
    snprintf(s.path, sizeof s.path, "%s", tmp_path("bomb.nii.gz"));
    REQUIRE(write_source(&s, 7) == 0);
    vxl_load_options o = options(NULL, NULL);
    vxl_brick_source *src = NULL;
    vxl_err e = {0};
    vxl_brick_cache_info info;
    REQUIRE(open_cache(&s, &o, &src, &e) == VXL_OK);
    REQUIRE(info_of(src, &info) == VXL_OK);
    char cpath[4096];
    snprintf(cpath, sizeof cpath, "%s", info.path);
    vxl_brick_source_free(src);
    src = NULL;
    REQUIRE(plant_bomb(cpath) == 0);
    REQUIRE(open_cache(&s, &o, &src, &e) == VXL_OK);
    CHECK(info_of(src, &info) == VXL_OK && info.built == 0); /* every checksum holds */
    uint8_t *all = malloc((size_t)40 * 30 * 20 * 2);
    int rc = src->ops->read(src, 0, (const uint32_t[3]){0, 0, 0}, s.dims, all, &e);
    CHECKF(rc == VXL_ERR_FORMAT && strstr(e.msg, "more than") && strstr(e.msg, cpath), "rc %d: %s", rc, e.msg);
    free(all);
    vxl_brick_source_free(src);
    unlink(cpath);
    unlink(s.path);
}

/* Through the public API: a .nii.gz loaded with streaming ON is a streamed
 * volume over this cache (in cache_dir), and reads what the whole load holds. */
TEST(vxl_volume_load_streams_a_gz_through_the_cache)
{
    const char *dir = tmp_path("api_caches");
    source_file s = {.dtype = VXL_DTYPE_I16, .dims = {45, 38, 35}, .slope = 0.5, .inter = 10};
    vxl_volume *whole = written_and_loaded(&s, "api.nii.gz", 8), *streamed = NULL;
    REQUIRE(whole);
    vxl_load_options o = options(NULL, NULL);
    o.streaming = VXL_STREAMING_ON;
    o.cache_dir = dir;
    int rc = vxl_volume_load(s.path, &o, &streamed);
    CHECKF(rc == VXL_OK, "%s", vxl_last_error());
    if (!rc) {
        vxl_volume_info info = {.struct_size = sizeof info};
        CHECK(vxl_volume_get_info(streamed, &info) == VXL_OK && info.streamed == 1);
        REQUIRE(streamed->source);
        /* (the library's own copy of the cache code made this source: look at the folder) */
        char names[4][256];
        CHECK(files_in(dir, names, 4) == 1 && strstr(names[0], "api.nii.gz-") && strstr(names[0], ".vxlcache"));
        CHECK(streamed->tex_lo == whole->tex_lo && streamed->tex_hi == whole->tex_hi);
        uint8_t *all = malloc((size_t)whole->storage_bytes);
        vxl_err e = {0};
        CHECK(streamed->source->ops->read(streamed->source, 0, (const uint32_t[3]){0, 0, 0}, whole->dims, all, &e) ==
                  VXL_OK &&
              memcmp(all, whole->texels, (size_t)whole->storage_bytes) == 0);
        free(all);
    }
    vxl_volume_destroy(streamed);
    vxl_volume_destroy(whole);
    unlink(s.path);
}

/* The texels of level L of whole (its downsample chain; the caller frees
 * the result when it is not whole). */
static vxl_volume *level_of(const vxl_volume *whole, uint32_t L)
{
    vxl_volume *cur = (vxl_volume *)whole;
    vxl_err e = {0};
    for (uint32_t k = 0; k < L && cur; k++) {
        vxl_volume *next = NULL;
        if (vxl_volume_downsample2(cur, &next, &e) != VXL_OK) next = NULL;
        if (cur != whole) vxl_volume_destroy(cur);
        cur = next;
    }
    return cur;
}

/* The box a renderer's loader asks for page brick c of edge P at level
 * dims: the brick with its one-voxel ghost, cut at the level's edges. */
static void page_box(const uint32_t c[3], uint32_t P, const uint32_t *dims, uint32_t lo[3], uint32_t sz[3])
{
    for (int a = 0; a < 3; a++) {
        const int64_t l = (int64_t)c[a] * P - 1, h = (int64_t)c[a] * P + P;
        lo[a] = l < 0 ? 0 : (uint32_t)l;
        sz[a] = (uint32_t)(h < dims[a] ? h : dims[a] - 1) - lo[a] + 1;
    }
}

/* Version 2 stores each brick with a one-voxel apron: a page brick of the
 * cache's edge is one stored brick (decoded in place), of twice the edge
 * eight; boxes at random exercise the covering bricks' choice and, touching
 * far more bricks than the decoded-brick LRU holds, its eviction. */
TEST(page_bricks_and_random_boxes_equal_the_whole_load)
{
    static const uint32_t types[2] = {VXL_DTYPE_U8, VXL_DTYPE_I16};
    for (int t = 0; t < 2; t++) {
        fixture f = {.s = {.dtype = types[t], .dims = {100, 61, 45}, .slope = 1, .inter = 0}};
        REQUIRE(fixture_open(&f, "boxes.nii.gz", 9 + t) == 0);
        uint8_t *buf = malloc((size_t)f.whole->storage_bytes);
        REQUIRE(buf);
        uint32_t rng = 77u + t;
        for (uint32_t L = 0; L < f.src->n_levels; L++) {
            vxl_volume *ref = level_of(f.whole, L);
            REQUIRE(ref);
            const uint32_t *d = ref->dims;
            int bad = 0, n = 0;
            for (uint32_t P = 4; P <= 16; P *= 2) { /* the cache's brick is 8 */
                const uint32_t g[3] = {(d[0] + P - 1) / P, (d[1] + P - 1) / P, (d[2] + P - 1) / P};
                for (uint32_t cz = 0; cz < g[2]; cz++)
                    for (uint32_t cy = 0; cy < g[1]; cy++)
                        for (uint32_t cx = 0; cx < g[0]; cx++) {
                            uint32_t lo[3], sz[3];
                            page_box((const uint32_t[3]){cx, cy, cz}, P, d, lo, sz);
                            vxl_err e = {0};
                            n++;
                            if (f.src->ops->read(f.src, L, lo, sz, buf, &e) != VXL_OK || !box_equals(buf, ref, lo, sz)) bad++;
                        }
            }
            for (int k = 0; k < 400; k++) {
                uint32_t lo[3], sz[3];
                for (int a = 0; a < 3; a++) {
                    rng = rng * 1664525u + 1013904223u;
                    lo[a] = (rng >> 8) % d[a];
                    sz[a] = 1 + (rng >> 20) % (k % 2 ? d[a] - lo[a] : (d[a] - lo[a] < 12 ? d[a] - lo[a] : 12));
                }
                vxl_err e = {0};
                n++;
                if (f.src->ops->read(f.src, L, lo, sz, buf, &e) != VXL_OK || !box_equals(buf, ref, lo, sz)) bad++;
            }
            CHECKF(bad == 0, "type %u level %u: %d of %d boxes differ", types[t], L, bad, n);
            if (ref != f.whole) vxl_volume_destroy(ref);
        }
        free(buf);
        fixture_close(&f);
    }
}

/* The renderer's loader over a cache, with 1 and 4 threads and page bricks
 * of the cache's edge and twice it: every brick of every level arrives
 * exactly once, also while the wanted list is renewed after every take,
 * and equals the level's voxels with the edge-repeating ghost (what
 * paging.c cuts from a whole volume). */
TEST(loader_threads_give_every_brick_with_its_ghost)
{
    fixture f = {.s = {.dtype = VXL_DTYPE_U16, .dims = {53, 38, 27}, .slope = 1, .inter = 0}};
    REQUIRE(fixture_open(&f, "loader.nii.gz", 4) == 0);
    const uint32_t tb = f.src->texture_bits / 8;
    for (uint32_t threads = 1; threads <= 4; threads += 3)
        for (uint32_t P = 8; P <= 16; P *= 2) {
            const uint32_t E = P + 2;
            /* every brick of every level, coarsest first */
            uint32_t total = 0, first[VXL_SOURCE_MAX_LEVELS + 1];
            for (uint32_t L = 0; L < f.src->n_levels; L++) {
                first[L] = total;
                const uint32_t *d = f.src->level_dims[L];
                total += ((d[0] + P - 1) / P) * ((d[1] + P - 1) / P) * ((d[2] + P - 1) / P);
            }
            first[f.src->n_levels] = total;
            vxl_brick_key *keys = malloc(total * sizeof *keys);
            uint8_t *seen = calloc(total, 1);
            REQUIRE(keys && seen);
            uint32_t n = 0;
            for (uint32_t L = f.src->n_levels; L-- > 0;)
                for (uint32_t i = 0; i < first[L + 1] - first[L]; i++) keys[n++] = (vxl_brick_key){L, i};
            vxl_brick_loader *ld = NULL;
            vxl_err e = {0};
            REQUIRE(vxl_loader_start_threads(&ld, f.src, P, 6, threads, &e) == VXL_OK);
            REQUIRE(vxl_loader_want(ld, keys, n, &e) == VXL_OK);
            vxl_volume *refs[VXL_SOURCE_MAX_LEVELS] = {0};
            for (uint32_t L = 0; L < f.src->n_levels; L++) refs[L] = level_of(f.whole, L);
            uint32_t got = 0, bad = 0, twice = 0;
            vxl_loaded_brick arrived[6];
            while (got < total) {
                const uint32_t k = vxl_loader_take(ld, arrived, 6, 1);
                if (!k) break;
                for (uint32_t j = 0; j < k; j++) {
                    const vxl_brick_key key = arrived[j].key;
                    const vxl_volume *ref = refs[key.level];
                    const uint32_t *d = ref->dims, g0 = (d[0] + P - 1) / P, g1 = (d[1] + P - 1) / P;
                    const uint32_t c[3] = {key.brick % g0, key.brick / g0 % g1, key.brick / (g0 * g1)};
                    twice += seen[first[key.level] + key.brick]++;
                    for (uint32_t z = 0; z < E; z++)
                        for (uint32_t y = 0; y < E; y++)
                            for (uint32_t x = 0; x < E; x++) {
                                const uint32_t v[3] = {x, y, z};
                                uint64_t at = 0;
                                for (int a = 2; a >= 0; a--) {
                                    int64_t q = (int64_t)c[a] * P + v[a] - 1;
                                    q = q < 0 ? 0 : q >= d[a] ? d[a] - 1 : q;
                                    at = at * d[a] + (uint64_t)q;
                                }
                                bad += memcmp(arrived[j].texels + (((size_t)z * E + y) * E + x) * tb,
                                              (const uint8_t *)ref->texels + at * tb, tb) != 0;
                            }
                }
                got += k;
                vxl_loader_recycle(ld, arrived, k);
                /* as the renderer does each frame: ask again for every brick
                 * not yet taken, those being read or waiting in the queue
                 * included; the loader must not read those twice */
                uint32_t m = 0;
                for (uint32_t L = f.src->n_levels; L-- > 0;)
                    for (uint32_t i = 0; i < first[L + 1] - first[L]; i++)
                        if (!seen[first[L] + i]) keys[m++] = (vxl_brick_key){L, i};
                REQUIRE(vxl_loader_want(ld, keys, m, &e) == VXL_OK);
            }
            CHECKF(vxl_loader_error(ld, &e) == VXL_OK, "threads %u: %s", threads, e.msg);
            CHECKF(got == total && twice == 0, "threads %u, brick %u: %u of %u bricks arrived (%u twice)", threads, P,
                   got, total, twice);
            CHECKF(bad == 0, "threads %u, brick %u: %u voxels differ", threads, P, bad);
            vxl_loader_stop(ld);
            for (uint32_t L = 0; L < f.src->n_levels; L++)
                if (refs[L] != f.whole) vxl_volume_destroy(refs[L]);
            free(keys);
            free(seen);
        }
    fixture_close(&f);
}

/* A cache of another format version (version 1 stored bricks without their
 * apron) is never read as this one: the open rebuilds it. */
TEST(an_old_format_version_is_rebuilt)
{
    fixture f = {.s = {.dtype = VXL_DTYPE_U8, .dims = {30, 20, 19}, .slope = 1, .inter = 0}};
    REQUIRE(fixture_open(&f, "old.nii.gz", 3) == 0);
    vxl_brick_source_free(f.src);
    f.src = NULL;
    /* the header as version 1 wrote it: version 1, its checksum fixed up */
    int fd = open(f.cache, O_RDWR);
    uint8_t head[VXL_CACHE_HEADER_BYTES];
    REQUIRE(fd >= 0 && pread(fd, head, sizeof head, 0) == (ssize_t)sizeof head);
    const uint32_t old = 1;
    memcpy(head + 8, &old, 4);
    const uint32_t crc = (uint32_t)crc32(crc32(0L, Z_NULL, 0), head, VXL_CACHE_HEADER_BYTES - 4);
    memcpy(head + VXL_CACHE_HEADER_BYTES - 4, &crc, 4);
    REQUIRE(pwrite(fd, head, sizeof head, 0) == (ssize_t)sizeof head);
    close(fd);
    vxl_cache_header h;
    vxl_err e = {0};
    CHECK(vxl_cache_header_decode(head, &h, f.cache, &e) == VXL_ERR_FORMAT && strstr(e.msg, "version 1"));
    vxl_load_options o = options(NULL, NULL);
    vxl_brick_cache_info info;
    REQUIRE(open_cache(&f.s, &o, &f.src, &e) == VXL_OK && info_of(f.src, &info) == VXL_OK);
    CHECK(info.built == 1);
    fd = open(f.cache, O_RDONLY);
    REQUIRE(fd >= 0 && pread(fd, head, sizeof head, 0) == (ssize_t)sizeof head);
    close(fd);
    CHECK(vxl_cache_header_decode(head, &h, f.cache, &e) == VXL_OK);
    check_levels(T_, f.src, f.whole);
    /* where the compressed stream starts is part of the key */
    vxl_raw_layout l;
    layout_of(&f.s, &l);
    CHECK(vxl_cache_header_matches(&h, &l));
    l.compressed_start = 1;
    CHECK(!vxl_cache_header_matches(&h, &l));
    fixture_close(&f);
}

/* Appends data to f as a gzip (window 31) or zlib (15) stream; 0 on success. */
static int append_deflated(FILE *f, const void *data, size_t n, int window)
{
    z_stream z;
    memset(&z, 0, sizeof z);
    if (deflateInit2(&z, 6, Z_DEFLATED, window, 8, Z_DEFAULT_STRATEGY) != Z_OK) return -1;
    const uLong cap = deflateBound(&z, (uLong)n);
    uint8_t *out = malloc(cap);
    z.next_in = (Bytef *)data;
    z.avail_in = (uInt)n;
    z.next_out = out;
    z.avail_out = (uInt)cap;
    const int ok = out && deflate(&z, Z_FINISH) == Z_STREAM_END &&
                   fwrite(out, 1, cap - z.avail_out, f) == cap - z.avail_out;
    deflateEnd(&z);
    free(out);
    return ok ? 0 : -1;
}

/* Gzip data after a NRRD header (in two concatenated gzip members) and zlib
 * data after a MetaImage header stream through the cache, which inflates
 * from the byte after the header (vxl_raw_layout.compressed_start), and
 * equal the whole read: every level, the index, boxes. */
TEST(attached_nrrd_gzip_and_zlib_metaimage_stream_through_the_cache)
{
    const uint32_t d[3] = {70, 33, 21};
    const size_t n = (size_t)d[0] * d[1] * d[2] * 2;
    uint16_t *data = make_data(VXL_DTYPE_U16, d, 5);
    REQUIRE(data);
    const char *dir = tmp_path("attached_caches");
    static const char *names[2] = {"attached.nrrd", "attached.mha"};
    static const char *heads[2] = {
        "NRRD0004\n# attached gzip\ntype: ushort\ndimension: 3\nsizes: 70 33 21\nencoding: gzip\nendian: little\n\n",
        "ObjectType = Image\nNDims = 3\nCompressedData = True\nDimSize = 70 33 21\nElementType = MET_USHORT\n"
        "BinaryDataByteOrderMSB = False\nElementDataFile = LOCAL\n"};
    for (int k = 0; k < 2; k++) {
        char path[256];
        snprintf(path, sizeof path, "%s", tmp_path(names[k]));
        FILE *f = fopen(path, "wb");
        REQUIRE(f);
        int bad = fputs(heads[k], f) < 0;
        if (k == 0) /* two gzip members, cut inside a row */
            bad |= append_deflated(f, data, 1001, 31) || append_deflated(f, (uint8_t *)data + 1001, n - 1001, 31);
        else
            bad |= append_deflated(f, data, n, 15);
        bad |= fclose(f) != 0;
        REQUIRE(!bad);
        vxl_load_options o = options(NULL, NULL);
        vxl_volume *whole = NULL, *streamed = NULL;
        REQUIRE(vxl_volume_load(path, &o, &whole) == VXL_OK);
        o.streaming = VXL_STREAMING_ON;
        o.cache_dir = dir;
        for (int pass = 0; pass < 2; pass++) { /* the second open reads the cache the first wrote */
            int rc = vxl_volume_load(path, &o, &streamed);
            CHECKF(rc == VXL_OK, "%s: %s", names[k], vxl_last_error());
            if (rc) break;
            vxl_volume_info info = {.struct_size = sizeof info};
            CHECK(vxl_volume_get_info(streamed, &info) == VXL_OK && info.streamed == 1 && streamed->source);
            char files[4][256];
            CHECKF(files_in(dir, files, 4) == 1 + k && (strstr(files[0], names[k]) || strstr(files[1], names[k])),
                   "%s: no cache in %s", names[k], dir);
            CHECK(streamed->tex_lo == whole->tex_lo && streamed->tex_hi == whole->tex_hi);
            check_levels(T_, streamed->source, whole);
            vxl_volume_destroy(streamed);
            streamed = NULL;
        }
        vxl_volume_destroy(whole);
        unlink(path);
    }
    free(data);
}

/* --write-seeds DIR: small valid caches (three types, many levels, every
 * brick kind) for fuzz_brick_cache's seed corpus. */
static int write_seeds(const char *dir)
{
    static const uint32_t types[3] = {VXL_DTYPE_U8, VXL_DTYPE_I16, VXL_DTYPE_F32};
    static const vxl_brick_cache_tuning tiny = {.brick = 4, .coarsest_bytes = 16};
    for (int k = 0; k < 3; k++) {
        source_file s = {.dtype = types[k], .dims = {23, 13, 11}, .slope = 1, .inter = 0};
        snprintf(s.path, sizeof s.path, "%s", tmp_path(k == 0 ? "seed_u8.nii.gz" : k == 1 ? "seed_i16.nii.gz" : "seed_f32.nii.gz"));
        vxl_raw_layout l;
        vxl_load_options o = options(NULL, dir);
        vxl_brick_source *src = NULL;
        vxl_err e = {0};
        if (write_source(&s, (uint32_t)k) != 0) return 1;
        /* the cache keeps its source's mtime: a fixed one makes the seeds the
         * same bytes on every run, which the fixed-seed fuzzing in
         * ./build.sh test needs */
        const struct timespec fixed[2] = {{1700000000, 0}, {1700000000, 0}};
        if (utimensat(AT_FDCWD, s.path, fixed, 0) != 0) return 1;
        layout_of(&s, &l);
        if (vxl_brick_cache_open_tuned(&l, &o, &tiny, &src, &e) != VXL_OK) {
            fprintf(stderr, "seed: %s\n", e.msg);
            return 1;
        }
        vxl_brick_source_free(src);
        unlink(s.path);
    }
    return 0;
}

int main(int argc, char **argv)
{
    snprintf(tmp_root, sizeof tmp_root, "/tmp/vxl_brick_cache_XXXXXX");
    if (!mkdtemp(tmp_root)) return 1;
    if (argc == 3 && strcmp(argv[1], "--write-seeds") == 0) {
        int rc = write_seeds(argv[2]);
        remove_tree(tmp_root);
        return rc;
    }
    RUN(every_level_equals_the_whole_load);
    RUN(second_open_reads_the_cache_and_changes_rebuild);
    RUN(damage_is_detected_never_trusted);
    RUN(cancel_leaves_no_file_and_cache_dir_is_honoured);
    RUN(bad_sources_fail_naming_the_file_and_leave_nothing);
    RUN(threads_read_at_once);
    RUN(page_bricks_and_random_boxes_equal_the_whole_load);
    RUN(loader_threads_give_every_brick_with_its_ghost);
    RUN(an_old_format_version_is_rebuilt);
    RUN(attached_nrrd_gzip_and_zlib_metaimage_stream_through_the_cache);
    RUN(a_brick_inflating_past_its_size_is_an_error);
    RUN(vxl_volume_load_streams_a_gz_through_the_cache);
    remove_tree(tmp_root);
    return TEST_SUMMARY();
}
