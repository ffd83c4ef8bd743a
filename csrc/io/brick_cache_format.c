/* brick_cache_format.c - encodes, decodes and bounds the bricked cache's
 * header and table (brick_cache_format.h). Everything a reader allocates or
 * seeks to is checked here first, against the file's real size. */
#include "brick_cache_format.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "crc32.h"
#include "volume.h"

#define CRC_AT (VXL_CACHE_HEADER_BYTES - 4u)

static uint32_t crc_of(const void *p, size_t n) { return vxl_crc32(0, p, n); }

/* The header's fields after magic, version and byte order, in file order:
 * one list serves the encoder and the decoder. */
typedef struct field {
    size_t at, size; /* offset in vxl_cache_header, bytes */
} field;

#define F(name) {offsetof(vxl_cache_header, name), sizeof(((vxl_cache_header *)0)->name)}
static const field header_fields[] = {
    F(src_size),     F(src_mtime_ns), F(src_header_hash), F(src_offset),   F(src_dtype),    F(src_swap),
    F(src_frame),    F(dims),         F(slope),           F(inter),        F(texture_bits), F(brick),
    F(n_levels),     F(index_brick),  F(value_min),       F(value_max),    F(tex_lo),       F(tex_hi),
    F(nan_count),    F(inf_count),    F(brick_count),     F(index_offset), F(index_bytes),  F(table_offset),
    F(table_bytes),  F(index_crc),    F(table_crc),       F(src_compressed_start)};
#undef F
#define FIELDS_AT 16u /* after the magic, version and byte-order mark */
/* the fields above take 192 bytes; they must end before the CRC (a new field needs room) */
_Static_assert(FIELDS_AT + 192 <= VXL_CACHE_HEADER_BYTES - 4, "the header's fields overlap its CRC");

void vxl_cache_header_encode(const vxl_cache_header *h, uint8_t out[VXL_CACHE_HEADER_BYTES])
{
    memset(out, 0, VXL_CACHE_HEADER_BYTES);
    const uint32_t version = VXL_CACHE_VERSION, order = VXL_CACHE_BYTE_ORDER;
    memcpy(out, VXL_CACHE_MAGIC, 8);
    memcpy(out + 8, &version, 4);
    memcpy(out + 12, &order, 4);
    size_t p = FIELDS_AT;
    for (size_t i = 0; i < sizeof header_fields / sizeof *header_fields; i++) {
        memcpy(out + p, (const uint8_t *)h + header_fields[i].at, header_fields[i].size);
        p += header_fields[i].size;
    }
    const uint32_t crc = crc_of(out, CRC_AT);
    memcpy(out + CRC_AT, &crc, 4);
}

int vxl_cache_header_decode(const uint8_t in[VXL_CACHE_HEADER_BYTES], vxl_cache_header *h, const char *path,
                            vxl_err *e)
{
    uint32_t version, order, crc;
    memcpy(&crc, in + CRC_AT, 4);
    if (memcmp(in, VXL_CACHE_MAGIC, 8) != 0)
        return vxl_fail(e, VXL_ERR_FORMAT, "%s is not a Voxlight brick cache", path);
    memcpy(&version, in + 8, 4);
    memcpy(&order, in + 12, 4);
    if (order != VXL_CACHE_BYTE_ORDER)
        return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s was written on a machine of the other byte order", path);
    if (version != VXL_CACHE_VERSION)
        return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s has format version %u, not %u", path, version,
                        VXL_CACHE_VERSION);
    if (crc != crc_of(in, CRC_AT))
        return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s: the header's checksum does not match (damaged)", path);
    memset(h, 0, sizeof *h);
    size_t p = FIELDS_AT;
    for (size_t i = 0; i < sizeof header_fields / sizeof *header_fields; i++) {
        memcpy((uint8_t *)h + header_fields[i].at, in + p, header_fields[i].size);
        p += header_fields[i].size;
    }
    return VXL_OK;
}

static uint32_t ceil_div(uint32_t a, uint32_t b) { return (uint32_t)(((uint64_t)a + b - 1) / b); }

int vxl_cache_grid_make(const uint32_t dims[3], uint32_t texture_bits, uint32_t brick, uint32_t n_levels,
                        uint32_t index_brick, vxl_cache_grid *g)
{
    memset(g, 0, sizeof *g);
    if (!brick || !index_brick || !n_levels || n_levels > VXL_SOURCE_MAX_LEVELS) return -1;
    if (texture_bits != 8 && texture_bits != 16 && texture_bits != 32) return -1;
    g->n_levels = n_levels;
    g->brick = brick;
    g->texel_bytes = texture_bits / 8;
    uint64_t total = 0;
    for (uint32_t L = 0; L < n_levels; L++) {
        uint64_t n = 1;
        for (int a = 0; a < 3; a++) {
            if (!dims[a]) return -1;
            g->dims[L][a] = (uint32_t)(((uint64_t)dims[a] + (1ull << L) - 1) >> L);
            g->bricks[L][a] = ceil_div(g->dims[L][a], brick);
            if (n > (1ull << 40) / g->bricks[L][a]) return -1; /* a table no file could hold */
            n *= g->bricks[L][a];
        }
        g->first[L] = total;
        total += n;
    }
    g->first[n_levels] = total;
    g->index_count = 1;
    for (int a = 0; a < 3; a++) {
        g->index_dims[a] = ceil_div(dims[a], index_brick);
        g->index_count *= g->index_dims[a];
    }
    return 0;
}

/* a + b <= limit without overflow */
static int fits(uint64_t a, uint64_t b, uint64_t limit) { return a <= limit && b <= limit - a; }

