/* brick_cache_read.c - a bricked cache file as a brick source
 * (brick_source.h): any box of any level, read by pread brick by brick and
 * kept in a small LRU of decoded bricks under a lock, so the loader thread
 * and the caller's thread can read at once. Every size in the file is
 * bounded (brick_cache_format.c) before anything is allocated; a brick
 * whose checksum fails is an error naming the cache, and the cache is
 * removed so the next open rebuilds it. */
#define _FILE_OFFSET_BITS 64
#include <errno.h>
#include <math.h>
#include "threads.h"
#include "files.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brick_cache.h"
#include "brick_cache_format.h"
#include "crc32.h"
#include "loader_util.h"
#include "zlib_api.h"

#define LRU_SLOTS 64
#define TABLE_CHUNK 4096 /* entries read at a time */

typedef struct lru_slot {
    uint64_t id;    /* brick number + 1; 0 = empty */
    uint64_t stamp; /* last use */
    uint8_t *data;
} lru_slot;

typedef struct cache_ctx {
    int fd;
    char path[4096];
    vxl_cache_header h;
    vxl_cache_grid g;
    vxl_cache_entry *table;
    int built;
    vxl_mutex lock;
    uint64_t clock;
    lru_slot lru[LRU_SLOTS];
} cache_ctx;

static int cache_read(vxl_brick_source *s, uint32_t level, const uint32_t lo[3], const uint32_t size[3], void *out,
                      vxl_err *e);
static void cache_close(vxl_brick_source *s);
static const vxl_brick_source_ops cache_ops = {cache_read, cache_close};

/* 0 when all n bytes at off were read (a short or failed read is damage to the cache) */
static int pread_all(int fd, void *buf, size_t n, uint64_t off)
{
    return vxl_pread_full(fd, buf, n, off) == (int64_t)n ? 0 : -1;
}

static uint64_t brick_bytes(const cache_ctx *c, uint32_t level, uint64_t i)
{
    uint32_t lo[3], sz[3];
    vxl_cache_brick_box(&c->g, level, i, lo, sz);
    return (uint64_t)sz[0] * sz[1] * sz[2] * c->g.texel_bytes;
}

static int damaged(const char *path, vxl_err *e, const char *what)
{
    return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s is truncated or damaged: %s", path, what);
}

/* The index: CRC-checked, and every value a normalised min <= max. */
static int load_index(cache_ctx *c, float **out, vxl_err *e)
{
    float *ix = malloc((size_t)c->h.index_bytes);
    if (!ix) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the index of %s", c->path);
    if (pread_all(c->fd, ix, (size_t)c->h.index_bytes, c->h.index_offset) != 0) {
        free(ix);
        return damaged(c->path, e, "its index cannot be read");
    }
    if (vxl_crc32(0, ix, (size_t)c->h.index_bytes) != c->h.index_crc) {
        free(ix);
        return damaged(c->path, e, "its index fails its checksum");
    }
    for (uint64_t i = 0; i < c->g.index_count; i++)
        if (!(ix[2 * i] >= 0 && ix[2 * i + 1] <= 1 && ix[2 * i] <= ix[2 * i + 1])) {
            free(ix);
            return damaged(c->path, e, "its index holds values outside [0, 1]");
        }
    *out = ix;
    return VXL_OK;
}

/* The brick table, read in chunks, CRC-checked and every entry bounded. */
static int load_table(cache_ctx *c, vxl_err *e)
{
    const uint64_t n = c->h.brick_count;
    c->table = malloc((size_t)n * sizeof *c->table);
    uint8_t *buf = malloc((size_t)TABLE_CHUNK * VXL_CACHE_ENTRY_BYTES);
    if (!c->table || !buf) {
        free(buf);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the brick table of %s", c->path);
    }
    const uint64_t data_end = c->h.index_offset < c->h.table_offset ? c->h.index_offset : c->h.table_offset;
    uint32_t crc = 0;
    int rc = VXL_OK;
    uint32_t level = 0;
    for (uint64_t i0 = 0; !rc && i0 < n; i0 += TABLE_CHUNK) {
        const size_t k = n - i0 < TABLE_CHUNK ? (size_t)(n - i0) : TABLE_CHUNK;
        if (pread_all(c->fd, buf, k * VXL_CACHE_ENTRY_BYTES, c->h.table_offset + i0 * VXL_CACHE_ENTRY_BYTES) != 0) {
            rc = damaged(c->path, e, "its brick table cannot be read");
            break;
        }
        crc = vxl_crc32(crc, buf, k * VXL_CACHE_ENTRY_BYTES);
        for (size_t j = 0; j < k; j++) {
            const uint64_t i = i0 + j;
            while (i >= c->g.first[level + 1]) level++;
            vxl_cache_entry_decode(buf + j * VXL_CACHE_ENTRY_BYTES, &c->table[i]);
            if (vxl_cache_entry_check(&c->table[i], brick_bytes(c, level, i - c->g.first[level]), c->g.texel_bytes,
                                      data_end) != 0) {
                rc = damaged(c->path, e, "a brick lies outside the file or has an impossible size");
                break;
            }
        }
    }
    free(buf);
    if (!rc && crc != c->h.table_crc) rc = damaged(c->path, e, "its brick table fails its checksum");
    return rc;
}

