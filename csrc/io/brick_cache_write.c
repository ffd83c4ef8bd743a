/* brick_cache_write.c - streams a gzip- or zlib-compressed source once
 * into a bricked cache (brick_cache.h, format in brick_cache_format.h).
 *
 * Memory stays bounded by a slab of `brick` + 2 slices per level (the core
 * and the slices either side that the bricks' one-voxel apron takes; the
 * slab of level k+1 is a quarter of level k's), one slice of raw values and
 * the index, never the volume: slices are converted to texels exactly as
 * vxl_volume_build converts a whole volume, a full core is cut into bricks
 * and written once the slice after it is in, then averaged 2x2x2 into the
 * next level's slab exactly as vxl_volume_downsample2 averages a whole
 * level.
 *
 * 32-bit and 64-bit types are normalised by the volume's finite range, which
 * is only known at the end: for them a first pass inflates the file for the
 * range alone, and the second writes. The cache then holds final texels, so
 * reading it is decompression only, and its pyramid and index are those of
 * the normalised volume, bit for bit. 8- and 16-bit types need no range and
 * take one pass.
 *
 * The file is written under a temporary name in the cache's folder, synced
 * and renamed into place; a failure or a cancel unlinks it. */
#define _FILE_OFFSET_BITS 64
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "crc32.h"
#include "files.h"
#include "zlib_api.h"

#include "brick_cache.h"
#include "brick_cache_format.h"
#include "brick_levels.h"


/* A level's slab: its `brick` core slices z0 .. z0 + brick - 1 in slots
 * 1 .. brick, the slice before them (the bricks' lower apron) in slot 0 and
 * the one after (their upper apron) in slot brick + 1. */
typedef struct slab {
    uint8_t *buf;        /* brick + 2 slices of the level */
    uint32_t z0, filled; /* first core slice, slices held from z0 on */
} slab;

#define SLAB_SLOTS(B) ((B) + 2 * VXL_CACHE_APRON)

typedef struct writer {
    const vxl_raw_layout *l;
    const vxl_load_options *opt;
    vxl_err *e;
    const vxl_zlib *zl;
    vxl_cache_grid g;
    vxl_cache_header h;
    uint32_t tb;          /* texel bytes */
    slab lv[VXL_SOURCE_MAX_LEVELS];
    vxl_cache_entry *table;
    uint8_t *brick_buf, *zbuf;
    uLong zcap;
    FILE *f;
    uint64_t pos;
    /* raw slice and its values */
    uint8_t *raw;
    double *row;
    vxl_index_build index; /* built slice by slice (brick_source.h) */
    double inv;           /* 32-bit texels: 1 / span of the range */
    /* progress */
    double frac0, fracw;
    const char *stage;
} writer;

static int fail_io(writer *w, const char *what)
{
    return vxl_fail(w->e, VXL_ERR_IO, "writing the brick cache of %s: %s: %s", w->l->path, what, strerror(errno));
}

static int report(writer *w, double done)
{
    return vxl_source_progress(w->opt, w->frac0 + w->fracw * done, w->stage, w->e);
}

/* ---------------------------------------------------------- the source */

/* The compressed stream from the layout's compressed_start: zlib's
 * inflateInit2(15 + 32) takes a gzip or a zlib header, so a .nii.gz, a
 * gzip NRRD data file or the gzip data after a NRRD header, and zlib
 * MetaImage data after its header all read the same way; a gzip member
 * that ends with more input after it is followed by the next (concatenated
 * members, as gzip and gzread allow). */
#define IN_CHUNK (1u << 18)

typedef struct zsrc {
    const vxl_zlib *zl;
    FILE *f;
    z_stream z;
    int started, ended; /* ended: the last inflate ended a member */
    uint8_t *in;
} zsrc;

static void close_source(zsrc *s)
{
    if (s->started) s->zl->inflateEnd(&s->z);
    if (s->f) fclose(s->f);
    free(s->in);
    memset(s, 0, sizeof *s);
}

#define BEFORE_VOXELS UINT32_MAX /* inflate_bytes' z_slice while skipping to the chosen frame */

