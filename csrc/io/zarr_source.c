/* zarr_source.c - an OME-Zarr store as a brick source (brick_source.h;
 * docs/zarr.md "Streaming"): boxes of any level are read chunk by chunk, on
 * demand, from any thread.
 *
 * Levels: the store's multiscale levels from the chosen one (0 unless
 * "#level=N") that are each 2x smaller per axis than the level before, as
 * the source contract wants (ceil(dims / 2^k); a level of floor(dims / 2^k)
 * is taken too, its missing last plane read as the one before it). Levels
 * that halve some axes only (anisotropic pyramids) are skipped.
 *
 * Memory: the store's metadata, the index and a small cache of decoded
 * chunks (LRU, at most CACHE_MAX_BYTES, or a few chunks when they are
 * larger); a read decodes into one chunk buffer of its own. Nothing else
 * of the store is held.
 *
 * Values: 8- and 16-bit integers are stored exactly (code = value - type
 * minimum, the type's range, as a whole read); other types are normalised
 * into [0, 1] over the omero window of the channel when the metadata has
 * one, else over the finite range of the coarsest level (values of finer
 * levels outside it are clamped to its ends).
 *
 * Index: built from level 0 one chunk at a time (each chunk decoded once),
 * folding each chunk's texels into the bricks whose box plus one-voxel
 * apron they fall in: the same min-max vxl_bricks_minmax_cpu gives over the
 * whole level, so no visible brick is ever skipped. */
#include <math.h>
#include "threads.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "loader_util.h"
#include "loaders.h"
#include "stream_load.h"
#include "zarr.h"

#define CACHE_SLOTS 64
#define CACHE_MAX_BYTES (64ull << 20)

typedef struct cache_slot {
    unsigned char *data; /* decoded chunk, the array's type, native order; NULL: empty */
    uint64_t bytes, used;
    uint32_t level;
    uint64_t idx[VXL_ZARR_MAX_NDIM];
} cache_slot;

typedef struct zarr_ctx {
    vxl_zarr_store *store;
    int array_of[VXL_SOURCE_MAX_LEVELS]; /* source level -> store level */
    uint64_t sel[VXL_ZARR_ROLES];         /* t and c chosen */
    uint32_t dtype;
    double lo, inv;                       /* 32-bit texels: t = (value - lo) * inv, clamped */
    vxl_zarr_codecs *codecs;
    vxl_mutex lock;                 /* the cache */
    cache_slot slot[CACHE_SLOTS];
    uint64_t cache_cap, cache_bytes, tick;
} zarr_ctx;

/* ------------------------------------------------------------ conversion */

static double raw_at(const unsigned char *p, uint32_t dtype)
{
    switch (dtype) {
    case VXL_DTYPE_U8: return *p;
    case VXL_DTYPE_I8: return *(const int8_t *)p;
    case VXL_DTYPE_U16: { uint16_t v; memcpy(&v, p, 2); return v; }
    case VXL_DTYPE_I16: { int16_t v; memcpy(&v, p, 2); return v; }
    case VXL_DTYPE_U32: { uint32_t v; memcpy(&v, p, 4); return v; }
    case VXL_DTYPE_I32: { int32_t v; memcpy(&v, p, 4); return v; }
    case VXL_DTYPE_F32: { float v; memcpy(&v, p, 4); return v; }
    default: { double v; memcpy(&v, p, 8); return v; }
    }
}

/* n elements of the chunk, stride apart (in elements), into n texels. */
static void convert_run(const zarr_ctx *c, const unsigned char *src, uint64_t stride, uint64_t n, void *dst)
{
    const size_t elem = vxl_dtype_size(c->dtype);
    switch (c->dtype) {
    case VXL_DTYPE_U8:
        for (uint64_t i = 0; i < n; i++) ((uint8_t *)dst)[i] = src[i * stride];
        return;
    case VXL_DTYPE_I8: /* code = value + 128, as vxl_volume_build */
        for (uint64_t i = 0; i < n; i++) ((uint8_t *)dst)[i] = (uint8_t)(src[i * stride] ^ 0x80);
        return;
    case VXL_DTYPE_U16:
        for (uint64_t i = 0; i < n; i++) memcpy((uint16_t *)dst + i, src + i * stride * 2, 2);
        return;
    case VXL_DTYPE_I16:
        for (uint64_t i = 0; i < n; i++) {
            int16_t v;
            memcpy(&v, src + i * stride * 2, 2);
            ((uint16_t *)dst)[i] = (uint16_t)(v + 32768);
        }
        return;
    default:
        for (uint64_t i = 0; i < n; i++) {
            double x = raw_at(src + i * stride * elem, c->dtype);
            double t = isnan(x) ? 0.0 : (x - c->lo) * c->inv; /* NaN as the minimum, as a whole read */
            ((float *)dst)[i] = (float)(t < 0 ? 0 : t > 1 ? 1 : t);
        }
    }
}

