/* raw_source.c - an uncompressed file read by offset (raw_source.h). */
#include "raw_source.h"
#include "files.h"

#include "brick_levels.h"
#include "loader_util.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PASS_SLAB_BYTES (16u << 20) /* raw bytes per slab of the opening pass (at least one slice) */

/* Coarse levels up to this many bytes are kept whole: VXL_SOURCE_KEEP_LEVEL_BYTES,
 * or VOXLIGHT_SOURCE_KEEP_BYTES (tests set 0 so every level is averaged
 * from level-0 reads, the path a large file's finer levels take). */
static uint64_t keep_level_bytes(void)
{
    const char *v = getenv("VOXLIGHT_SOURCE_KEEP_BYTES");
    char *end = NULL;
    unsigned long long n = v && *v ? strtoull(v, &end, 10) : 0;
    return v && *v && end && !*end ? (uint64_t)n : VXL_SOURCE_KEEP_LEVEL_BYTES;
}

typedef struct raw_ctx {
    int fd;
    vxl_raw_layout l;
    uint32_t es;                              /* bytes per raw voxel */
    vxl_texel_map map;
    uint64_t nan_count, inf_count;
    uint8_t *levels[VXL_SOURCE_MAX_LEVELS];   /* coarse levels kept whole (NULL: averaged from level 0) */
    uint64_t *slices;                         /* the layout's slice_offsets, copied (NULL: contiguous) */
} raw_ctx;

/* Where voxel (x, y, z) of level 0 is stored: the one place that knows how
 * slices (contiguous from the offset, or a table) and rows (bottom or top
 * first) lie in the file. */
static uint64_t voxel_at(const raw_ctx *c, uint32_t x, uint32_t y, uint32_t z)
{
    const uint32_t *d = c->l.dims;
    const uint64_t row = c->l.rows_top_first ? d[1] - 1 - y : y;
    const uint64_t slice = c->slices ? c->slices[z] : c->l.offset + (uint64_t)d[0] * d[1] * z * c->es;
    return slice + (row * d[0] + x) * c->es;
}

static void raw_close(vxl_brick_source *s)
{
    raw_ctx *c = s->ctx;
    if (!c) return;
    vxl_file_close(c->fd);
    free(c->slices);
    for (int k = 0; k < VXL_SOURCE_MAX_LEVELS; k++) free(c->levels[k]);
    free(c);
    s->ctx = NULL;
}

/* pread of exactly n bytes at off; a short read is a file cut short after it was opened. */
static int read_at(vxl_brick_source *s, void *buf, size_t n, uint64_t off, vxl_err *e)
{
    const raw_ctx *c = s->ctx;
    const int64_t got = vxl_pread_full(c->fd, buf, n, off);
    if (got < 0) return vxl_fail(e, VXL_ERR_IO, "read error in '%s': %s", c->l.path, strerror(errno));
    if ((uint64_t)got < n)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': file ends at %llu, before the voxels the header claims", c->l.path,
                        (unsigned long long)(off + (uint64_t)got));
    __atomic_fetch_add(&s->bytes_read, (uint64_t)n, __ATOMIC_RELAXED);
    return VXL_OK;
}

/* Raw bytes in file order -> texels (swapped first when the file's order is foreign). */
static void to_texels(const raw_ctx *c, void *raw, size_t n, void *out)
{
    if (c->l.swap) vxl_swap_elements(raw, n, c->es);
    vxl_texels_from_raw(&c->map, raw, n, out);
}

/* Level-0 box, read row by row (whole rows or slices in one pread where the
 * box spans them and they follow each other; rows stored top first are read
 * as one run too, converted in reverse). */