/* Inflates the next n bytes of slice z_slice into dst (NULL: skip them). */
static int inflate_bytes(writer *w, zsrc *s, uint8_t *dst, uint64_t n, uint32_t z_slice)
{
    uint8_t skip[4096];
    while (n) {
        if (!s->z.avail_in) {
            const size_t r = fread(s->in, 1, IN_CHUNK, s->f);
            if (!r) {
                if (ferror(s->f)) return vxl_fail(w->e, VXL_ERR_IO, "read error in %s: %s", w->l->path, strerror(errno));
                if (z_slice == BEFORE_VOXELS)
                    return vxl_fail(w->e, VXL_ERR_FORMAT, "%s ends before its voxels (offset %llu)", w->l->path,
                                    (unsigned long long)w->l->offset);
                return vxl_fail(w->e, VXL_ERR_FORMAT, "%s ends at slice %u of %u: the file is shorter than its header says",
                                w->l->path, z_slice, w->l->dims[2]);
            }
            s->z.next_in = s->in;
            s->z.avail_in = (uInt)r;
        }
        if (s->ended) { /* another member follows */
            if (s->zl->inflateReset(&s->z) != Z_OK) return vxl_fail(w->e, VXL_ERR_NO_MEMORY, "%s: zlib reset failed", w->l->path);
            s->ended = 0;
        }
        const uint64_t cap = dst ? (1u << 30) : sizeof skip; /* inflate counts in uInt */
        const uInt room = (uInt)(n < cap ? n : cap);
        s->z.next_out = dst ? dst : skip;
        s->z.avail_out = room;
        const int zr = s->zl->inflate(&s->z, Z_NO_FLUSH);
        const uInt got = room - s->z.avail_out;
        if (dst) dst += got;
        n -= got;
        if (zr == Z_STREAM_END) s->ended = 1;
        else if (zr == Z_BUF_ERROR && !s->z.avail_in) continue; /* needs more input */
        else if (zr != Z_OK)
            return vxl_fail(w->e, VXL_ERR_FORMAT, "%s: the compressed stream is damaged at slice %u: %s", w->l->path,
                            z_slice == BEFORE_VOXELS ? 0 : z_slice, s->z.msg ? s->z.msg : "zlib error");
    }
    return VXL_OK;
}

/* Opens the stream at compressed_start and inflates up to the chosen
 * frame's first voxel (offset in the inflated bytes). */
static int open_source(writer *w, zsrc *s)
{
    memset(s, 0, sizeof *s);
    s->zl = w->zl;
    s->f = vxl_fopen(w->l->path, "rb");
    if (!s->f) return vxl_fail(w->e, VXL_ERR_IO, "cannot open %s: %s", w->l->path, strerror(errno));
    if (!(s->in = malloc(IN_CHUNK))) {
        close_source(s);
        return vxl_fail(w->e, VXL_ERR_NO_MEMORY, "out of memory reading %s", w->l->path);
    }
    if (vxl_fseek(s->f, w->l->compressed_start) != 0) {
        close_source(s);
        return vxl_fail(w->e, VXL_ERR_FORMAT, "%s: no compressed data at byte %llu", w->l->path,
                        (unsigned long long)w->l->compressed_start);
    }
    if (VXL_INFLATE_INIT2(s->zl, &s->z, 15 + 32) != Z_OK) { /* zlib or gzip, auto-detected */
        close_source(s);
        return vxl_fail(w->e, VXL_ERR_NO_MEMORY, "%s: cannot start zlib", w->l->path);
    }
    s->started = 1;
    int rc = inflate_bytes(w, s, NULL, w->l->offset, BEFORE_VOXELS);
    if (rc) close_source(s);
    return rc;
}

static int read_slice(writer *w, zsrc *src, uint32_t z, size_t bytes)
{
    int rc = inflate_bytes(w, src, w->raw, bytes, z);
    if (rc) return rc;
    if (w->l->swap) {
        const uint32_t n = vxl_dtype_size(w->l->dtype);
        for (size_t i = 0; i < bytes; i += n)
            for (uint32_t a = 0; a < n / 2; a++) {
                uint8_t t = w->raw[i + a];
                w->raw[i + a] = w->raw[i + n - 1 - a];
                w->raw[i + n - 1 - a] = t;
            }
    }
    return VXL_OK;
}