int vxl_brick_cache_read_open(const char *path, const vxl_raw_layout *l, uint32_t max_dim, vxl_brick_source **out,
                              vxl_err *e)
{
    *out = NULL;
    vxl_brick_source *s = calloc(1, sizeof *s);
    cache_ctx *c = calloc(1, sizeof *c);
    if (!s || !c) {
        free(s);
        free(c);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the brick cache %s", path);
    }
    s->ops = &cache_ops;
    s->ctx = c;
    c->fd = -1;
    vxl_mutex_init(&c->lock);
    snprintf(c->path, sizeof c->path, "%s", path);
    int rc = VXL_OK;
    vxl_path_info st;
    uint8_t head[VXL_CACHE_HEADER_BYTES];
    /* nonblocking: a FIFO in the cache's place must not hang the open */
    if ((c->fd = vxl_file_open_read(path, 1)) < 0 || vxl_file_stat(c->fd, &st) != 0)
        rc = vxl_fail(e, VXL_ERR_IO, "cannot open the brick cache %s: %s", path, strerror(errno));
    else if (st.kind != VXL_PATH_FILE)
        rc = vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s is not a regular file", path);
    else if (st.size < VXL_CACHE_HEADER_BYTES || pread_all(c->fd, head, sizeof head, 0) != 0)
        rc = damaged(path, e, "shorter than its header");
    if (!rc) rc = vxl_cache_header_decode(head, &c->h, path, e);
    if (!rc && l && !vxl_cache_header_matches(&c->h, l))
        rc = vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s was made from another version of %s (size, time or header differ)",
                      path, l->path);
    if (!rc) rc = vxl_cache_header_check(&c->h, st.size, max_dim, &c->g, path, e);
    if (!rc) rc = load_index(c, &s->minmax, e);
    if (!rc) rc = load_table(c, e);
    if (rc) {
        vxl_brick_source_free(s);
        return rc;
    }
    s->texture_bits = c->h.texture_bits;
    s->n_levels = c->g.n_levels;
    memcpy(s->level_dims, c->g.dims, sizeof c->g.dims);
    s->index_brick = c->h.index_brick;
    memcpy(s->index_dims, c->g.index_dims, sizeof s->index_dims);
    s->resident_bytes = sizeof *s + sizeof *c + c->h.index_bytes + c->h.brick_count * sizeof *c->table +
                        (uint64_t)LRU_SLOTS * (c->h.brick + 2 * VXL_CACHE_APRON) * (c->h.brick + 2 * VXL_CACHE_APRON) *
                            (c->h.brick + 2 * VXL_CACHE_APRON) * c->g.texel_bytes;
    *out = s;
    return VXL_OK;
}