static int read_level0(vxl_brick_source *s, const uint32_t lo[3], const uint32_t size[3], void *out, vxl_err *e)
{
    const raw_ctx *c = s->ctx;
    const uint32_t *d = c->l.dims;
    const size_t es = c->es, bpv = s->texture_bits / 8;
    const int flip = c->l.rows_top_first;
    const int rows = size[0] == d[0], slices = rows && size[1] == d[1] && !flip && !c->slices;
    const size_t run = slices ? (size_t)size[0] * size[1] * size[2] : rows ? (size_t)size[0] * size[1] : size[0];
    uint8_t *raw = malloc(run * es);
    if (!raw) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory reading a box of '%s'", c->l.path);
    int rc = VXL_OK;
    uint8_t *o = out;
    for (uint32_t z = 0; z < size[2] && !rc; z++)
        for (uint32_t y = 0; y < size[1] && !rc; y++) {
            /* a run of flipped rows starts at the box's top row */
            const uint32_t y0 = rows && flip ? lo[1] + size[1] - 1 : lo[1] + y;
            rc = read_at(s, raw, run * es, voxel_at(c, lo[0], y0, lo[2] + z), e);
            if (rc) break;
            if (rows && flip)
                for (uint32_t r = 0; r < size[1]; r++) /* stored row r is the box's row size[1]-1-r */
                    to_texels(c, raw + (size_t)r * size[0] * es, size[0], o + (size_t)(size[1] - 1 - r) * size[0] * bpv);
            else
                to_texels(c, raw, run, o);
            o += run * bpv;
            if (slices) z = size[2];
            if (rows) y = size[1];
        }
    free(raw);
    return rc;
}

/* Level k (not kept): each output slice from the 2^k level-0 slices under it,
 * downsampled k times as the levels were built (brick_levels.h). */
static int read_averaged(vxl_brick_source *s, uint32_t k, const uint32_t lo[3], const uint32_t size[3], void *out,
                         vxl_err *e)
{
    const uint32_t *d = s->level_dims[0], f = 1u << k;
    const size_t bpv = s->texture_bits / 8;
    uint32_t lo0[3], size0[3];
    for (int a = 0; a < 2; a++) {
        lo0[a] = lo[a] * f;
        const uint64_t end = (uint64_t)(lo[a] + size[a]) * f;
        size0[a] = (uint32_t)((end < d[a] ? end : d[a]) - lo0[a]);
    }
    uint8_t *a = malloc((size_t)size0[0] * size0[1] * f * bpv), *b = malloc((size_t)size0[0] * size0[1] * f * bpv);
    if (!a || !b) {
        free(a);
        free(b);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory averaging level %u", k);
    }
    int rc = VXL_OK;
    const size_t out_slice = (size_t)size[0] * size[1] * bpv;
    for (uint32_t z = 0; z < size[2] && !rc; z++) {
        const uint64_t z0 = (uint64_t)(lo[2] + z) * f, end = z0 + f < d[2] ? z0 + f : d[2];
        uint32_t box[3] = {size0[0], size0[1], (uint32_t)(end - z0)};
        lo0[2] = (uint32_t)z0;
        rc = read_level0(s, lo0, box, a, e);
        for (uint32_t j = 0; j < k && !rc; j++) { /* a -> b, then swap */
            vxl_downsample2_box(s->texture_bits, a, box, b);
            for (int ax = 0; ax < 3; ax++) box[ax] = (box[ax] + 1) / 2;
            uint8_t *t = a;
            a = b;
            b = t;
        }
        if (!rc) memcpy((uint8_t *)out + out_slice * z, a, out_slice);
    }
    free(a);
    free(b);
    return rc;
}

static int raw_read(vxl_brick_source *s, uint32_t level, const uint32_t lo[3], const uint32_t size[3], void *out,
                    vxl_err *e)
{
    const raw_ctx *c = s->ctx;
    if (level >= s->n_levels)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': level %u of %u", c->l.path, level, s->n_levels);
    const uint32_t *d = s->level_dims[level];
    for (int a = 0; a < 3; a++)
        if (size[a] == 0 || lo[a] >= d[a] || size[a] > d[a] - lo[a])
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': box %u+%u on axis %d is outside level %u (%u voxels)",
                            c->l.path, lo[a], size[a], a, level, d[a]);
    if (level == 0) return read_level0(s, lo, size, out, e);
    if (c->levels[level]) {
        vxl_level_copy_box(s->texture_bits, c->levels[level], d, lo, size, out);
        return VXL_OK;
    }
    return read_averaged(s, level, lo, size, out, e);
}