/* Raw values of row y of the slice, as doubles (vxl_volume_build's raw_value). */
static void row_values(const writer *w, uint32_t y, double *out)
{
    const uint32_t nx = w->l->dims[0];
    const size_t i0 = (size_t)y * nx;
    switch (w->l->dtype) {
#define ROW(T) for (uint32_t x = 0; x < nx; x++) { T v; memcpy(&v, w->raw + (i0 + x) * sizeof(T), sizeof v); out[x] = v; } break
    case VXL_DTYPE_U8: ROW(uint8_t);
    case VXL_DTYPE_I8: ROW(int8_t);
    case VXL_DTYPE_U16: ROW(uint16_t);
    case VXL_DTYPE_I16: ROW(int16_t);
    case VXL_DTYPE_U32: ROW(uint32_t);
    case VXL_DTYPE_I32: ROW(int32_t);
    case VXL_DTYPE_F32: ROW(float);
    default: ROW(double);
#undef ROW
    }
}

/* The finite range and the NaN/Inf counts of one slice, into the header. */
static void slice_range(writer *w)
{
    const double slope = w->h.slope, inter = w->h.inter;
    for (uint32_t y = 0; y < w->l->dims[1]; y++) {
        row_values(w, y, w->row);
        for (uint32_t x = 0; x < w->l->dims[0]; x++) {
            double v = w->row[x] * slope + inter;
            if (isnan(v)) w->h.nan_count++;
            else if (isinf(v)) w->h.inf_count++;
            else {
                if (v < w->h.value_min) w->h.value_min = v;
                if (v > w->h.value_max) w->h.value_max = v;
            }
        }
    }
}

/* 8- and 16-bit types: the texel is the code raw - type minimum (exact, as
 * vxl_volume_build stores it), a copy or a flip of the sign bit, done in
 * typed loops since this runs over every voxel. The slice's value range
 * comes from its lowest and highest code: raw * slope + inter is monotone
 * in raw (rounding included), so they give the same range and NaN/Inf
 * counts as a pass over every voxel, unless an end overflows, where that
 * pass is taken. */
static void int_slice_texels(writer *w, uint8_t *dst)
{
    const size_t n = (size_t)w->l->dims[0] * w->l->dims[1];
    const uint32_t dt = w->l->dtype;
    uint32_t lo = UINT32_MAX, hi = 0;
    if (w->tb == 1) {
        const uint8_t flip = dt == VXL_DTYPE_I8 ? 0x80 : 0;
        uint8_t a = 0xff, b = 0;
        for (size_t i = 0; i < n; i++) {
            const uint8_t t = w->raw[i] ^ flip;
            dst[i] = t;
            a = t < a ? t : a;
            b = t > b ? t : b;
        }
        lo = a, hi = b;
    } else {
        const uint16_t flip = dt == VXL_DTYPE_I16 ? 0x8000 : 0;
        const uint16_t *r = (const uint16_t *)w->raw;
        uint16_t *d = (uint16_t *)dst, a = 0xffff, b = 0;
        for (size_t i = 0; i < n; i++) {
            const uint16_t t = r[i] ^ flip;
            d[i] = t;
            a = t < a ? t : a;
            b = t > b ? t : b;
        }
        lo = a, hi = b;
    }
    const double t0 = dt == VXL_DTYPE_I8 ? -128 : dt == VXL_DTYPE_I16 ? -32768 : 0;
    const double va = (lo + t0) * w->h.slope + w->h.inter, vb = (hi + t0) * w->h.slope + w->h.inter;
    if (!isfinite(va) || !isfinite(vb)) {
        slice_range(w);
        return;
    }
    const double mn = va < vb ? va : vb, mx = va < vb ? vb : va;
    if (mn < w->h.value_min) w->h.value_min = mn;
    if (mx > w->h.value_max) w->h.value_max = mx;
}