int vxl_cache_header_check(const vxl_cache_header *h, uint64_t file_size, uint32_t max_dim, vxl_cache_grid *g,
                           const char *path, vxl_err *e)
{
    for (int a = 0; a < 3; a++)
        if (!h->dims[a] || h->dims[a] > max_dim)
            return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s: dimensions %ux%ux%u out of range (1..%u)", path,
                            h->dims[0], h->dims[1], h->dims[2], max_dim);
    if (!vxl_dtype_size(h->src_dtype) || vxl_texture_bits_for(h->src_dtype) != h->texture_bits)
        return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s: data type %u / %u-bit texels do not agree", path,
                        h->src_dtype, h->texture_bits);
    if (h->brick < 1 || h->brick > VXL_CACHE_MAX_BRICK || h->index_brick < 1 ||
        h->index_brick > VXL_CACHE_MAX_INDEX_BRICK)
        return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s: brick edge %u or index brick %u out of range", path,
                        h->brick, h->index_brick);
    if (!isfinite(h->value_min) || !isfinite(h->value_max) || !isfinite(h->tex_lo) || !isfinite(h->tex_hi) ||
        !(h->value_min <= h->value_max))
        return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s: the value range is not finite", path);
    if (vxl_cache_grid_make(h->dims, h->texture_bits, h->brick, h->n_levels, h->index_brick, g) != 0)
        return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s: %u levels of %u-voxel bricks do not fit %ux%ux%u", path,
                        h->n_levels, h->brick, h->dims[0], h->dims[1], h->dims[2]);
    if (h->brick_count != g->first[g->n_levels])
        return vxl_fail(e, VXL_ERR_FORMAT, "brick cache %s: %llu bricks listed, %llu expected", path,
                        (unsigned long long)h->brick_count, (unsigned long long)g->first[g->n_levels]);
    /* index and table lie in the file, after the header, and have their sizes */
    if (h->index_bytes / 8 != g->index_count || h->index_bytes % 8 ||
        h->table_bytes / VXL_CACHE_ENTRY_BYTES != h->brick_count || h->table_bytes % VXL_CACHE_ENTRY_BYTES ||
        h->index_offset < VXL_CACHE_HEADER_BYTES || h->table_offset < VXL_CACHE_HEADER_BYTES ||
        !fits(h->index_offset, h->index_bytes, file_size) || !fits(h->table_offset, h->table_bytes, file_size))
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "brick cache %s is truncated or damaged: its index or brick table lies outside its %llu bytes",
                        path, (unsigned long long)file_size);
    return VXL_OK;
}

int vxl_cache_header_matches(const vxl_cache_header *h, const vxl_raw_layout *l)
{
    return h->src_size == l->file_size && h->src_mtime_ns == l->mtime_ns && h->src_header_hash == l->header_hash &&
           h->src_offset == l->offset && h->src_compressed_start == l->compressed_start && h->src_dtype == l->dtype &&
           h->src_swap == (uint32_t)(l->swap != 0) && h->src_frame == l->frame && h->dims[0] == l->dims[0] && h->dims[1] == l->dims[1] &&
           h->dims[2] == l->dims[2] && memcmp(&h->slope, &l->slope, sizeof h->slope) == 0 &&
           memcmp(&h->inter, &l->inter, sizeof h->inter) == 0;
}

void vxl_cache_brick_box(const vxl_cache_grid *g, uint32_t level, uint64_t i, uint32_t lo[3], uint32_t size[3])
{
    const uint32_t *nb = g->bricks[level], *d = g->dims[level];
    const uint64_t c[3] = {i % nb[0], i / nb[0] % nb[1], i / ((uint64_t)nb[0] * nb[1])};
    for (int a = 0; a < 3; a++) {
        const uint64_t core = c[a] * g->brick, end = core + g->brick + VXL_CACHE_APRON;
        lo[a] = (uint32_t)(core < VXL_CACHE_APRON ? 0 : core - VXL_CACHE_APRON);
        size[a] = (uint32_t)((end < d[a] ? end : d[a]) - lo[a]);
    }
}

/* An entry on disk: offset (8), size (4), crc (4), kind (4), 4 zero bytes. */
void vxl_cache_entry_encode(const vxl_cache_entry *en, uint8_t out[VXL_CACHE_ENTRY_BYTES])
{
    memset(out, 0, VXL_CACHE_ENTRY_BYTES);
    memcpy(out, &en->offset, 8);
    memcpy(out + 8, &en->size, 4);
    memcpy(out + 12, &en->crc, 4);
    memcpy(out + 16, &en->kind, 4);
}

void vxl_cache_entry_decode(const uint8_t in[VXL_CACHE_ENTRY_BYTES], vxl_cache_entry *en)
{
    memcpy(&en->offset, in, 8);
    memcpy(&en->size, in + 8, 4);
    memcpy(&en->crc, in + 12, 4);
    memcpy(&en->kind, in + 16, 4);
}

int vxl_cache_entry_check(const vxl_cache_entry *en, uint64_t brick_bytes, uint32_t texel_bytes, uint64_t data_end)
{
    if (en->offset < VXL_CACHE_HEADER_BYTES || !fits(en->offset, en->size, data_end)) return -1;
    switch (en->kind) {
    case VXL_CACHE_RAW: return en->size == brick_bytes ? 0 : -1;
    case VXL_CACHE_CONSTANT: return en->size == texel_bytes ? 0 : -1;
    case VXL_CACHE_ZLIB: return en->size > 0 && en->size < brick_bytes ? 0 : -1; /* stored only when smaller */
    default: return -1;
    }
}