/* ---------------------------------------------------------------- chunks */

/* Element strides of a chunk (C order). */
static void chunk_strides(const vxl_zarr_array *a, uint64_t *stride)
{
    uint64_t st = 1;
    for (int i = a->ndim - 1; i >= 0; i--) {
        stride[i] = st;
        st *= a->chunks[i];
    }
}

/* The chunk index holding element (t, c, z, y, x) = (sel, z, y, x). */
static void chunk_index(const zarr_ctx *c, const vxl_zarr_array *a, const uint64_t xyz[3], uint64_t *idx)
{
    const vxl_zarr_store *s = c->store;
    for (int i = 0; i < a->ndim; i++) idx[i] = 0;
    for (int r = VXL_ZARR_T; r <= VXL_ZARR_C; r++)
        if (s->axis[r] >= 0) idx[s->axis[r]] = c->sel[r] / a->chunks[s->axis[r]];
    idx[s->axis[VXL_ZARR_X]] = xyz[0] / a->chunks[s->axis[VXL_ZARR_X]];
    idx[s->axis[VXL_ZARR_Y]] = xyz[1] / a->chunks[s->axis[VXL_ZARR_Y]];
    idx[s->axis[VXL_ZARR_Z]] = xyz[2] / a->chunks[s->axis[VXL_ZARR_Z]];
}

static cache_slot *cache_find(zarr_ctx *c, uint32_t level, const uint64_t *idx, int ndim)
{
    for (int i = 0; i < CACHE_SLOTS; i++) {
        cache_slot *sl = &c->slot[i];
        if (sl->data && sl->level == level && !memcmp(sl->idx, idx, (size_t)ndim * sizeof *idx)) {
            sl->used = ++c->tick;
            return sl;
        }
    }
    return NULL;
}

/* Keeps data (the caller's malloc) in the cache when it fits, evicting the
 * least recently used; returns 0 when it is not kept (the caller frees it). */
static int cache_put(vxl_brick_source *s, zarr_ctx *c, uint32_t level, const uint64_t *idx, int ndim,
                     unsigned char *data, uint64_t bytes)
{
    if (bytes > c->cache_cap) return 0;
    for (;;) {
        cache_slot *victim = NULL, *empty = NULL;
        for (int i = 0; i < CACHE_SLOTS; i++) {
            cache_slot *sl = &c->slot[i];
            if (!sl->data) empty = empty ? empty : sl;
            else if (!victim || sl->used < victim->used) victim = sl;
        }
        if (empty && c->cache_bytes + bytes <= c->cache_cap) {
            empty->data = data;
            empty->bytes = bytes;
            empty->level = level;
            memcpy(empty->idx, idx, (size_t)ndim * sizeof *idx);
            empty->used = ++c->tick;
            c->cache_bytes += bytes;
            __atomic_fetch_add(&s->resident_bytes, bytes, __ATOMIC_RELAXED);
            return 1;
        }
        if (!victim) return 0;
        free(victim->data);
        victim->data = NULL;
        c->cache_bytes -= victim->bytes;
        __atomic_fetch_sub(&s->resident_bytes, victim->bytes, __ATOMIC_RELAXED);
    }
}

/* The part of box [lo, hi) (level coordinates, x y z) inside chunk idx,
 * converted into out (the box's texels, x fastest). Coordinates past the
 * array's extent (a floor-sized level) read its last plane. */
