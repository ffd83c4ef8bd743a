/* tiff_layout.c - a TIFF's directories walked to find whether its pages can
 * be read by offset (tiff_layout.h). Every read is a bounded pread checked
 * against the file's size; nothing is allocated in proportion to what a
 * header claims, only to the pages actually found (at most max_dim). */
#include "tiff_layout.h"
#include "files.h"

#include "channel_volume.h"
#include "loader_util.h"
#include "ome_xml.h"
#include "stream_load.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_ENTRIES 4096u   /* more tags than any real directory: a damaged one, read whole */
#define ARRAY_CHUNK 512u    /* strip offsets/counts read this many at a time */

typedef struct tfile {
    int fd;
    const char *path;
    uint64_t size;
    int be;                 /* 1: big-endian ("MM") */
    int big;                /* 1: BigTIFF */
    int channels_off;       /* vxl_load_options.channels is OFF: an OME-TIFF's channels are slices */
} tfile;

/* One directory entry: type, count and the raw value field (4 or 8 bytes). */
typedef struct entry {
    uint16_t type;
    uint64_t count;
    uint8_t val[8];
    int present;
} entry;

/* What a page says; tags absent take TIFF's defaults. */
enum { T_WIDTH, T_HEIGHT, T_BITS, T_COMP, T_PHOTO, T_FILL, T_OFFSETS, T_ORIENT, T_SPP, T_RPS, T_COUNTS, T_PRED,
       T_FORMAT, T_DEPTH, T_N };
static const uint16_t k_tags[T_N] = {256, 257, 258, 259, 262, 266, 273, 274, 277, 278, 279, 317, 339, 32997};

/* read_page's answers besides VXL_* errors: the page streams, or it cannot
 * (t->why says why; negative, so never a VXL_ERR_* code). */
enum { PAGE_OK = 0, PAGE_NO = -1 };

static uint64_t get(const tfile *f, const uint8_t *p, int n)
{
    uint64_t v = 0;
    for (int i = 0; i < n; i++) v |= (uint64_t)p[f->be ? n - 1 - i : i] << (8 * i);
    return v;
}

/* n bytes at off, which the caller has checked lie in the file. */
static int read_exact(const tfile *f, void *buf, size_t n, uint64_t off, vxl_err *e)
{
    const int64_t got = vxl_pread_full(f->fd, buf, n, off);
    if (got < 0) return vxl_fail(e, VXL_ERR_IO, "read error in '%s': %s", f->path, strerror(errno));
    if ((uint64_t)got < n)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': truncated file: it ends at byte %llu", f->path,
                        (unsigned long long)(off + (uint64_t)got));
    return VXL_OK;
}

#define MAX_DESCRIPTION (1u << 20) /* OME-XML read from the first page's ImageDescription */

/* Whether the first page's ImageDescription (tag 270 at entry p) is OME-XML
 * of several channels, which the whole read (image_stack.cpp) makes a
 * multi-channel volume: those pages are not slices to stream. */
static int ome_channels(const tfile *f, const uint8_t *p, uint64_t *channels, vxl_err *e)
{
    const uint64_t count = get(f, p + 4, f->big ? 8 : 4), at = get(f, p + (f->big ? 12 : 8), f->big ? 8 : 4);
    *channels = 0;
    if (get(f, p + 2, 2) != 2 || count <= (f->big ? 8u : 4u) || count > MAX_DESCRIPTION || at > f->size ||
        f->size - at < count)
        return VXL_OK; /* inline, absurd or past the end: not OME-XML the whole read would take */
    char *text = malloc((size_t)count + 1);
    if (!text) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for its description", f->path);
    int rc = read_exact(f, text, (size_t)count, at, e);
    text[count] = '\0';
    vxl_ome_pixels px;
    if (!rc && vxl_ome_xml_parse(text, strlen(text), &px)) *channels = px.size[1];
    free(text);
    return rc;
}