/* Slice z of level L in its slab (z0 - 1 .. z0 + brick). */
static uint8_t *slab_slice(const writer *w, uint32_t L, uint32_t z)
{
    const size_t plane = (size_t)w->g.dims[L][0] * w->g.dims[L][1] * w->tb;
    return w->lv[L].buf + (size_t)(z + VXL_CACHE_APRON - w->lv[L].z0) * plane;
}

/* Texels of slice z (raw values already read) into level 0's slab; for
 * 8/16-bit types the range too. */
static void slice_texels(writer *w, uint32_t z)
{
    const uint32_t nx = w->l->dims[0], ny = w->l->dims[1];
    uint8_t *dst = slab_slice(w, 0, z);
    if (w->tb < 4) {
        int_slice_texels(w, dst);
        return;
    }
    const double lo = w->h.value_min, hi = w->h.value_max;
    float *d = (float *)dst;
    for (uint32_t y = 0; y < ny; y++) {
        row_values(w, y, w->row);
        const size_t i0 = (size_t)y * nx;
        for (uint32_t x = 0; x < nx; x++) {
            double v = w->row[x] * w->h.slope + w->h.inter;
            if (isnan(v)) v = lo;
            else if (v > hi) v = hi;
            else if (v < lo) v = lo;
            double s = (v - lo) * w->inv;
            d[i0 + x] = (float)(s < 0 ? 0 : s > 1 ? 1 : s);
        }
    }
}

/* ---------------------------------------------------------- the bricks */

static int write_bytes(writer *w, const void *p, size_t n)
{
    if (n && fwrite(p, 1, n, w->f) != n) return fail_io(w, "write");
    w->pos += n;
    return VXL_OK;
}

/* Stores brick_buf (n texels) as brick `id`: one value when constant, zlib
 * when that shrinks it, else raw. */
static int store_brick(writer *w, uint64_t id, size_t n)
{
    const size_t bytes = n * w->tb;
    vxl_cache_entry *en = &w->table[id];
    const uint8_t *data = w->brick_buf;
    /* every texel equals the one before it: one value */
    if (memcmp(w->brick_buf, w->brick_buf + w->tb, bytes - w->tb) == 0) {
        en->kind = VXL_CACHE_CONSTANT;
        en->size = w->tb;
    } else {
        uLongf zlen = w->zcap;
        if (w->zl->compress2(w->zbuf, &zlen, w->brick_buf, (uLong)bytes, Z_BEST_SPEED) == Z_OK && zlen < bytes) {
            en->kind = VXL_CACHE_ZLIB;
            en->size = (uint32_t)zlen;
            data = w->zbuf;
        } else {
            en->kind = VXL_CACHE_RAW;
            en->size = (uint32_t)bytes;
        }
    }
    en->offset = w->pos;
    en->crc = vxl_crc32(0, data, en->size);
    return write_bytes(w, data, en->size);
}

static int push_slice(writer *w, uint32_t level);


/* Averages level L's slice pair (2z, 2z+1, the last repeated at an odd
 * end) of its slab into the next level's slab, as vxl_volume_downsample2
 * averages a whole level (brick_levels.h). */
static void downsample_slice(writer *w, uint32_t L, uint32_t z)
{
    const uint32_t *d = w->g.dims[L];
    vxl_downsample2_slice(w->tb * 8, slab_slice(w, L, 2 * z), slab_slice(w, L, 2 * z + 1 < d[2] ? 2 * z + 1 : d[2] - 1),
                          d[0], d[1], slab_slice(w, L + 1, z));
}

/* Level L's core slices z0 .. z0 + core - 1 are in, with the slices
 * around them that the level has: cut them into bricks with their apron
 * (vxl_cache_brick_box's boxes), write them, average the core into level
 * L+1. */