static void copy_box(const zarr_ctx *c, const vxl_zarr_array *a, const uint64_t *idx, const unsigned char *chunk,
                     const uint64_t ext[3], const uint32_t lo[3], const uint32_t hi[3], uint32_t bpv, void *out)
{
    const vxl_zarr_store *s = c->store;
    const int ax[3] = {s->axis[VXL_ZARR_X], s->axis[VXL_ZARR_Y], s->axis[VXL_ZARR_Z]};
    const size_t elem = vxl_dtype_size(a->dtype);
    uint64_t stride[VXL_ZARR_MAX_NDIM];
    chunk_strides(a, stride);
    uint64_t base = 0; /* the chosen t and c inside the chunk */
    for (int r = VXL_ZARR_T; r <= VXL_ZARR_C; r++)
        if (s->axis[r] >= 0) base += (c->sel[r] % a->chunks[s->axis[r]]) * stride[s->axis[r]];
    uint64_t o0[3], o1[3], c0[3]; /* output range per axis, the chunk's first element */
    for (int d = 0; d < 3; d++) {
        c0[d] = idx[ax[d]] * a->chunks[ax[d]];
        const uint64_t c1 = c0[d] + a->chunks[ax[d]];
        o0[d] = lo[d] > c0[d] ? lo[d] : c0[d];
        o1[d] = c1 >= ext[d] ? hi[d] : (hi[d] < c1 ? hi[d] : c1); /* the last chunk also serves past the extent */
    }
    const uint64_t w = hi[0] - lo[0], h = hi[1] - lo[1];
    for (uint64_t z = o0[2]; z < o1[2]; z++) {
        const uint64_t zc = (z < ext[2] ? z : ext[2] - 1) - c0[2];
        for (uint64_t y = o0[1]; y < o1[1]; y++) {
            const uint64_t yc = (y < ext[1] ? y : ext[1] - 1) - c0[1];
            const unsigned char *src = chunk + (base + zc * stride[ax[2]] + yc * stride[ax[1]] +
                                                (o0[0] - c0[0]) * stride[ax[0]]) * elem;
            unsigned char *dst = (unsigned char *)out + (((z - lo[2]) * h + (y - lo[1])) * w + (o0[0] - lo[0])) * bpv;
            const uint64_t end = o1[0] < ext[0] ? o1[0] : ext[0], inside = end > o0[0] ? end - o0[0] : 0;
            if (inside) convert_run(c, src, stride[ax[0]], inside, dst);
            if (inside < o1[0] - o0[0]) { /* past a floor-sized extent: the array's last voxel */
                const unsigned char *last = chunk + (base + zc * stride[ax[2]] + yc * stride[ax[1]] +
                                                     (ext[0] - 1 - c0[0]) * stride[ax[0]]) * elem;
                for (uint64_t x = inside; x < o1[0] - o0[0]; x++) convert_run(c, last, 1, 1, dst + x * bpv);
            }
        }
    }
}

/* Decodes chunk idx of source level `level` (from the cache when there)
 * and copies the box's part of it (copy_box) under the cache lock; the
 * decoding itself runs outside the lock, so readers decode in parallel. */
static int with_chunk(vxl_brick_source *s, uint32_t level, const uint64_t *idx, const uint64_t ext[3],
                      const uint32_t lo[3], const uint32_t hi[3], void *out, vxl_err *e)
{
    zarr_ctx *c = s->ctx;
    const vxl_zarr_array *a = &c->store->level[c->array_of[level]];
    const uint32_t bpv = s->texture_bits / 8;
    vxl_mutex_lock(&c->lock);
    cache_slot *hit = cache_find(c, level, idx, a->ndim);
    if (hit) {
        copy_box(c, a, idx, hit->data, ext, lo, hi, bpv, out);
        vxl_mutex_unlock(&c->lock);
        return VXL_OK;
    }
    vxl_mutex_unlock(&c->lock);
    const uint64_t nbytes = vxl_zarr_chunk_bytes(a);
    unsigned char *chunk = malloc((size_t)nbytes);
    if (!chunk)
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for a chunk of %llu bytes", a->path,
                        (unsigned long long)nbytes);
    int rc = vxl_zarr_read_chunk_counted(a, idx, c->codecs, chunk, &s->bytes_read, e);
    if (rc) {
        free(chunk);
        return rc;
    }
    vxl_mutex_lock(&c->lock);
    copy_box(c, a, idx, chunk, ext, lo, hi, bpv, out);
    const int kept = !cache_find(c, level, idx, a->ndim) && cache_put(s, c, level, idx, a->ndim, chunk, nbytes);
    vxl_mutex_unlock(&c->lock);
    if (!kept) free(chunk);
    return VXL_OK;
}

static void array_extent(const zarr_ctx *c, const vxl_zarr_array *a, uint64_t ext[3])
{
    ext[0] = a->shape[c->store->axis[VXL_ZARR_X]];
    ext[1] = a->shape[c->store->axis[VXL_ZARR_Y]];
    ext[2] = a->shape[c->store->axis[VXL_ZARR_Z]];
}

