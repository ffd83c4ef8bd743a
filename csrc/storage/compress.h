/* compress.h - compressed page bricks, CPU side (pure, no GL): each data
 * brick of a vxl_pages (ghost border included) becomes a palette of at most
 * 256 values and one 8-bit code per voxel; value = palette[code]. The
 * palette is the brick's own values when it holds at most 256 distinct ones
 * (exact: every 8-bit brick), else 256 levels fitted by a 1-D Lloyd (k-means)
 * pass. Reconstruction is a table lookup, not linear in the codes, so the
 * codes cannot be filtered by hardware: the GL side decodes the bricks a
 * frame needs into a linear cache first (deferred filtering, paged.c). */
#ifndef VXL_COMPRESS_H
#define VXL_COMPRESS_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "paging.h"

#define VXL_PALETTE_SIZE 256

typedef struct vxl_compressed {
    uint32_t n;          /* bricks: the data bricks of the pages, in data order */
    uint32_t voxels;     /* voxels per brick, ghost included */
    uint32_t exact;      /* bricks whose palette holds every value exactly */
    float *palette;      /* n rows of 256 normalised values (what the sampler returns); unused entries repeat the last */
    uint8_t *codes;      /* n bricks of codes, laid out as vxl_pages.data */
} vxl_compressed;

int vxl_compress_pages(vxl_compressed *c, const vxl_pages *pg, vxl_err *e);
void vxl_compressed_free(vxl_compressed *c);

/* The normalised value voxel i of data brick k decodes to. */
static inline float vxl_compressed_value(const vxl_compressed *c, uint32_t k, size_t i)
{
    return c->palette[(size_t)k * VXL_PALETTE_SIZE + c->codes[(size_t)k * c->voxels + i]];
}

#endif