/* Reads and decodes brick `id` (level L, number i in the level) into dst. */
static int load_brick(vxl_brick_source *s, uint32_t L, uint64_t i, uint8_t *dst, uint64_t bytes, vxl_err *e)
{
    cache_ctx *c = s->ctx;
    const uint64_t id = c->g.first[L] + i;
    const vxl_cache_entry *en = &c->table[id];
    uint8_t *stored = en->kind == VXL_CACHE_RAW ? dst : malloc(en->size);
    if (!stored) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory reading brick %llu of %s", (unsigned long long)id, c->path);
    int rc = VXL_OK;
    errno = 0;
    if (pread_all(c->fd, stored, en->size, en->offset) != 0)
        rc = vxl_fail(e, VXL_ERR_IO, "cannot read brick %llu of the brick cache %s: %s", (unsigned long long)id,
                      c->path, errno ? strerror(errno) : "the file is shorter than its table says");
    else if (vxl_crc32(0, stored, en->size) != en->crc) {
        vxl_remove(c->path); /* never trusted again: the next open rebuilds it */
        rc = vxl_fail(e, VXL_ERR_FORMAT,
                      "brick cache %s is damaged (brick %llu of level %u fails its checksum); it was removed and the "
                      "next open rebuilds it",
                      c->path, (unsigned long long)i, L);
    }
    __atomic_fetch_add(&s->bytes_read, (uint64_t)en->size, __ATOMIC_RELAXED);
    if (!rc && en->kind == VXL_CACHE_CONSTANT) {
        for (uint64_t k = 0; k < bytes; k += c->g.texel_bytes) memcpy(dst + k, stored, c->g.texel_bytes);
    } else if (!rc && en->kind == VXL_CACHE_ZLIB) {
        const vxl_zlib *zl = vxl_zlib_api(e);
        uLongf n = (uLongf)bytes;
        int z = zl ? zl->uncompress(dst, &n, stored, en->size) : Z_OK;
        if (!zl)
            rc = VXL_ERR_IO;
        else if (z == Z_BUF_ERROR || (z == Z_OK && n != bytes))
            rc = vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s: brick %llu of level %u decompresses to %s its %llu bytes",
                          c->path, (unsigned long long)i, L, z == Z_OK ? "less than" : "more than",
                          (unsigned long long)bytes);
        else if (z != Z_OK)
            rc = vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s: brick %llu of level %u does not decompress (zlib %d)",
                          c->path, (unsigned long long)i, L, z);
    }
    if (stored != dst) free(stored);
    return rc;
}

/* Copies the part of brick (blo, bsz) inside the box (lo, size) to out. */
static void copy_overlap(const uint8_t *brick, const uint32_t blo[3], const uint32_t bsz[3], const uint32_t lo[3],
                         const uint32_t size[3], uint8_t *out, uint32_t tb)
{
    uint32_t a[3], b[3];
    for (int k = 0; k < 3; k++) {
        a[k] = blo[k] > lo[k] ? blo[k] : lo[k];
        b[k] = blo[k] + bsz[k] < lo[k] + size[k] ? blo[k] + bsz[k] : lo[k] + size[k];
    }
    const size_t row = (size_t)(b[0] - a[0]) * tb;
    for (uint32_t z = a[2]; z < b[2]; z++)
        for (uint32_t y = a[1]; y < b[1]; y++)
            memcpy(out + (((size_t)(z - lo[2]) * size[1] + (y - lo[1])) * size[0] + (a[0] - lo[0])) * tb,
                   brick + (((size_t)(z - blo[2]) * bsz[1] + (y - blo[1])) * bsz[0] + (a[0] - blo[0])) * tb, row);
}

/* The stored bricks whose boxes (core plus apron) cover lo .. lo + size - 1
 * on one axis: k0 .. k1. Brick k stores k*B - 1 .. k*B + B (inside the
 * level), so k0 = (lo + 1) / B starts at or before lo and k1 = (hi - 1) / B,
 * hi = lo + size - 1 the box's last voxel, ends at or past hi. A page brick
 * of edge B with its one-voxel ghost is one stored brick. */
static void covering(uint32_t lo, uint32_t size, uint32_t B, uint32_t n, uint32_t *k0, uint32_t *k1)
{
    const uint64_t hi = (uint64_t)lo + size - 1;
    *k0 = (uint32_t)(((uint64_t)lo + VXL_CACHE_APRON) / B);
    if (*k0 >= n) *k0 = n - 1;
    *k1 = hi >= VXL_CACHE_APRON ? (uint32_t)((hi - VXL_CACHE_APRON) / B) : 0;
    if (*k1 >= n) *k1 = n - 1;
    if (*k1 < *k0) *k1 = *k0;
}

/* Brick id (+1, as the LRU's ids) copied from the LRU into the box; 0 when absent. */
static int copy_cached(cache_ctx *c, uint64_t id, const uint32_t blo[3], const uint32_t bsz[3], const uint32_t lo[3],
                       const uint32_t size[3], uint8_t *out)
{
    vxl_mutex_lock(&c->lock);
    lru_slot *hit = NULL;
    for (int k = 0; k < LRU_SLOTS && !hit; k++)
        if (c->lru[k].id == id) hit = &c->lru[k];
    if (hit) {
        hit->stamp = ++c->clock;
        copy_overlap(hit->data, blo, bsz, lo, size, out, c->g.texel_bytes);
    }
    vxl_mutex_unlock(&c->lock);
    return hit != NULL;
}