static int zarr_read(vxl_brick_source *s, uint32_t level, const uint32_t lo[3], const uint32_t size[3], void *out,
                     vxl_err *e)
{
    int rc = vxl_brick_source_check_box(s, level, lo, size, e);
    if (rc) return rc;
    zarr_ctx *c = s->ctx;
    const vxl_zarr_array *a = &c->store->level[c->array_of[level]];
    uint64_t ext[3];
    array_extent(c, a, ext);
    const uint32_t hi[3] = {lo[0] + size[0], lo[1] + size[1], lo[2] + size[2]};
    uint64_t first[3], last[3]; /* the chunks the box touches, per axis (x y z) */
    const int ax[3] = {c->store->axis[VXL_ZARR_X], c->store->axis[VXL_ZARR_Y], c->store->axis[VXL_ZARR_Z]};
    for (int k = 0; k < 3; k++) {
        const uint64_t l = lo[k] < ext[k] ? lo[k] : ext[k] - 1, h = hi[k] - 1 < ext[k] ? hi[k] - 1 : ext[k] - 1;
        first[k] = l / a->chunks[ax[k]];
        last[k] = h / a->chunks[ax[k]];
    }
    uint64_t idx[VXL_ZARR_MAX_NDIM];
    for (uint64_t cz = first[2]; cz <= last[2]; cz++)
        for (uint64_t cy = first[1]; cy <= last[1]; cy++)
            for (uint64_t cx = first[0]; cx <= last[0]; cx++) {
                const uint64_t at[3] = {cx * a->chunks[ax[0]], cy * a->chunks[ax[1]], cz * a->chunks[ax[2]]};
                chunk_index(c, a, at, idx);
                if ((rc = with_chunk(s, level, idx, ext, lo, hi, out, e))) return rc;
            }
    return VXL_OK;
}

static void zarr_close(vxl_brick_source *s)
{
    zarr_ctx *c = s->ctx;
    if (!c) return;
    for (int i = 0; i < CACHE_SLOTS; i++) free(c->slot[i].data);
    vxl_zarr_codecs_free(c->codecs);
    vxl_mutex_destroy(&c->lock);
    free(c->store);
    free(c);
    s->ctx = NULL;
}

static const vxl_brick_source_ops zarr_ops = {zarr_read, zarr_close};

/* ---------------------------------------------------------------- levels */

static int halves(uint64_t fine, uint64_t coarse, uint32_t k)
{
    const uint64_t ceil_k = (fine + (1ull << k) - 1) >> k, floor_k = fine >> k;
    return coarse == ceil_k || (coarse == floor_k && floor_k >= 1);
}

/* Source levels: the store's levels from `base` that are 2^k smaller per
 * axis than base (k = 1, 2, ...); the rest skipped. */
static uint32_t pick_levels(zarr_ctx *c, int base)
{
    const vxl_zarr_store *s = c->store;
    uint64_t e0[3], ek[3];
    array_extent(c, &s->level[base], e0);
    uint32_t n = 0;
    c->array_of[n++] = base;
    for (int l = base + 1; l < s->nlevels && n < VXL_SOURCE_MAX_LEVELS; l++) {
        array_extent(c, &s->level[l], ek);
        if (halves(e0[0], ek[0], n) && halves(e0[1], ek[1], n) && halves(e0[2], ek[2], n)) c->array_of[n++] = l;
    }
    return n;
}

/* ------------------------------------------------------------ the index */

/* Folds min-max over texels [x0, x1] of one row into the bricks whose box
 * plus apron holds (y, z): the per-brick rule of vxl_index_build_slice,
 * applied to a chunk's box instead of a whole slice. */