static const vxl_brick_source_ops raw_ops = {raw_read, raw_close};

/* ------------------------------------------------------------- the pass */

/* One slab of the pass: slices z0 .. z0+n-1 in raw (file order, holes as
 * zeros), and which of them are holes throughout. */
typedef struct slab {
    uint8_t *raw;
    uint8_t *hole;          /* per slice: 1 = no data byte in it */
    uint8_t *row_data;      /* per row of each slice: 1 = it holds data bytes (0: a hole throughout) */
    uint32_t z0, n;
} slab;

/* Reads the data extents (SEEK_DATA / SEEK_HOLE; a file system without them
 * is all data) of the file bytes [start, start + len), which hold slab
 * slices first.. in file order, into raw; marks those slices and their
 * voxel rows that hold data. raw, hole and row_data are cleared by the caller. */
static int read_extent(vxl_brick_source *s, slab *sb, uint8_t *raw, uint64_t start, uint64_t len, uint32_t first,
                       vxl_err *e)
{
    const raw_ctx *c = s->ctx;
    const uint32_t h = c->l.dims[1];
    const uint64_t row = (uint64_t)c->l.dims[0] * c->es, end = start + len;
    uint64_t pos = start;
    while (pos < end) {
        uint64_t data, hole;
        const int k = vxl_file_data_extent(c->fd, pos, &data, &hole);
        if (k < 0) break; /* a hole to the end of the file */
        if (k == 0) {     /* the file system cannot tell: read it all */
            data = pos;
            hole = end;
        }
        if (data >= end) break;
        uint64_t stop = hole > end ? end : hole;
        if (stop <= data) stop = end;
        int rc = read_at(s, raw + (data - start), (size_t)(stop - data), data, e);
        if (rc) return rc;
        /* stored rows a .. b (counted from start) hold data */
        const uint64_t a = (data - start) / row, b = (stop - 1 - start) / row;
        for (uint64_t z = a / h; z <= b / h; z++) {
            uint64_t r0 = z == a / h ? a % h : 0, r1 = z == b / h ? b % h : h - 1;
            if (c->l.rows_top_first) { /* stored row r is voxel row h-1-r */
                const uint64_t t = r0;
                r0 = h - 1 - r1;
                r1 = h - 1 - t;
            }
            sb->hole[first + z] = 0;
            memset(sb->row_data + (first + z) * (uint64_t)h + r0, 1, (size_t)(r1 - r0 + 1));
        }
        pos = stop;
    }
    return VXL_OK;
}

/* Reads the slab's slices: one extent when slices follow each other, else
 * one per slice (slice_offsets), holes as zeros. */
static int read_slab(vxl_brick_source *s, slab *sb, vxl_err *e)
{
    const raw_ctx *c = s->ctx;
    const uint64_t slice = (uint64_t)c->l.dims[0] * c->l.dims[1] * c->es;
    memset(sb->raw, 0, (size_t)(slice * sb->n));
    memset(sb->hole, 1, sb->n);
    memset(sb->row_data, 0, (size_t)sb->n * c->l.dims[1]);
    if (!c->slices) return read_extent(s, sb, sb->raw, c->l.offset + slice * sb->z0, slice * sb->n, 0, e);
    for (uint32_t i = 0; i < sb->n; i++) {
        int rc = read_extent(s, sb, sb->raw + slice * i, c->slices[sb->z0 + i], slice, i, e);
        if (rc) return rc;
    }
    return VXL_OK;
}

/* The pass over slabs: stage 0 the range (floats only: their texels need it),
 * stage 1 texels into the index and the levels (with the range for integers). */
typedef struct pass {
    vxl_brick_source *s;
    const vxl_load_options *opt;
    slab sb;
    uint8_t *texels;        /* one slice */
    uint8_t *hole_row;      /* one row of the texel a hole stores */
    double mn, mx;
    int any_hole;
    vxl_index_build index;
    vxl_level_build levels;
    uint32_t stages, stage;
} pass;

