/* raw_layout.h - where a file's voxels lie and how they read:
 * what the NIfTI, NRRD and MetaImage headers say, handed from the loader
 * that parsed the header to the brick source that reads the voxels (by
 * offset, raw_source.c) or streams them once into a bricked cache
 * (brick_cache.c). The loaders fill it; the sources never parse headers. */
#ifndef VXL_RAW_LAYOUT_H
#define VXL_RAW_LAYOUT_H

#include <stdint.h>

typedef struct vxl_raw_layout {
    char path[4096];        /* the file holding the voxels (.img of a .hdr pair, the detached data file) */
    uint64_t offset;        /* byte offset of the first voxel of the chosen frame, in the uncompressed stream */
    int compressed;         /* 1: gzip/zlib stream (no seeking: a bricked cache), 0: raw bytes */
    uint32_t dims[3];
    uint32_t dtype;         /* VXL_DTYPE_* stored in the file */
    int swap;               /* 1: the file's byte order is not the host's */
    double slope, inter;    /* value = raw * slope + inter (slope 0 already replaced by 1) */
    double spacing[3];
    double affine[16];      /* voxel -> world, column-major */
    uint32_t affine_source; /* as vxl_volume.affine_source */
    uint32_t nifti_version;
    uint32_t frame_count, frame;
    uint64_t file_size;     /* bytes of `path` on disk (the cache key, and the check against what the
                               header claims: a file shorter than its voxels is an error naming it) */
    int64_t mtime_ns;       /* the cache key */
    uint64_t header_hash;   /* hash of the header bytes: the cache key */
    /* Slices that do not follow each other (a multi-page TIFF, tiff_layout.h):
     * dims[2] byte offsets, slice z's first stored byte at slice_offsets[z]
     * (owned by the loader; vxl_raw_source_open copies it). NULL: slice z at
     * offset + z * slice bytes, as NIfTI, NRRD and MetaImage store them. */
    const uint64_t *slice_offsets;
    int rows_top_first;     /* 1: a slice stores its top row (voxel y = dims[1]-1) first, as images do */
    uint64_t compressed_start; /* compressed: file byte where the gzip/zlib stream begins (0: the file's start;
                                  after the text header of attached NRRD/MetaImage data); offset counts from
                                  the start of what it inflates to */
} vxl_raw_layout;

#endif
