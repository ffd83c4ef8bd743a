/* source_probe.c - test hooks (voxlight_dev.h) that hold a streamed volume
 * against a whole one: its levels against the LOD fallback's downsampling
 * (lod.c) and its index against the skipping grid's CPU copy (paging.c).
 * Here, in storage/, because both of those live here. */
#include "lod.h"
#include "paging.h"
#include "voxlight_dev.h"

#include <stdlib.h>
#include <string.h>

int vxl_volume_read_level(const vxl_volume *v, uint32_t level, const uint32_t lo[3], const uint32_t size[3],
                          void *out)
{
    if (!v || !lo || !size || !out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "volume, box or out is NULL");
    if (v->source) {
        vxl_err e = {0};
        int rc = v->source->ops->read(v->source, level, lo, size, out, &e);
        if (rc) vxl_publish_error(&e);
        return rc;
    }
    if (level >= VXL_SOURCE_MAX_LEVELS) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "level %u", level);
    const vxl_volume *cur = v;
    vxl_volume *owned = NULL;
    for (uint32_t k = 0; k < level; k++) {
        vxl_volume *next = NULL;
        vxl_err e = {0};
        int rc = vxl_volume_downsample2(cur, &next, &e);
        vxl_volume_destroy(owned);
        if (rc) {
            vxl_publish_error(&e);
            return rc;
        }
        cur = owned = next;
    }
    for (int a = 0; a < 3; a++)
        if (size[a] == 0 || lo[a] >= cur->dims[a] || size[a] > cur->dims[a] - lo[a]) {
            vxl_volume_destroy(owned);
            return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "box outside level %u", level);
        }
    const size_t bpv = cur->texture_bits / 8, run = (size_t)size[0] * bpv;
    uint8_t *o = out;
    for (uint32_t z = 0; z < size[2]; z++)
        for (uint32_t y = 0; y < size[1]; y++, o += run)
            memcpy(o, (const uint8_t *)cur->texels +
                          bpv * (lo[0] + (size_t)cur->dims[0] * ((lo[1] + y) + (size_t)cur->dims[1] * (lo[2] + z))),
                   run);
    vxl_volume_destroy(owned);
    return VXL_OK;
}

int vxl_volume_brick_index(const vxl_volume *v, uint32_t *brick, uint32_t dims[3], float *out, size_t max_floats)
{
    if (!v || !brick || !dims) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "volume, brick or dims is NULL");
    vxl_bricks b;
    memset(&b, 0, sizeof b);
    const float *mm;
    if (v->source) {
        *brick = v->source->index_brick;
        memcpy(dims, v->source->index_dims, 3 * sizeof *dims);
        mm = v->source->minmax;
    } else {
        if (*brick < 1) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "brick must be >= 1");
        vxl_err e = {0};
        if (vxl_bricks_minmax_cpu(&b, v, *brick, &e)) {
            vxl_publish_error(&e);
            return e.code;
        }
        memcpy(dims, b.dims, 3 * sizeof *dims);
        mm = b.minmax;
    }
    const size_t n = (size_t)dims[0] * dims[1] * dims[2] * 2;
    if (out) memcpy(out, mm, (n < max_floats ? n : max_floats) * sizeof *out);
    free(b.minmax);
    return VXL_OK;
}