static int run_stage(pass *p, int texels, vxl_err *e)
{
    raw_ctx *c = p->s->ctx;
    const uint32_t *d = c->l.dims;
    const uint64_t n_slice = (uint64_t)d[0] * d[1], slice = n_slice * c->es;
    const uint32_t per = (uint32_t)(PASS_SLAB_BYTES / slice > 0 ? PASS_SLAB_BYTES / slice : 1);
    double hole_value = 0;
    if (texels) { /* the texel a hole (raw zero) stores */
        uint8_t zero[8] = {0}, t[4];
        vxl_texels_from_raw(&c->map, zero, 1, t);
        hole_value = vxl_texel_at(p->s->texture_bits, t, 0);
        const size_t tb = p->s->texture_bits / 8;
        for (uint32_t x = 0; x < d[0]; x++) memcpy(p->hole_row + (size_t)x * tb, t, tb);
    }
    for (uint32_t z0 = 0; z0 < d[2]; z0 += per) {
        p->sb.z0 = z0;
        p->sb.n = per < d[2] - z0 ? per : d[2] - z0;
        int rc = read_slab(p->s, &p->sb, e);
        if (rc) return rc;
        for (uint32_t i = 0; i < p->sb.n; i++) {
            uint8_t *raw = p->sb.raw + slice * i;
            const uint32_t z = z0 + i;
            if (p->sb.hole[i]) {
                p->any_hole = 1;
                if (texels) {
                    vxl_index_build_const(&p->index, z, hole_value);
                    vxl_level_build_slice(&p->levels, NULL, 1, hole_value);
                }
                continue;
            }
            /* Row by row, so the holes inside a slice of a sparse file cost
             * O(bricks), not O(voxels): the rows without data hold raw zero. */
            const uint8_t *rows = p->sb.row_data + (size_t)i * d[1];
            const size_t tb = p->s->texture_bits / 8, row_t = (size_t)d[0] * tb, row_r = (size_t)d[0] * c->es;
            for (uint32_t y = 0; y < d[1]; y++) {
                uint8_t *rr = raw + row_r * (c->l.rows_top_first ? d[1] - 1 - y : y); /* stored order */
                if (!rows[y]) {
                    p->any_hole = 1;
                    if (texels) memcpy(p->texels + row_t * y, p->hole_row, row_t);
                    continue;
                }
                if (c->l.swap) vxl_swap_elements(rr, d[0], c->es);
                if (!texels || p->stages == 1)
                    vxl_raw_range(c->l.dtype, rr, d[0], c->map.slope, c->map.inter, &p->mn, &p->mx, &c->nan_count,
                                  &c->inf_count);
                if (texels) vxl_texels_from_raw(&c->map, rr, d[0], p->texels + row_t * y);
            }
            if (texels) {
                vxl_index_build_slice_rows(&p->index, z, p->texels, rows, hole_value);
                vxl_level_build_slice(&p->levels, p->texels, 0, 0);
            }
        }
        const double done = (p->stage + (double)(z0 + p->sb.n) / d[2]) / p->stages;
        rc = vxl_source_progress(p->opt, done, p->stages == 2 && !texels ? "finding the value range" : "indexing bricks", e);
        if (rc) return rc;
    }
    return VXL_OK;
}

/* Finishes the range (a hole is a raw zero, so it counts) into the map. */
static void fix_range(pass *p)
{
    raw_ctx *c = p->s->ctx;
    if (p->any_hole) {
        uint8_t zero[8] = {0};
        uint64_t nan = 0, inf = 0;
        vxl_raw_range(c->l.dtype, zero, 1, c->map.slope, c->map.inter, &p->mn, &p->mx, &nan, &inf);
    }
    vxl_texel_map_init(&c->map, c->l.dtype, c->map.slope, c->map.inter, p->mn, p->mx);
}