static int why(vxl_tiff_layout *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int why(vxl_tiff_layout *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(t->why, sizeof t->why, fmt, ap);
    va_end(ap);
    return PAGE_NO;
}

static uint32_t type_size(uint16_t type)
{
    switch (type) {
    case 1: return 1;  /* BYTE */
    case 3: return 2;  /* SHORT */
    case 4: return 4;  /* LONG */
    case 16: return 8; /* LONG8 (BigTIFF) */
    default: return 0; /* not an unsigned integer: not a tag we read */
    }
}

/* Element i of an integer entry whose values fit in the value field. */
static int inline_value(const tfile *f, const entry *en, uint64_t *v)
{
    const uint32_t es = type_size(en->type), field = f->big ? 8 : 4;
    if (!en->count || !es || en->count * es > field) return 0;
    *v = get(f, en->val, (int)es);
    return 1;
}

/* A single-valued tag (absent: def); 0 when it is present but not one integer. */
static int scalar(const tfile *f, const entry *tags, int k, uint64_t def, uint64_t *v)
{
    if (!tags[k].present) {
        *v = def;
        return 1;
    }
    return tags[k].count == 1 && inline_value(f, &tags[k], v);
}

/* Reads elements [i0, i0+n) of an integer array entry into out. */
static int array_chunk(const tfile *f, const entry *en, uint64_t i0, uint32_t n, uint64_t *out, uint32_t page,
                       vxl_err *e)
{
    const uint32_t es = type_size(en->type), field = f->big ? 8 : 4;
    uint8_t buf[ARRAY_CHUNK * 8];
    const uint8_t *src;
    if (en->count * es <= field) {
        src = en->val + i0 * es;
    } else {
        const uint64_t base = get(f, en->val, f->big ? 8 : 4), at = base + i0 * es;
        if (base > f->size || i0 * es > f->size - base || (uint64_t)n * es > f->size - at)
            return vxl_fail(e, VXL_ERR_FORMAT,
                            "'%s': truncated file: the strip table of page %u lies past its end (%llu bytes)",
                            f->path, page + 1, (unsigned long long)f->size);
        int rc = read_exact(f, buf, (size_t)n * es, at, e);
        if (rc) return rc;
        src = buf;
    }
    for (uint32_t i = 0; i < n; i++) out[i] = get(f, src + (size_t)i * es, (int)es);
    return VXL_OK;
}

typedef struct page {
    uint32_t w, h, dtype;
    uint64_t start;         /* where its pixels start */
    uint64_t next;          /* the next directory (0: none) */
} page;

/* The pixel type the whole read gives (image_stack.cpp's dtype_for), or 0. */
static uint32_t dtype_of(uint64_t bits, uint64_t format)
{
    if (format == 1) return bits == 8 ? VXL_DTYPE_U8 : bits == 16 ? VXL_DTYPE_U16 : bits == 32 ? VXL_DTYPE_U32 : 0;
    if (format == 2) return bits == 8 ? VXL_DTYPE_I8 : bits == 16 ? VXL_DTYPE_I16 : bits == 32 ? VXL_DTYPE_I32 : 0;
    if (format == 3) return bits == 32 ? VXL_DTYPE_F32 : bits == 64 ? VXL_DTYPE_F64 : 0;
    return 0;
}

/* Reads the directory at off (page index n): PAGE_OK with pg filled,
 * PAGE_NO with t->why, or an error (a truncated file). */
static int read_page(const tfile *f, uint64_t at, uint32_t n, uint32_t max_dim, vxl_tiff_layout *t, page *pg,
                     vxl_err *e)
{
    const uint32_t head = f->big ? 8 : 2, esz = f->big ? 20 : 12, tail = f->big ? 8 : 4;
    uint8_t b[8];
    if (at > f->size || f->size - at < head)
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s': truncated file: the directory of page %u at byte %llu lies past its end (%llu bytes)",
                        f->path, n + 1, (unsigned long long)at, (unsigned long long)f->size);
    int rc = read_exact(f, b, head, at, e);
    if (rc) return rc;
    const uint64_t count = get(f, b, (int)head);
    if (count == 0 || count > MAX_ENTRIES) return why(t, "TIFF with a damaged directory (page %u)", n + 1);
    const uint64_t bytes = count * esz + tail;
    if (f->size - at - head < bytes)
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s': truncated file: the directory of page %u at byte %llu lies past its end (%llu bytes)",
                        f->path, n + 1, (unsigned long long)at, (unsigned long long)f->size);
    uint8_t *d = malloc((size_t)bytes);
    if (!d) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for a directory", f->path);
    rc = read_exact(f, d, (size_t)bytes, at + head, e);
    entry tags[T_N];
    memset(tags, 0, sizeof tags);
    int res = PAGE_OK;
    for (uint64_t i = 0; i < count && !rc && res == PAGE_OK; i++) {
        const uint8_t *p = d + i * esz;
        const uint16_t tag = (uint16_t)get(f, p, 2);
        uint64_t channels = 0;
        if (tag >= 322 && tag <= 325) res = why(t, "tiled TIFF (page %u)", n + 1);
        else if (tag == 338) res = why(t, "TIFF with extra samples (page %u)", n + 1);
        else if (tag == 270 && n == 0 && !f->channels_off && !(rc = ome_channels(f, p, &channels, e)) && channels > 1)
            res = why(t, "an OME-TIFF of %llu channels (a multi-channel volume is read whole)",
                      (unsigned long long)channels);
        for (int k = 0; k < T_N && res == PAGE_OK; k++) {
            if (k_tags[k] != tag) continue;
            if (tags[k].present) res = why(t, "TIFF with a repeated tag %u (page %u)", tag, n + 1);
            tags[k].present = 1;
            tags[k].type = (uint16_t)get(f, p + 2, 2);
            tags[k].count = get(f, p + 4, f->big ? 8 : 4);
            memcpy(tags[k].val, p + (f->big ? 12 : 8), f->big ? 8 : 4);
        }
    }
    if (!rc) pg->next = get(f, d + count * esz, (int)tail);
    free(d);
    if (rc || res) return rc ? rc : res;

    uint64_t w, h, bits, comp, photo, fill, orient, spp, rps, pred, format, depth;
    if (!tags[T_WIDTH].present || !tags[T_HEIGHT].present || !tags[T_OFFSETS].present || !tags[T_COUNTS].present ||
        !tags[T_PHOTO].present)
        return why(t, "TIFF without size, strips or photometric tags (page %u)", n + 1);
    /* compression and samples first: a colour page's per-sample tags are arrays */
    if (!scalar(f, tags, T_COMP, 1, &comp) || !scalar(f, tags, T_SPP, 1, &spp))
        return why(t, "TIFF with a damaged directory (page %u)", n + 1);
    if (comp != 1) return why(t, "compressed TIFF (page %u: compression %llu)", n + 1, (unsigned long long)comp);
    if (spp != 1) return why(t, "colour TIFF (page %u: %llu samples per pixel)", n + 1, (unsigned long long)spp);
    if (!scalar(f, tags, T_WIDTH, 0, &w) || !scalar(f, tags, T_HEIGHT, 0, &h) || !scalar(f, tags, T_BITS, 1, &bits) ||
        !scalar(f, tags, T_PHOTO, 0, &photo) || !scalar(f, tags, T_FILL, 1, &fill) ||
        !scalar(f, tags, T_ORIENT, 1, &orient) || !scalar(f, tags, T_RPS, UINT32_MAX, &rps) ||
        !scalar(f, tags, T_PRED, 1, &pred) || !scalar(f, tags, T_FORMAT, 1, &format) ||
        !scalar(f, tags, T_DEPTH, 1, &depth))
        return why(t, "TIFF with unusual tag values (page %u)", n + 1);
    if (photo != 1)
        return why(t, "TIFF with photometric interpretation %llu (page %u)", (unsigned long long)photo, n + 1);
    if (fill != 1 || orient != 1 || pred != 1 || depth != 1)
        return why(t, "TIFF with bit order, orientation, predictor or depth tags (page %u)", n + 1);
    if (format == 3 && bits == 16) return why(t, "half-float TIFF");
    const uint32_t dtype = dtype_of(bits, format);
    if (!dtype)
        return why(t, "TIFF with %llu-bit pixels of sample format %llu", (unsigned long long)bits,
                   (unsigned long long)format);
    if (w == 0 || h == 0) return why(t, "TIFF with an empty page (page %u)", n + 1);
    if (w > max_dim || h > max_dim) {
        t->why[0] = '\0'; /* a limit: the whole read names it */
        return PAGE_NO;
    }
    if (rps == 0) return why(t, "TIFF with 0 rows per strip (page %u)", n + 1);
    const uint64_t es = bits / 8, row = w * es, strips = h / rps + (h % rps != 0);
    if (h > UINT64_MAX / row) {
        t->why[0] = '\0'; /* sizes past any file: the whole read's limits name them */
        return PAGE_NO;
    }
    if (tags[T_OFFSETS].count != strips || tags[T_COUNTS].count != strips || !type_size(tags[T_OFFSETS].type) ||
        !type_size(tags[T_COUNTS].type))
        return why(t, "TIFF whose strip tables do not match its strips (page %u)", n + 1);
    /* the strips in order, each starting where the one before ends */
    uint64_t off[ARRAY_CHUNK], cnt[ARRAY_CHUNK], expect = 0, start = 0;
    for (uint64_t s0 = 0; s0 < strips; s0 += ARRAY_CHUNK) {
        const uint32_t m = (uint32_t)(strips - s0 < ARRAY_CHUNK ? strips - s0 : ARRAY_CHUNK);
        rc = array_chunk(f, &tags[T_OFFSETS], s0, m, off, n, e);
        if (!rc) rc = array_chunk(f, &tags[T_COUNTS], s0, m, cnt, n, e);
        if (rc) return rc;
        for (uint32_t i = 0; i < m; i++) {
            const uint64_t s = s0 + i, rows = s + 1 < strips ? rps : h - s * rps, need = rows * row;
            if (s == 0) expect = start = off[0];
            if (off[i] != expect || cnt[i] < need)
                return why(t, "TIFF whose strips are not contiguous (page %u)", n + 1);
            if (off[i] > f->size || cnt[i] > f->size - off[i])
                return vxl_fail(e, VXL_ERR_FORMAT,
                                "'%s': truncated file: strip %llu of page %u ends at byte %llu, past its end (%llu "
                                "bytes)",
                                f->path, (unsigned long long)s + 1, n + 1,
                                (unsigned long long)(off[i] > UINT64_MAX - cnt[i] ? UINT64_MAX : off[i] + cnt[i]),
                                (unsigned long long)f->size);
            expect = off[i] + need;
        }
    }
    pg->w = (uint32_t)w;
    pg->h = (uint32_t)h;
    pg->dtype = dtype;
    pg->start = start;
    return PAGE_OK;
}