static int flush_slab(writer *w, uint32_t L, uint32_t core)
{
    slab *sl = &w->lv[L];
    const uint32_t *d = w->g.dims[L], *nb = w->g.bricks[L], B = w->g.brick;
    const uint32_t bz = sl->z0 / B;
    for (uint32_t by = 0; by < nb[1]; by++)
        for (uint32_t bx = 0; bx < nb[0]; bx++) {
            const uint64_t id = bx + (uint64_t)nb[0] * (by + (uint64_t)nb[1] * bz);
            uint32_t lo[3], sz[3];
            vxl_cache_brick_box(&w->g, L, id, lo, sz);
            uint8_t *p = w->brick_buf;
            const size_t row = (size_t)sz[0] * w->tb;
            for (uint32_t z = 0; z < sz[2]; z++) {
                const uint8_t *slice = slab_slice(w, L, lo[2] + z);
                for (uint32_t y = 0; y < sz[1]; y++) {
                    memcpy(p, slice + ((size_t)(lo[1] + y) * d[0] + lo[0]) * w->tb, row);
                    p += row;
                }
            }
            int rc = store_brick(w, w->g.first[L] + id, (size_t)sz[0] * sz[1] * sz[2]);
            if (rc) return rc;
        }
    if (L + 1 < w->g.n_levels) {
        for (uint32_t z = sl->z0 / 2; z <= (sl->z0 + core - 1) / 2; z++) {
            downsample_slice(w, L, z);
            int rc = push_slice(w, L + 1);
            if (rc) return rc;
        }
    }
    return VXL_OK;
}

/* A slice was written after the last one held in level L's slab. Once the
 * slice after a full core is in (the core's upper apron), the core is
 * written and the slab moves on by `brick`, keeping its last core slice and
 * that slice as the next core's lower apron and first slice; at the
 * level's end what is left is written. */
static int push_slice(writer *w, uint32_t L)
{
    slab *sl = &w->lv[L];
    const uint32_t B = w->g.brick, nz = w->g.dims[L][2];
    const size_t plane = (size_t)w->g.dims[L][0] * w->g.dims[L][1] * w->tb;
    sl->filled++;
    if (sl->filled == B + VXL_CACHE_APRON) {
        int rc = flush_slab(w, L, B);
        if (rc) return rc;
        /* slices z0 + B - APRON .. z0 + B + APRON - 1 (slots B ..) to the slab's start */
        memmove(sl->buf, sl->buf + (size_t)B * plane, 2 * VXL_CACHE_APRON * plane);
        sl->z0 += B;
        sl->filled = VXL_CACHE_APRON;
    }
    if (sl->z0 + sl->filled == nz) {
        int rc = flush_slab(w, L, sl->filled);
        sl->filled = 0;
        sl->z0 = nz;
        return rc;
    }
    return VXL_OK;
}

/* ------------------------------------------------------------ the passes */

static int range_pass(writer *w, size_t slice_bytes)
{
    zsrc src;
    w->stage = "reading the value range"; /* before open_source, which reports too */
    int rc = open_source(w, &src);
    for (uint32_t z = 0; !rc && z < w->l->dims[2]; z++) {
        rc = read_slice(w, &src, z, slice_bytes);
        if (!rc) slice_range(w);
        if (!rc) rc = report(w, (z + 1.0) / w->l->dims[2]);
    }
    close_source(&src);
    return rc;
}

static int write_pass(writer *w, size_t slice_bytes)
{
    zsrc src;
    w->stage = "writing the brick cache";
    int rc = open_source(w, &src);
    for (uint32_t z = 0; !rc && z < w->l->dims[2]; z++) {
        rc = read_slice(w, &src, z, slice_bytes);
        if (rc) break;
        slice_texels(w, z);
        vxl_index_build_slice(&w->index, z, slab_slice(w, 0, z));
        rc = push_slice(w, 0);
        if (!rc) rc = report(w, (z + 1.0) / w->l->dims[2]);
    }
    close_source(&src);
    return rc;
}