static int make_pass(vxl_brick_source *s, const vxl_load_options *opt, vxl_err *e)
{
    raw_ctx *c = s->ctx;
    const uint32_t *d = c->l.dims;
    const uint64_t slice = (uint64_t)d[0] * d[1] * c->es;
    const uint32_t per = (uint32_t)(PASS_SLAB_BYTES / slice > 0 ? PASS_SLAB_BYTES / slice : 1);
    pass p;
    memset(&p, 0, sizeof p);
    p.s = s;
    p.opt = opt;
    p.mn = INFINITY;
    p.mx = -INFINITY;
    p.stages = s->texture_bits == 32 ? 2 : 1;
    const uint32_t n = per < d[2] ? per : d[2];
    p.sb.raw = malloc((size_t)(slice * n));
    p.sb.hole = malloc(n);
    p.sb.row_data = malloc((size_t)n * d[1]);
    p.hole_row = malloc((size_t)d[0] * (s->texture_bits / 8));
    p.texels = malloc((size_t)d[0] * d[1] * (s->texture_bits / 8));
    int rc = VXL_OK;
    if (!p.sb.raw || !p.sb.hole || !p.sb.row_data || !p.hole_row || !p.texels)
        rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for a slab of %u slices", c->l.path, n);
    if (!rc) rc = vxl_index_build_begin(&p.index, d, s->texture_bits, vxl_source_index_brick(d), e);
    if (!rc)
        rc = vxl_level_build_begin(&p.levels, d, s->texture_bits, s->n_levels, keep_level_bytes(), e);
    if (!rc && p.stages == 2) { /* floats: their texels need the range first */
        rc = run_stage(&p, 0, e);
        if (!rc) fix_range(&p);
        p.stage = 1;
    }
    if (!rc) rc = run_stage(&p, 1, e);
    if (!rc && p.stages == 1) fix_range(&p);
    if (!rc) {
        vxl_level_build_finish(&p.levels);
        for (uint32_t k = 1; k < s->n_levels; k++) {
            c->levels[k] = p.levels.kept[k];
            p.levels.kept[k] = NULL;
            if (c->levels[k])
                s->resident_bytes += (uint64_t)s->level_dims[k][0] * s->level_dims[k][1] * s->level_dims[k][2] *
                                     (s->texture_bits / 8);
        }
        vxl_index_build_finish(&p.index, s);
    }
    vxl_index_build_free(&p.index);
    vxl_level_build_free(&p.levels);
    free(p.sb.raw);
    free(p.sb.hole);
    free(p.sb.row_data);
    free(p.hole_row);
    free(p.texels);
    return rc;
}

/* ------------------------------------------------------------- opening */

static int check_layout(const vxl_raw_layout *l, const vxl_load_options *opt, uint64_t file_size, vxl_err *e)
{
    const uint32_t max_dim = (opt && opt->max_dim) ? opt->max_dim : VXL_DEFAULT_MAX_DIM;
    const uint32_t es = vxl_dtype_size(l->dtype);
    if (l->compressed) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s' is compressed: read it through a brick cache", l->path);
    if (!es) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unknown data type %u", l->path, l->dtype);
    for (int a = 0; a < 3; a++) {
        if (l->dims[a] == 0)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': bad dimensions %ux%ux%u: every axis needs at least 1 voxel",
                            l->path, l->dims[0], l->dims[1], l->dims[2]);
        if (l->dims[a] > max_dim)
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s': dimensions %ux%ux%u exceed the per-axis limit of %u", l->path,
                            l->dims[0], l->dims[1], l->dims[2], max_dim);
    }
    uint64_t n, bytes, end;
    if (__builtin_mul_overflow((uint64_t)l->dims[0] * l->dims[1], (uint64_t)l->dims[2], &n) ||
        __builtin_mul_overflow(n, (uint64_t)es, &bytes) || __builtin_add_overflow(bytes, l->offset, &end) ||
        end > (uint64_t)INT64_MAX)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': %ux%ux%u voxels at offset %llu overflow any file size", l->path,
                        l->dims[0], l->dims[1], l->dims[2], (unsigned long long)l->offset);
    if (l->slice_offsets) { /* each slice within the file */
        const uint64_t slice = (uint64_t)l->dims[0] * l->dims[1] * es;
        for (uint32_t z = 0; z < l->dims[2]; z++) {
            const uint64_t at = l->slice_offsets[z];
            if (at > (uint64_t)INT64_MAX - slice)
                return vxl_fail(e, VXL_ERR_LIMIT, "'%s': slice %u at offset %llu overflows any file size", l->path,
                                z, (unsigned long long)at);
            if (file_size < at + slice)
                return vxl_fail(e, VXL_ERR_FORMAT,
                                "'%s': truncated file: expected %llu bytes of slice %u at offset %llu, got %llu",
                                l->path, (unsigned long long)slice, z, (unsigned long long)at,
                                (unsigned long long)(file_size > at ? file_size - at : 0));
        }
    } else if (file_size < end) /* the whole read's words (nifti.c, loader_util.c) */
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s': truncated file: expected %llu bytes of voxel data at offset %llu, got %llu", l->path,
                        (unsigned long long)bytes, (unsigned long long)l->offset,
                        (unsigned long long)(file_size > l->offset ? file_size - l->offset : 0));
    if (!isfinite(l->slope) || !isfinite(l->inter))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': scaling is not finite (%g, %g)", l->path, l->slope, l->inter);
    return VXL_OK;
}