/* The directories seen, so a chain that loops back ends the walk (open
 * addressing over offsets; grows with the pages found, which max_dim bounds). */
typedef struct seen {
    uint64_t *slot;
    size_t cap, n;
} seen;

/* 1 when off was there already; -1 out of memory. */
static int seen_add(seen *s, uint64_t off)
{
    if (2 * (s->n + 1) > s->cap) {
        const size_t cap = s->cap ? 2 * s->cap : 64;
        uint64_t *slot = calloc(cap, sizeof *slot);
        if (!slot) return -1;
        for (size_t i = 0; i < s->cap; i++)
            if (s->slot[i]) {
                size_t j = (size_t)(s->slot[i] * 0x9E3779B97F4A7C15ull >> 20) & (cap - 1);
                while (slot[j]) j = (j + 1) & (cap - 1);
                slot[j] = s->slot[i];
            }
        free(s->slot);
        s->slot = slot;
        s->cap = cap;
    }
    size_t j = (size_t)(off * 0x9E3779B97F4A7C15ull >> 20) & (s->cap - 1);
    for (; s->slot[j]; j = (j + 1) & (s->cap - 1))
        if (s->slot[j] == off) return 1;
    s->slot[j] = off; /* off is never 0: 0 ends the chain */
    s->n++;
    return 0;
}