static void fold_row(vxl_index_build *b, const void *row, uint32_t x_lo, uint32_t x_hi, uint32_t y, uint32_t z)
{
    const uint32_t B = b->brick, w = b->dims[0];
    uint32_t by0 = y > 0 ? (y - 1) / B : 0, by1 = (y + 1) / B < b->grid[1] ? (y + 1) / B : b->grid[1] - 1;
    uint32_t bz0 = z > 0 ? (z - 1) / B : 0, bz1 = (z + 1) / B < b->grid[2] ? (z + 1) / B : b->grid[2] - 1;
    uint32_t bx0 = x_lo > 0 ? (x_lo - 1) / B : 0;
    uint32_t bx1 = (x_hi + 1) / B < b->grid[0] ? (x_hi + 1) / B : b->grid[0] - 1;
    for (uint32_t bx = bx0; bx <= bx1; bx++) {
        uint32_t x0 = bx * B > 0 ? bx * B - 1 : 0, x1 = bx * B + B < w ? bx * B + B : w - 1;
        x0 = x0 > x_lo ? x0 : x_lo;
        x1 = x1 < x_hi ? x1 : x_hi;
        if (x0 > x1) continue;
        float lo = 0, hi = 0;
        for (uint32_t x = x0; x <= x1; x++) { /* the index's floats: code / (2^bits - 1) in double */
            float v = b->texture_bits == 8 ? (float)(((const uint8_t *)row)[x - x_lo] / 255.0)
                      : b->texture_bits == 16 ? (float)(((const uint16_t *)row)[x - x_lo] / 65535.0)
                                              : ((const float *)row)[x - x_lo];
            if (x == x0 || v < lo) lo = v;
            if (x == x0 || v > hi) hi = v;
        }
        for (uint32_t bz = bz0; bz <= bz1; bz++)
            for (uint32_t by = by0; by <= by1; by++) {
                float *mm = b->minmax + 2 * (bx + (size_t)b->grid[0] * (by + (size_t)b->grid[1] * bz));
                if (lo < mm[0]) mm[0] = lo;
                if (hi > mm[1]) mm[1] = hi;
            }
    }
}

/* Level 0, one chunk at a time: its box read (so decoded once) and folded. */
static int build_index(vxl_brick_source *s, const vxl_load_options *opt, vxl_err *e)
{
    zarr_ctx *c = s->ctx;
    const vxl_zarr_array *a = &c->store->level[c->array_of[0]];
    const uint32_t *d = s->level_dims[0], bpv = s->texture_bits / 8;
    const int ax[3] = {c->store->axis[VXL_ZARR_X], c->store->axis[VXL_ZARR_Y], c->store->axis[VXL_ZARR_Z]};
    uint64_t grid[3], total = 1;
    for (int k = 0; k < 3; k++) total *= grid[k] = (d[k] + a->chunks[ax[k]] - 1) / a->chunks[ax[k]];
    vxl_index_build b;
    int rc = vxl_index_build_begin(&b, d, s->texture_bits, vxl_source_index_brick(d), e);
    if (rc) return rc;
    const uint64_t box_bytes = a->chunks[ax[0]] * a->chunks[ax[1]] * a->chunks[ax[2]] * bpv;
    unsigned char *box = malloc((size_t)box_bytes);
    if (!box) rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for a chunk", a->path);
    uint64_t n = 0;
    for (uint64_t cz = 0; cz < grid[2] && !rc; cz++)
        for (uint64_t cy = 0; cy < grid[1] && !rc; cy++)
            for (uint64_t cx = 0; cx < grid[0] && !rc; cx++, n++) {
                uint32_t lo[3], size[3];
                const uint64_t at[3] = {cx, cy, cz};
                for (int k = 0; k < 3; k++) {
                    lo[k] = (uint32_t)(at[k] * a->chunks[ax[k]]);
                    size[k] = (uint32_t)(lo[k] + a->chunks[ax[k]] <= d[k] ? a->chunks[ax[k]] : d[k] - lo[k]);
                }
                if ((rc = zarr_read(s, 0, lo, size, box, e))) break;
                for (uint32_t z = 0; z < size[2]; z++)
                    for (uint32_t y = 0; y < size[1]; y++)
                        fold_row(&b, box + ((size_t)z * size[1] + y) * size[0] * bpv, lo[0], lo[0] + size[0] - 1,
                                 lo[1] + y, lo[2] + z);
                if (n % 64 == 63 || n + 1 == total)
                    rc = vxl_source_progress(opt, (n + 1.0) / (double)total, "indexing the OME-Zarr chunks", e);
            }
    free(box);
    if (rc) {
        vxl_index_build_free(&b);
        return rc;
    }
    vxl_index_build_finish(&b, s);
    return VXL_OK;
}

/* ------------------------------------------------------ the value range */

/* Finite min and max of source level `level` (the coarsest), over its
 * chunks at the chosen t and c; the values are read raw (before any range
 * is known) with a float texel format that passes them through. */
