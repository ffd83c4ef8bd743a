/* brick_cache_format.h - the bricked cache file, shared by its writer
 * (brick_cache_write.c) and reader (brick_cache_read.c).
 *
 *   [header, VXL_CACHE_HEADER_BYTES] [bricks ...] [index] [brick table]
 *
 * Numbers are in the writer's byte order (the header's byte-order mark
 * tells; a cache from a machine of the other order is rebuilt). The header
 * ends with a CRC32 of everything before it, and holds CRC32s of the index
 * and of the table; each table entry holds the CRC32 of its brick's stored
 * bytes. Bricks are numbered level by level, then x fastest; a brick at the
 * volume's end is cut to what is left.
 *
 * Version 2: each brick stores its `brick`^3 core widened by a one-voxel
 * apron on every side that lies inside the level (VXL_CACHE_APRON): a
 * renderer's page brick of the same edge with its one-voxel ghost is then
 * exactly one stored brick, one inflate, instead of up to 27 (version 1
 * stored the core alone). A version-1 cache fails the version check and is
 * rebuilt. Nothing read from a cache is used before vxl_cache_header_check
 * has bounded it. */
#ifndef VXL_BRICK_CACHE_FORMAT_H
#define VXL_BRICK_CACHE_FORMAT_H

#include <stddef.h>
#include <stdint.h>

#include "brick_source.h"
#include "error.h"
#include "raw_layout.h"

#define VXL_CACHE_MAGIC "VXLBRICK"
#define VXL_CACHE_VERSION 2u
#define VXL_CACHE_APRON 1u /* voxels each stored brick extends past its core (inside the level) */
#define VXL_CACHE_BYTE_ORDER 0x01020304u
#define VXL_CACHE_HEADER_BYTES 224u
#define VXL_CACHE_ENTRY_BYTES 24u
#define VXL_CACHE_MAX_BRICK 256u      /* brick edge limit a reader accepts */
#define VXL_CACHE_MAX_INDEX_BRICK 65536u

/* How a brick's bytes are stored. */
enum { VXL_CACHE_RAW = 0, VXL_CACHE_ZLIB = 1, VXL_CACHE_CONSTANT = 2 };

typedef struct vxl_cache_header {
    /* the key: the source and how its voxels are read */
    uint64_t src_size;
    int64_t src_mtime_ns;
    uint64_t src_header_hash;
    uint64_t src_offset;
    uint32_t src_dtype, src_swap, src_frame;
    uint64_t src_compressed_start; /* where the compressed stream starts in the source file */
    uint32_t dims[3];
    double slope, inter;
    /* the content */
    uint32_t texture_bits, brick, n_levels, index_brick;
    double value_min, value_max, tex_lo, tex_hi;
    uint64_t nan_count, inf_count;
    uint64_t brick_count;
    uint64_t index_offset, index_bytes;
    uint64_t table_offset, table_bytes;
    uint32_t index_crc, table_crc;
} vxl_cache_header;

typedef struct vxl_cache_entry {
    uint64_t offset;
    uint32_t size; /* stored bytes */
    uint32_t crc;  /* CRC32 of the stored bytes */
    uint32_t kind; /* VXL_CACHE_* */
} vxl_cache_entry;

/* The grid of a header's levels: dims of each level, bricks per axis and
 * the number of its first brick in the table. */
typedef struct vxl_cache_grid {
    uint32_t n_levels, brick, texel_bytes;
    uint32_t dims[VXL_SOURCE_MAX_LEVELS][3];
    uint32_t bricks[VXL_SOURCE_MAX_LEVELS][3];
    uint64_t first[VXL_SOURCE_MAX_LEVELS + 1]; /* first[n_levels] = brick count */
    uint32_t index_dims[3];
    uint64_t index_count;                      /* index bricks */
} vxl_cache_grid;

void vxl_cache_header_encode(const vxl_cache_header *h, uint8_t out[VXL_CACHE_HEADER_BYTES]);
/* Decodes and checks the magic, version, byte order and header CRC; names path on failure. */
int vxl_cache_header_decode(const uint8_t in[VXL_CACHE_HEADER_BYTES], vxl_cache_header *h, const char *path,
                            vxl_err *e);
/* Checks every size and offset against each other and the file's size, and
 * fills the grid. max_dim: the largest axis accepted. */
int vxl_cache_header_check(const vxl_cache_header *h, uint64_t file_size, uint32_t max_dim, vxl_cache_grid *g,
                           const char *path, vxl_err *e);
/* The grid of dims cut in bricks of `brick` over n_levels (used by the writer too). */
int vxl_cache_grid_make(const uint32_t dims[3], uint32_t texture_bits, uint32_t brick, uint32_t n_levels,
                        uint32_t index_brick, vxl_cache_grid *g);
/* 1 when h was made from this layout's source (size, mtime, header, how it is read). */
int vxl_cache_header_matches(const vxl_cache_header *h, const vxl_raw_layout *l);
/* Voxels stored for brick i of level L (its core plus the apron, cut at the
 * level's edges): origin and size. */
void vxl_cache_brick_box(const vxl_cache_grid *g, uint32_t level, uint64_t i, uint32_t lo[3], uint32_t size[3]);

void vxl_cache_entry_encode(const vxl_cache_entry *en, uint8_t out[VXL_CACHE_ENTRY_BYTES]);
void vxl_cache_entry_decode(const uint8_t in[VXL_CACHE_ENTRY_BYTES], vxl_cache_entry *en);
/* Checks an entry against the data region [header end, data_end) and its brick's size. */
int vxl_cache_entry_check(const vxl_cache_entry *en, uint64_t brick_bytes, uint32_t texel_bytes, uint64_t data_end);

#endif