static int walk(const tfile *f, uint64_t first, uint32_t max_dim, vxl_tiff_layout *t, vxl_err *e)
{
    seen visited = {0};
    uint64_t *offs = NULL;
    size_t cap = 0;
    uint32_t n = 0;
    page p0 = {0}, pg;
    int rc = VXL_OK, res = PAGE_OK;
    for (uint64_t off = first; off && !rc && res == PAGE_OK; off = pg.next) {
        if (n >= max_dim) {
            t->why[0] = '\0'; /* more pages than the per-axis limit: the whole read says so */
            res = PAGE_NO;
            break;
        }
        const int again = seen_add(&visited, off);
        if (again < 0) rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory walking its pages", f->path);
        else if (again) res = why(t, "TIFF whose directories loop (page %u)", n + 1);
        if (rc || res) break;
        memset(&pg, 0, sizeof pg);
        rc = read_page(f, off, n, max_dim, t, &pg, e);
        if (rc == PAGE_NO) {
            rc = VXL_OK;
            res = PAGE_NO;
        }
        if (rc || res) break;
        if (n == 0) p0 = pg;
        else if (pg.w != p0.w || pg.h != p0.h || pg.dtype != p0.dtype)
            res = why(t, "TIFF whose pages differ in size or pixel type (page %u)", n + 1);
        if (res) break;
        if (n == cap) {
            cap = cap ? 2 * cap : 64;
            if (cap > max_dim) cap = max_dim;
            uint64_t *grown = realloc(offs, cap * sizeof *offs);
            if (!grown) {
                rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory walking its pages", f->path);
                break;
            }
            offs = grown;
        }
        offs[n++] = pg.start;
    }
    free(visited.slot);
    if (!rc && !res && n < 2) res = why(t, "single-page TIFF files or TIFF series");
    if (rc || res) {
        free(offs);
        return rc;
    }
    t->dims[0] = p0.w;
    t->dims[1] = p0.h;
    t->dims[2] = n;
    t->dtype = p0.dtype;
    t->page_offsets = offs;
    t->why[0] = '\0';
    return VXL_OK;
}