static int level_range(vxl_brick_source *s, uint32_t level, double *mn, double *mx, vxl_err *e)
{
    zarr_ctx *c = s->ctx;
    const vxl_zarr_array *a = &c->store->level[c->array_of[level]];
    const vxl_zarr_store *st = c->store;
    uint64_t ext[3], stride[VXL_ZARR_MAX_NDIM], idx[VXL_ZARR_MAX_NDIM];
    array_extent(c, a, ext);
    chunk_strides(a, stride);
    const int ax[3] = {st->axis[VXL_ZARR_X], st->axis[VXL_ZARR_Y], st->axis[VXL_ZARR_Z]};
    const size_t elem = vxl_dtype_size(a->dtype);
    unsigned char *chunk = malloc((size_t)vxl_zarr_chunk_bytes(a));
    if (!chunk) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for a chunk", a->path);
    *mn = INFINITY;
    *mx = -INFINITY;
    int rc = VXL_OK;
    uint64_t base = 0;
    for (int r = VXL_ZARR_T; r <= VXL_ZARR_C; r++)
        if (st->axis[r] >= 0) base += (c->sel[r] % a->chunks[st->axis[r]]) * stride[st->axis[r]];
    for (uint64_t z0 = 0; z0 < ext[2] && !rc; z0 += a->chunks[ax[2]])
        for (uint64_t y0 = 0; y0 < ext[1] && !rc; y0 += a->chunks[ax[1]])
            for (uint64_t x0 = 0; x0 < ext[0] && !rc; x0 += a->chunks[ax[0]]) {
                const uint64_t at[3] = {x0, y0, z0};
                chunk_index(c, a, at, idx);
                if ((rc = vxl_zarr_read_chunk_counted(a, idx, c->codecs, chunk, &s->bytes_read, e))) break;
                const uint64_t nx = ext[0] - x0 < a->chunks[ax[0]] ? ext[0] - x0 : a->chunks[ax[0]];
                const uint64_t ny = ext[1] - y0 < a->chunks[ax[1]] ? ext[1] - y0 : a->chunks[ax[1]];
                const uint64_t nz = ext[2] - z0 < a->chunks[ax[2]] ? ext[2] - z0 : a->chunks[ax[2]];
                for (uint64_t z = 0; z < nz; z++)
                    for (uint64_t y = 0; y < ny; y++)
                        for (uint64_t x = 0; x < nx; x++) {
                            double v = raw_at(chunk + (base + z * stride[ax[2]] + y * stride[ax[1]] +
                                                       x * stride[ax[0]]) * elem, a->dtype);
                            if (isfinite(v)) {
                                if (v < *mn) *mn = v;
                                if (v > *mx) *mx = v;
                            }
                        }
            }
    free(chunk);
    if (!rc && !(*mn <= *mx)) *mn = *mx = 0.0; /* nothing finite */
    return rc;
}

/* ----------------------------------------------------------------- open */

/* The decoded-chunk cache: CACHE_MAX_BYTES, or a sixteenth of a small
 * budget, but room for 4 chunks of level 0 whatever (at most 256 MiB). */
static uint64_t cache_capacity(const vxl_zarr_array *a, const vxl_load_options *opt)
{
    const uint64_t budget = vxl_load_budget(opt);
    const uint64_t chunk = vxl_zarr_chunk_bytes(a), four = 4 * chunk < (256ull << 20) ? 4 * chunk : (256ull << 20);
    const uint64_t cap = budget / 16 < CACHE_MAX_BYTES ? budget / 16 : CACHE_MAX_BYTES;
    return cap > four ? cap : four;
}

/* The value range texels normalise over (32-bit types), and the data
 * range the volume reports. */
static int value_range(vxl_brick_source *s, vxl_zarr_source_info *info, vxl_err *e)
{
    zarr_ctx *c = s->ctx;
    const vxl_zarr_store *st = c->store;
    const uint64_t ch = c->sel[VXL_ZARR_C];
    if (s->texture_bits < 32) {
        const double tlo = c->dtype == VXL_DTYPE_I8 ? -128 : c->dtype == VXL_DTYPE_I16 ? -32768 : 0;
        const double span = s->texture_bits == 8 ? 255 : 65535;
        info->tex_lo = tlo;
        info->tex_hi = tlo + span;
        return VXL_OK;
    }
    double mn = 0, mx = 0;
    if (ch < VXL_ZARR_MAX_WINDOWS && st->window_set[ch]) {
        mn = st->window[ch][0];
        mx = st->window[ch][1];
    } else {
        int rc = level_range(s, s->n_levels - 1, &mn, &mx, e);
        if (rc) return rc;
    }
    c->lo = mn;
    c->inv = mx > mn ? 1.0 / (mx - mn) : 0.0;
    info->tex_lo = info->value_min = mn;
    info->tex_hi = mx > mn ? mx : mn + 1.0;
    info->value_max = mx;
    return VXL_OK;
}

/* 8/16-bit data: the exact range from the index (its floats are codes /
 * (2^bits - 1), which round back to the codes). */