/* Index, table and header after the bricks, then sync. */
static int finish(writer *w)
{
    vxl_cache_header *h = &w->h;
    h->index_offset = w->pos;
    h->index_bytes = w->g.index_count * 8;
    h->index_crc = vxl_crc32(0, w->index.minmax, (size_t)h->index_bytes);
    int rc = write_bytes(w, w->index.minmax, h->index_bytes);
    h->table_offset = w->pos;
    h->table_bytes = h->brick_count * VXL_CACHE_ENTRY_BYTES;
    uint32_t crc = 0;
    for (uint64_t i = 0; !rc && i < h->brick_count; i++) {
        uint8_t en[VXL_CACHE_ENTRY_BYTES];
        vxl_cache_entry_encode(&w->table[i], en);
        crc = vxl_crc32(crc, en, VXL_CACHE_ENTRY_BYTES);
        rc = write_bytes(w, en, VXL_CACHE_ENTRY_BYTES);
    }
    if (rc) return rc;
    h->table_crc = crc;
    uint8_t head[VXL_CACHE_HEADER_BYTES];
    vxl_cache_header_encode(h, head);
    if (fflush(w->f) != 0 || vxl_fseek(w->f, 0) != 0) return fail_io(w, "seek");
    if (fwrite(head, 1, sizeof head, w->f) != sizeof head || fflush(w->f) != 0) return fail_io(w, "write");
    if (vxl_fsync(w->f) != 0) return fail_io(w, "fsync");
    return VXL_OK;
}

/* ---------------------------------------------------------- the layout */

/* Brick edge and level count for this volume under the tuning. */
static int plan(writer *w, const vxl_brick_cache_tuning *t)
{
    const vxl_raw_layout *l = w->l;
    const uint32_t bits = vxl_texture_bits_for(l->dtype);
    w->tb = bits / 8;
    const uint64_t plane = (uint64_t)l->dims[0] * l->dims[1] * w->tb;
    uint32_t B = t->brick;
    while (B > 8 && B * plane > t->slab_bytes) B /= 2;
    if (B * plane > 4 * t->slab_bytes)
        return vxl_fail(w->e, VXL_ERR_LIMIT,
                        "%s: slices of %ux%u voxels are too large to stream into a brick cache (%llu MiB per %u slices)",
                        l->path, l->dims[0], l->dims[1], (unsigned long long)(B * plane >> 20), B);
    uint32_t levels = t->coarsest_bytes ? 1 : vxl_source_level_count(l->dims);
    while (t->coarsest_bytes) {
        uint64_t n = w->tb;
        for (int a = 0; a < 3; a++) n *= ((uint64_t)l->dims[a] + (1ull << (levels - 1)) - 1) >> (levels - 1);
        if (n <= t->coarsest_bytes || levels == VXL_SOURCE_MAX_LEVELS) break;
        levels++;
    }
    const uint32_t index_brick = vxl_source_index_brick(l->dims);
    if (vxl_cache_grid_make(l->dims, bits, B, levels, index_brick, &w->g) != 0)
        return vxl_fail(w->e, VXL_ERR_LIMIT, "%s: %ux%ux%u voxels need too many bricks for a brick cache", l->path,
                        l->dims[0], l->dims[1], l->dims[2]);
    vxl_cache_header *h = &w->h;
    h->src_size = l->file_size;
    h->src_mtime_ns = l->mtime_ns;
    h->src_header_hash = l->header_hash;
    h->src_offset = l->offset;
    h->src_compressed_start = l->compressed_start;
    h->src_dtype = l->dtype;
    h->src_swap = l->swap != 0;
    h->src_frame = l->frame;
    memcpy(h->dims, l->dims, sizeof h->dims);
    h->slope = l->slope;
    h->inter = l->inter;
    h->texture_bits = bits;
    h->brick = B;
    h->n_levels = levels;
    h->index_brick = index_brick;
    h->brick_count = w->g.first[levels];
    h->value_min = INFINITY;
    h->value_max = -INFINITY;
    return VXL_OK;
}

