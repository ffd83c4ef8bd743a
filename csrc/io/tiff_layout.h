/* tiff_layout.h - whether a multi-page TIFF can be read by offset,
 * decided by walking its directories in this process (no libtiff, no
 * OpenImageIO): classic TIFF and BigTIFF, either byte order. A file streams
 * when every page is one uncompressed, untiled, single-sample image of the
 * same size and pixel type, 8/16/32-bit integer or 32/64-bit float (as the
 * whole read, image_stack.cpp, maps them; half floats are not streamed), and
 * each page's strips follow each other in the file, so a page is one run of
 * bytes. Anything else is read whole through the OpenImageIO helper, as
 * before. */
#ifndef VXL_TIFF_LAYOUT_H
#define VXL_TIFF_LAYOUT_H

#include <stdint.h>

#include "error.h"
#include "raw_layout.h"
#include "volume.h"

typedef struct vxl_tiff_layout {
    uint32_t dims[3];        /* width, height, pages */
    uint32_t dtype;          /* VXL_DTYPE_* of the pixels */
    int swap;                /* 1: the file's byte order is not the host's */
    uint64_t *page_offsets;  /* dims[2] entries (malloc'd): where each page's pixels start; NULL: cannot stream */
    uint64_t file_size;
    char why[160];           /* when it cannot stream: what the file is, for "streaming is not available for
                                ...", e.g. "compressed TIFF (page 1: compression 5)"; empty when the reason is a
                                limit the whole read reports itself (too many pages) */
} vxl_tiff_layout;

/* Walks path's directories (at most opt->max_dim pages). VXL_OK: streamable
 * when t->page_offsets is set, else t->why says why not. VXL_ERR_FORMAT
 * naming the file when a directory or a page's pixels lie past the end of
 * the file (a truncated file); VXL_ERR_IO when it cannot be opened. Free
 * with vxl_tiff_layout_free in every case. */
int vxl_tiff_layout_probe(const char *path, const vxl_load_options *opt, vxl_tiff_layout *t, vxl_err *e);

void vxl_tiff_layout_free(vxl_tiff_layout *t);

/* The raw layout a streamable t reads through (raw_source.h): its page table
 * (l->slice_offsets points into t, which must outlive l's use), rows top
 * first, and the geometry of the whole read: spacing from
 * vxl_load_voxel_size, affine diag(spacing). */
int vxl_tiff_raw_layout(const char *path, const vxl_tiff_layout *t, const vxl_load_options *opt, vxl_raw_layout *l,
                        vxl_err *e);

#endif