static void range_from_index(const vxl_brick_source *s, vxl_zarr_source_info *info)
{
    const size_t n = (size_t)s->index_dims[0] * s->index_dims[1] * s->index_dims[2];
    float lo = 1e30f, hi = -1e30f;
    for (size_t i = 0; i < n; i++) {
        lo = s->minmax[2 * i] < lo ? s->minmax[2 * i] : lo;
        hi = s->minmax[2 * i + 1] > hi ? s->minmax[2 * i + 1] : hi;
    }
    const double span = info->tex_hi - info->tex_lo;
    info->value_min = info->tex_lo + nearbyint(lo * span);
    info->value_max = info->tex_lo + nearbyint(hi * span);
}

/* The level's x, y, z extents (too_large: one is past 2^32 - 1). */
static void chosen_level_dims(const vxl_zarr_store *s, int l, uint32_t dims[3], int *too_large)
{
    const vxl_zarr_array *a = &s->level[l];
    const uint64_t v[3] = {a->shape[s->axis[VXL_ZARR_X]], a->shape[s->axis[VXL_ZARR_Y]],
                           a->shape[s->axis[VXL_ZARR_Z]]};
    *too_large = 0;
    for (int k = 0; k < 3; k++) {
        *too_large |= v[k] > UINT32_MAX;
        dims[k] = v[k] > UINT32_MAX ? UINT32_MAX : (uint32_t)v[k];
    }
}

static void fill_geometry(const vxl_zarr_store *st, int l, uint64_t nt, uint64_t t, vxl_zarr_source_info *info)
{
    const int ix = st->axis[VXL_ZARR_X], iy = st->axis[VXL_ZARR_Y], iz = st->axis[VXL_ZARR_Z];
    const double sp[3] = {st->scale[l][ix], st->scale[l][iy], st->scale[l][iz]};
    const double dir[3][3] = {{sp[0], 0, 0}, {0, sp[1], 0}, {0, 0, sp[2]}};
    const double org[3] = {st->translation[l][ix], st->translation[l][iy], st->translation[l][iz]};
    memcpy(info->spacing, sp, sizeof sp);
    vxl_affine_from(dir, org, info->affine);
    info->frame_count = (uint32_t)(nt > UINT32_MAX ? UINT32_MAX : nt);
    info->frame = (uint32_t)t;
}

int vxl_zarr_open_source(const char *path, const vxl_load_options *opt, vxl_brick_source **out,
                         vxl_zarr_source_info *info, vxl_err *e)
{
    *out = NULL;
    memset(info, 0, sizeof *info);
    char folder[4096];
    vxl_zarr_choice ch;
    int rc = vxl_zarr_parse_path(path, folder, sizeof folder, &ch, e);
    if (rc) return rc;
    vxl_brick_source *s = calloc(1, sizeof *s);
    zarr_ctx *c = calloc(1, sizeof *c);
    vxl_zarr_store *st = calloc(1, sizeof *st);
    vxl_zarr_codecs *codecs = vxl_zarr_codecs_new();
    if (!s || !c || !st || !codecs || vxl_mutex_init(&c->lock)) {
        free(s);
        free(c);
        free(st);
        vxl_zarr_codecs_free(codecs);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for a brick source", path);
    }
    s->ops = &zarr_ops;
    s->ctx = c;
    c->store = st;
    c->codecs = codecs;
    if ((rc = vxl_zarr_open(folder, st, e))) goto fail;
    const int base = ch.level >= 0 ? ch.level : 0;
    uint64_t nt = 1;
    if ((rc = vxl_zarr_select(path, st, base, opt, &ch, c->sel, &nt, e))) goto fail;
    const vxl_zarr_array *a = &st->level[base];
    uint32_t dims[3];
    int too_large;
    chosen_level_dims(st, base, dims, &too_large);
    const uint32_t max_dim = opt && opt->max_dim ? opt->max_dim : VXL_DEFAULT_MAX_DIM;
    if (too_large || dims[0] > max_dim || dims[1] > max_dim || dims[2] > max_dim) {
        rc = vxl_fail(e, VXL_ERR_LIMIT, "'%s' (level %d): dimensions %llux%llux%llu exceed the per-axis limit of %u",
                      path, base, (unsigned long long)a->shape[st->axis[VXL_ZARR_X]],
                      (unsigned long long)a->shape[st->axis[VXL_ZARR_Y]],
                      (unsigned long long)a->shape[st->axis[VXL_ZARR_Z]], max_dim);
        goto fail;
    }
    const uint64_t budget = vxl_load_budget(opt);
    if (vxl_zarr_chunk_bytes(a) > budget / 4) { /* a reader holds a chunk or two next to the budget's bricks */
        rc = vxl_fail(e, VXL_ERR_LIMIT, "'%s': one chunk needs %.1f MiB, over a quarter of the memory budget of "
                      "%.1f MiB", a->path, vxl_zarr_chunk_bytes(a) / 1048576.0, budget / 1048576.0);
        goto fail;
    }
    c->dtype = a->dtype;
    s->texture_bits = vxl_texture_bits_for(a->dtype);
    vxl_brick_source_set_levels(s, dims, pick_levels(c, base));
    c->cache_cap = cache_capacity(a, opt);
    s->resident_bytes = sizeof *s + sizeof *c + sizeof *st;
    info->dtype = a->dtype;
    fill_geometry(st, base, nt, c->sel[VXL_ZARR_T], info);
    if ((rc = value_range(s, info, e))) goto fail;
    if ((rc = build_index(s, opt, e))) goto fail;
    if (s->texture_bits < 32) range_from_index(s, info);
    *out = s;
    return VXL_OK;
fail:
    vxl_brick_source_free(s);
    return rc;
}