static int allocate(writer *w)
{
    const uint32_t B = w->g.brick, E = B + 2 * VXL_CACHE_APRON; /* a stored brick's edge at most */
    const size_t brick_bytes = (size_t)E * E * E * w->tb;
    int ok = 1;
    for (uint32_t L = 0; L < w->g.n_levels; L++)
        ok &= (w->lv[L].buf = malloc((size_t)SLAB_SLOTS(B) * w->g.dims[L][0] * w->g.dims[L][1] * w->tb)) != NULL;
    w->table = calloc((size_t)w->g.first[w->g.n_levels], sizeof *w->table);
    w->brick_buf = malloc(brick_bytes);
    w->zcap = w->zl->compressBound((uLong)brick_bytes);
    w->zbuf = malloc(w->zcap);
    w->raw = malloc((size_t)w->l->dims[0] * w->l->dims[1] * vxl_dtype_size(w->l->dtype));
    w->row = malloc((size_t)w->l->dims[0] * sizeof *w->row);
    if (!ok || !w->table || !w->brick_buf || !w->zbuf || !w->raw || !w->row)
        return vxl_fail(w->e, VXL_ERR_NO_MEMORY, "out of memory for the brick cache writer of %s", w->l->path);
    return vxl_index_build_begin(&w->index, w->l->dims, w->tb * 8, w->h.index_brick, w->e);
}

static void release(writer *w)
{
    for (uint32_t L = 0; L < VXL_SOURCE_MAX_LEVELS; L++) free(w->lv[L].buf);
    free(w->table);
    free(w->brick_buf);
    free(w->zbuf);
    free(w->raw);
    free(w->row);
    vxl_index_build_free(&w->index);
}

/* The range the texels are normalised by, as vxl_volume_build sets it. */
static void settle_range(writer *w)
{
    vxl_cache_header *h = &w->h;
    if (!(h->value_min <= h->value_max)) h->value_min = h->value_max = 0.0;
    if (w->tb < 4) {
        const double t0 = (w->l->dtype == VXL_DTYPE_I8 ? -128 : w->l->dtype == VXL_DTYPE_I16 ? -32768 : 0);
        const double span = w->tb == 1 ? 255 : 65535;
        h->tex_lo = t0 * h->slope + h->inter;
        h->tex_hi = (t0 + span) * h->slope + h->inter;
    } else {
        const double span = h->value_max - h->value_min;
        h->tex_lo = h->value_min;
        h->tex_hi = span > 0 ? h->value_max : h->value_min + 1.0;
        w->inv = span > 0 ? 1.0 / span : 0.0;
    }
}

int vxl_brick_cache_write(const vxl_raw_layout *l, const vxl_load_options *opt, const vxl_brick_cache_tuning *t,
                          const char *cache_path, vxl_err *e)
{
    writer w;
    memset(&w, 0, sizeof w);
    w.l = l;
    w.opt = opt;
    w.e = e;
    if (!(w.zl = vxl_zlib_api(e))) return VXL_ERR_IO;
    int rc = plan(&w, t);
    if (!rc) rc = allocate(&w);
    if (rc) {
        release(&w);
        return rc;
    }
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp-XXXXXX", cache_path);
    w.f = vxl_temp_file(tmp);
    if (!w.f) {
        rc = vxl_fail(e, VXL_ERR_IO, "cannot create the brick cache %s: %s", tmp, strerror(errno));
        release(&w);
        return rc;
    }
    {
        setvbuf(w.f, NULL, _IOFBF, 1u << 20);
        static const uint8_t zero[VXL_CACHE_HEADER_BYTES];
        rc = write_bytes(&w, zero, sizeof zero); /* the header, written last */
        const size_t slice_bytes = (size_t)l->dims[0] * l->dims[1] * vxl_dtype_size(l->dtype);
        const int ranged = w.tb == 4;
        w.fracw = ranged ? 0.5 : 1.0;
        if (!rc) rc = report(&w, 0);
        if (!rc && ranged) rc = range_pass(&w, slice_bytes);
        if (!rc) settle_range(&w);
        w.frac0 = ranged ? 0.5 : 0.0;
        if (!rc) rc = write_pass(&w, slice_bytes);
        if (!rc && !ranged) settle_range(&w);
        if (!rc) rc = finish(&w);
        if (fclose(w.f) != 0 && !rc) rc = fail_io(&w, "close");
    }
    if (!rc && vxl_rename(tmp, cache_path) != 0) rc = vxl_fail(e, VXL_ERR_IO, "cannot rename %s to %s: %s", tmp, cache_path, strerror(errno));
    if (rc) vxl_remove(tmp); /* never a half cache */
    release(&w);
    return rc;
}
