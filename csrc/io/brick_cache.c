/* brick_cache.c - where a source's bricked cache lives, and the open that
 * reads it or (re)builds it first (brick_cache.h). A cache that is missing,
 * made from another version of the source, or damaged in any way the reader
 * detects is rebuilt, never trusted; the rebuild replaces it by rename, so
 * readers of the old file keep their own copy. */
#include "brick_cache.h"
#include "files.h"

#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hash.h"

#define DEFAULT_BRICK 32u
#define DEFAULT_SLAB_BYTES (128ull << 20)

/* mkdir -p; 0 on success (or when it exists). */
static int make_dirs(const char *dir)
{
    char p[4096];
    if (snprintf(p, sizeof p, "%s", dir) >= (int)sizeof p) return -1;
    for (char *c = p + 1; *c; c++)
        if (vxl_path_is_separator(*c) && c[-1] != ':') { /* "C:" is a drive, not a folder to make */
            const char sep = *c;
            *c = 0;
            if (vxl_mkdir(p) != 0) return -1;
            *c = sep;
        }
    return vxl_mkdir(p);
}

/* A cache in a shared folder is named by the source's base name and a hash
 * of its absolute path, so equal names from different folders differ. */
static int shared_name(const char *dir, const vxl_raw_layout *l, const char *base, const char *suffix, char *out,
                       size_t n, vxl_err *e)
{
    if (make_dirs(dir) != 0)
        return vxl_fail(e, VXL_ERR_IO, "cannot create the cache folder %s: %s", dir, strerror(errno));
    char abs[4096];
    const char *key = vxl_real_path(l->path, abs, sizeof abs) ? abs : l->path;
    uint64_t h = vxl_fnv(14695981039346656037ull, key, strlen(key));
    if (snprintf(out, n, "%s/%s-%016llx%s.vxlcache", dir, base, (unsigned long long)h, suffix) >= (int)n)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "the cache path in %s is too long", dir);
    return VXL_OK;
}

/* opt->cache_dir, else beside the source, else the user's cache folder. */
static int cache_path(const vxl_raw_layout *l, const vxl_load_options *opt, char *out, size_t n, vxl_err *e)
{
    const char *slash = vxl_path_last_separator(l->path);
    const char *base = slash ? slash + 1 : l->path;
    char suffix[32] = "";
    if (l->frame) snprintf(suffix, sizeof suffix, ".frame%u", l->frame);
    const size_t have = opt && opt->struct_size ? opt->struct_size : sizeof *opt; /* 0: the whole struct */
    if (opt && have >= offsetof(vxl_load_options, cache_dir) + sizeof opt->cache_dir && opt->cache_dir &&
        opt->cache_dir[0])
        return shared_name(opt->cache_dir, l, base, suffix, out, n, e);
    char dir[4096];
    if (slash) snprintf(dir, sizeof dir, "%.*s", (int)(slash - l->path) ? (int)(slash - l->path) : 1, l->path);
    else snprintf(dir, sizeof dir, ".");
    if (vxl_dir_writable(dir)) {
        if (snprintf(out, n, "%s/%s%s.vxlcache", dir, base, suffix) >= (int)n)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "the cache path beside %s is too long", l->path);
        return VXL_OK;
    }
    char user[4096];
    if (vxl_user_cache_dir(user, sizeof user) != 0)
        return vxl_fail(e, VXL_ERR_IO,
                        "%s's folder is not writable and the system names no cache folder for this user (XDG_CACHE_HOME "
                        "or HOME; LOCALAPPDATA on Windows): set a cache folder", l->path);
    return shared_name(user, l, base, suffix, out, n, e);
}

static uint32_t power_of_two_at_most(uint32_t v)
{
    uint32_t p = 1;
    while (p * 2 <= v) p *= 2;
    return p;
}

int vxl_brick_cache_open_tuned(const vxl_raw_layout *l, const vxl_load_options *opt, const vxl_brick_cache_tuning *t,
                               vxl_brick_source **out, vxl_err *e)
{
    if (!out || !l) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "brick cache: layout or out is NULL");
    *out = NULL;
    const uint32_t max_dim = opt && opt->max_dim ? opt->max_dim : VXL_DEFAULT_MAX_DIM;
    for (int a = 0; a < 3; a++)
        if (!l->dims[a] || l->dims[a] > max_dim)
            return vxl_fail(e, VXL_ERR_LIMIT, "%s: dimensions %ux%ux%u are outside 1..%u per axis", l->path,
                            l->dims[0], l->dims[1], l->dims[2], max_dim);
    if (!vxl_dtype_size(l->dtype)) return vxl_fail(e, VXL_ERR_FORMAT, "%s: unknown data type %u", l->path, l->dtype);
    vxl_brick_cache_tuning tt = {DEFAULT_BRICK, DEFAULT_SLAB_BYTES, 0};
    if (t && t->brick) tt.brick = power_of_two_at_most(t->brick < 2 ? 2 : t->brick > 256 ? 256 : t->brick);
    if (t && t->slab_bytes) tt.slab_bytes = t->slab_bytes;
    if (t && t->coarsest_bytes) tt.coarsest_bytes = t->coarsest_bytes;

    char path[4400];
    int rc = cache_path(l, opt, path, sizeof path, e);
    if (rc) return rc;
    vxl_err probe = {0};
    if (vxl_brick_cache_read_open(path, l, max_dim, out, &probe) == VXL_OK) return VXL_OK;
    /* missing, stale or damaged: (re)build it */
    rc = vxl_brick_cache_write(l, opt, &tt, path, e);
    if (!rc) rc = vxl_brick_cache_read_open(path, l, max_dim, out, e);
    if (!rc) vxl_brick_cache_mark_built(*out);
    return rc;
}

int vxl_brick_cache_open(const vxl_raw_layout *layout, const vxl_load_options *opt, vxl_brick_source **out,
                         vxl_err *e)
{
    return vxl_brick_cache_open_tuned(layout, opt, NULL, out, e);
}