/* ------------------------------------------------------------- dispatch */

/* ON, or AUTO and the level the whole read would start from (the one asked
 * for, else level 0) is over half the budget in texture bytes; never a
 * store read as channels (multi-channel volumes are read whole: its notes
 * say so under ON, and over the budget its error does). */
static int wants_streaming(const char *path, const vxl_load_options *opt)
{
    const uint32_t mode = vxl_load_streaming(opt);
    if (mode == VXL_STREAMING_OFF) return 0;
    char folder[4096];
    vxl_zarr_choice ch;
    vxl_err ignore = {0};
    vxl_zarr_store *st = calloc(1, sizeof *st);
    int stream = mode == VXL_STREAMING_ON; /* a store that does not open: the chosen path reports it */
    uint32_t channels = 0;
    const int opened =
        st && !vxl_zarr_parse_path(path, folder, sizeof folder, &ch, &ignore) && !vxl_zarr_open(folder, st, &ignore);
    if (opened && (vxl_zarr_channels(path, st, &ch, opt, &channels, &ignore) || channels))
        stream = 0;
    else if (opened && mode == VXL_STREAMING_AUTO) {
        const int l = ch.level >= 0 && ch.level < st->nlevels ? ch.level : 0;
        const vxl_zarr_array *a = &st->level[l];
        const double bytes = (double)a->shape[st->axis[VXL_ZARR_X]] * (double)a->shape[st->axis[VXL_ZARR_Y]] *
                             (double)a->shape[st->axis[VXL_ZARR_Z]] * (vxl_texture_bits_for(a->dtype) / 8);
        const uint64_t budget = vxl_load_budget(opt);
        stream = bytes > budget / 2.0;
    }
    free(st); /* a store that does not open is the whole read's to report */
    return stream;
}

int vxl_zarr_load_any(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    *out = NULL;
    if (!wants_streaming(path, opt)) {
        int rc = vxl_zarr_load(path, opt, out, e);
        if (!rc && (*out)->channels && vxl_load_streaming(opt) == VXL_STREAMING_ON)
            vxl_volume_note(*out, "read whole: a multi-channel volume does not stream");
        return rc;
    }
    vxl_brick_source *s = NULL;
    vxl_zarr_source_info info;
    int rc = vxl_zarr_open_source(path, opt, &s, &info, e);
    if (rc) return rc;
    vxl_volume *v = calloc(1, sizeof *v);
    if (!v) {
        vxl_brick_source_free(s);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for a volume header", path);
    }
    memcpy(v->dims, s->level_dims[0], sizeof v->dims);
    v->src_dtype = info.dtype;
    v->texture_bits = s->texture_bits;
    v->affine_source = 2; /* a full affine from the file, as a whole read */
    v->storage_bytes = (uint64_t)v->dims[0] * v->dims[1] * v->dims[2] * (s->texture_bits / 8);
    v->tex_lo = info.tex_lo;
    v->tex_hi = info.tex_hi;
    v->value_min = info.value_min;
    v->value_max = info.value_max;
    memcpy(v->spacing, info.spacing, sizeof v->spacing);
    memcpy(v->affine, info.affine, sizeof v->affine);
    v->frame_count = info.frame_count;
    v->frame = info.frame;
    v->source = s;
    *out = v;
    return VXL_OK;
}