int vxl_raw_source_open(const vxl_raw_layout *l, const vxl_load_options *opt, vxl_brick_source **out, vxl_err *e)
{
    *out = NULL;
    int fd = vxl_file_open_read(l->path, 0);
    if (fd < 0) return vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", l->path, strerror(errno));
    vxl_path_info st;
    if (vxl_file_stat(fd, &st) != 0 || st.kind != VXL_PATH_FILE) {
        vxl_file_close(fd);
        return vxl_fail(e, VXL_ERR_IO, "'%s' is not a regular file", l->path);
    }
    int rc = check_layout(l, opt, st.size, e);
    vxl_brick_source *s = rc ? NULL : calloc(1, sizeof *s);
    raw_ctx *c = rc ? NULL : calloc(1, sizeof *c);
    if (!rc && (!s || !c)) rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory opening '%s'", l->path);
    if (rc) {
        free(s);
        free(c);
        vxl_file_close(fd);
        return rc;
    }
    c->fd = fd;
    c->l = *l;
    if (l->slice_offsets) { /* the loader's table is its own: keep a copy (dims[2] <= max_dim entries) */
        c->slices = malloc((size_t)l->dims[2] * sizeof *c->slices);
        if (!c->slices) {
            free(s);
            free(c);
            vxl_file_close(fd);
            return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory opening '%s'", l->path);
        }
        memcpy(c->slices, l->slice_offsets, (size_t)l->dims[2] * sizeof *c->slices);
        c->l.slice_offsets = c->slices;
    }
    c->es = vxl_dtype_size(l->dtype);
    /* slope and intercept as vxl_volume_build takes them; the range comes with the pass */
    vxl_texel_map_init(&c->map, l->dtype, l->slope, l->inter, 0, 0);
    s->ops = &raw_ops;
    s->ctx = c;
    s->texture_bits = vxl_texture_bits_for(l->dtype);
    s->resident_bytes = sizeof *c + (c->slices ? (uint64_t)l->dims[2] * sizeof *c->slices : 0);
    vxl_brick_source_set_levels(s, l->dims, vxl_source_level_count(l->dims));
    rc = make_pass(s, opt, e);
    if (rc) {
        vxl_brick_source_free(s);
        return rc;
    }
    *out = s;
    return VXL_OK;
}

int vxl_raw_source_describe(const vxl_brick_source *s, vxl_volume *v, vxl_err *e)
{
    if (!s || s->ops != &raw_ops) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "not a raw file source");
    const raw_ctx *c = s->ctx;
    vxl_volume_set_values(v, &c->map);
    v->nan_count = c->nan_count;
    v->inf_count = c->inf_count;
    return VXL_OK;
}