static int cache_read(vxl_brick_source *s, uint32_t level, const uint32_t lo[3], const uint32_t size[3], void *out,
                      vxl_err *e)
{
    cache_ctx *c = s->ctx;
    if (level >= c->g.n_levels || !out)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "brick cache %s: no level %u (it has %u)", c->path, level,
                        c->g.n_levels);
    const uint32_t *d = c->g.dims[level], B = c->g.brick;
    for (int a = 0; a < 3; a++)
        if (!size[a] || lo[a] >= d[a] || size[a] > d[a] - lo[a])
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "box %u+%u %u+%u %u+%u is outside level %u (%ux%ux%u)",
                            lo[0], size[0], lo[1], size[1], lo[2], size[2], level, d[0], d[1], d[2]);
    const uint32_t *nb = c->g.bricks[level];
    uint32_t k0[3], k1[3];
    for (int a = 0; a < 3; a++) covering(lo[a], size[a], B, nb[a], &k0[a], &k1[a]);
    for (uint32_t bz = k0[2]; bz <= k1[2]; bz++)
        for (uint32_t by = k0[1]; by <= k1[1]; by++)
            for (uint32_t bx = k0[0]; bx <= k1[0]; bx++) {
                const uint64_t i = bx + (uint64_t)nb[0] * (by + (uint64_t)nb[1] * bz), id = c->g.first[level] + i + 1;
                uint32_t blo[3], bsz[3];
                vxl_cache_brick_box(&c->g, level, i, blo, bsz);
                if (copy_cached(c, id, blo, bsz, lo, size, out)) continue;
                const uint64_t bytes = (uint64_t)bsz[0] * bsz[1] * bsz[2] * c->g.texel_bytes;
                if (!memcmp(blo, lo, sizeof blo) && !memcmp(bsz, size, sizeof bsz))
                    /* the box is this brick (a page brick of the cache's edge): decoded in place, not kept,
                       since the renderer keeps it and it is the only read that wants all of it */
                    return load_brick(s, level, i, out, bytes, e);
                /* decoded outside the lock, into a buffer of this call */
                uint8_t *data = malloc((size_t)bytes);
                if (!data) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for a brick of %s", c->path);
                int rc = load_brick(s, level, i, data, bytes, e);
                if (rc) {
                    free(data);
                    return rc;
                }
                copy_overlap(data, blo, bsz, lo, size, out, c->g.texel_bytes);
                vxl_mutex_lock(&c->lock);
                lru_slot *oldest = &c->lru[0];
                for (int k = 1; k < LRU_SLOTS; k++)
                    if (c->lru[k].stamp < oldest->stamp) oldest = &c->lru[k];
                free(oldest->data);
                oldest->data = data;
                oldest->id = id;
                oldest->stamp = ++c->clock;
                vxl_mutex_unlock(&c->lock);
            }
    return VXL_OK;
}

static void cache_close(vxl_brick_source *s)
{
    cache_ctx *c = s->ctx;
    if (!c) return;
    vxl_file_close(c->fd);
    for (int k = 0; k < LRU_SLOTS; k++) free(c->lru[k].data);
    free(c->table);
    vxl_mutex_destroy(&c->lock);
    free(c);
    s->ctx = NULL;
}

int vxl_brick_cache_get_info(const vxl_brick_source *s, vxl_brick_cache_info *out, vxl_err *e)
{
    if (!s || s->ops != &cache_ops || !out)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "not a brick cache source");
    const cache_ctx *c = s->ctx;
    memset(out, 0, sizeof *out);
    out->value_min = c->h.value_min;
    out->value_max = c->h.value_max;
    out->tex_lo = c->h.tex_lo;
    out->tex_hi = c->h.tex_hi;
    out->nan_count = c->h.nan_count;
    out->inf_count = c->h.inf_count;
    out->brick = c->h.brick;
    out->built = c->built;
    out->path = c->path;
    return VXL_OK;
}

void vxl_brick_cache_mark_built(vxl_brick_source *s)
{
    if (s && s->ops == &cache_ops) ((cache_ctx *)s->ctx)->built = 1;
}

int vxl_brick_cache_describe(const vxl_brick_source *s, vxl_volume *v, vxl_err *e)
{
    vxl_brick_cache_info info = {0};
    int rc = vxl_brick_cache_get_info(s, &info, e);
    if (rc) return rc;
    v->tex_lo = info.tex_lo;
    v->tex_hi = info.tex_hi;
    v->value_min = info.value_min;
    v->value_max = info.value_max;
    v->nan_count = info.nan_count;
    v->inf_count = info.inf_count;
    return VXL_OK;
}