int vxl_tiff_layout_probe(const char *path, const vxl_load_options *opt, vxl_tiff_layout *t, vxl_err *e)
{
    memset(t, 0, sizeof *t);
    const uint32_t max_dim = opt && opt->max_dim ? opt->max_dim : VXL_DEFAULT_MAX_DIM;
    int fd = vxl_file_open_read(path, 0);
    if (fd < 0) return vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    vxl_path_info st;
    if (vxl_file_stat(fd, &st) != 0 || st.kind != VXL_PATH_FILE) {
        vxl_file_close(fd);
        return vxl_fail(e, VXL_ERR_IO, "'%s' is not a regular file", path);
    }
    uint32_t mode = VXL_CHANNELS_AUTO, scalar;
    vxl_err ignore = {0};
    if (vxl_load_channels_mode(opt, &mode, &scalar, &ignore)) mode = VXL_CHANNELS_AUTO; /* the whole read reports it */
    tfile f = {fd, path, st.size, 0, 0, mode == VXL_CHANNELS_OFF};
    t->file_size = f.size;
    uint8_t h[16] = {0};
    int rc = VXL_OK;
    if (f.size < 8 || read_exact(&f, h, f.size < 16 ? (size_t)f.size : 16, 0, e) != VXL_OK ||
        (memcmp(h, "II", 2) && memcmp(h, "MM", 2))) {
        why(t, "a file that is not a TIFF");
        vxl_file_close(fd);
        return VXL_OK;
    }
    f.be = h[0] == 'M';
    const uint64_t magic = get(&f, h + 2, 2);
    uint64_t first = 0;
    if (magic == 42) {
        first = get(&f, h + 4, 4);
    } else if (magic == 43 && f.size >= 16 && get(&f, h + 4, 2) == 8 && get(&f, h + 6, 2) == 0) {
        f.big = 1;
        first = get(&f, h + 8, 8);
    } else {
        why(t, "a file that is not a TIFF");
        vxl_file_close(fd);
        return VXL_OK;
    }
    if (!first) why(t, "TIFF without pages");
    else rc = walk(&f, first, max_dim, t, e);
    vxl_file_close(fd);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
    t->swap = !f.be;
#else
    t->swap = f.be;
#endif
    return rc;
}

void vxl_tiff_layout_free(vxl_tiff_layout *t)
{
    if (!t) return;
    free(t->page_offsets);
    t->page_offsets = NULL;
}

int vxl_tiff_raw_layout(const char *path, const vxl_tiff_layout *t, const vxl_load_options *opt, vxl_raw_layout *l,
                        vxl_err *e)
{
    if (!t->page_offsets) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s' cannot be read by offset", path);
    double vs[3];
    vxl_load_voxel_size(opt, vs); /* as the whole read: images carry no reliable geometry */
    double affine[16] = {0};
    for (int a = 0; a < 3; a++) affine[a * 4 + a] = vs[a];
    affine[15] = 1.0;
    int rc = vxl_layout_init(l, path, t->page_offsets[0], t->dims, t->dtype, vs, affine, e);
    if (rc) return rc;
    l->swap = t->swap;
    l->slice_offsets = t->page_offsets;
    l->rows_top_first = 1;
    return VXL_OK;
}
