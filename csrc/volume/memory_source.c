/* memory_source.c - a brick source over a copy of a volume in memory: every
 * level held whole. Tests render a streamed volume against the whole one
 * with it (vxl_volume_stream_copy), and every other source is checked
 * against what it serves. */
#include "brick_levels.h"
#include "brick_source.h"
#include "colour_volume.h"
#include "volume.h"
#include "voxlight_dev.h"

#include <stdlib.h>
#include <string.h>

typedef struct memory_ctx {
    uint8_t *levels[VXL_SOURCE_MAX_LEVELS];
} memory_ctx;

static int memory_read(vxl_brick_source *s, uint32_t level, const uint32_t lo[3], const uint32_t size[3], void *out,
                       vxl_err *e)
{
    int rc = vxl_brick_source_check_box(s, level, lo, size, e);
    if (rc) return rc;
    const uint32_t *d = s->level_dims[level];
    const memory_ctx *c = s->ctx;
    vxl_level_copy_box(s->texture_bits, c->levels[level], d, lo, size, out);
    return VXL_OK;
}

static void memory_close(vxl_brick_source *s)
{
    memory_ctx *c = s->ctx;
    if (!c) return;
    for (int k = 0; k < VXL_SOURCE_MAX_LEVELS; k++) free(c->levels[k]);
    free(c);
    s->ctx = NULL;
}

static const vxl_brick_source_ops memory_ops = {memory_read, memory_close};

int vxl_brick_source_from_volume(const vxl_volume *v, uint32_t n_levels, vxl_brick_source **out, vxl_err *e)
{
    *out = NULL;
    if (!v || !v->texels) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "a memory source needs a volume with texels");
    const uint32_t bits = v->texture_bits, bpv = bits / 8;
    vxl_brick_source *s = calloc(1, sizeof *s);
    memory_ctx *c = calloc(1, sizeof *c);
    if (!s || !c) {
        free(s);
        free(c);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for a brick source");
    }
    s->ops = &memory_ops;
    s->ctx = c;
    s->texture_bits = bits;
    vxl_brick_source_set_levels(s, v->dims, n_levels ? n_levels : vxl_source_level_count(v->dims));
    const size_t slice = (size_t)v->dims[0] * v->dims[1] * bpv;
    int rc = VXL_OK;
    if (!(c->levels[0] = malloc(slice * v->dims[2])))
        rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory copying %llu bytes of texels",
                      (unsigned long long)slice * v->dims[2]);
    vxl_level_build lb;
    if (!rc) rc = vxl_level_build_begin(&lb, v->dims, bits, s->n_levels, UINT64_MAX, e);
    if (!rc) {
        memcpy(c->levels[0], v->texels, slice * v->dims[2]);
        for (uint32_t z = 0; z < v->dims[2]; z++) vxl_level_build_slice(&lb, c->levels[0] + slice * z, 0, 0);
        vxl_level_build_finish(&lb);
        s->resident_bytes = slice * v->dims[2];
        for (uint32_t k = 1; k < s->n_levels; k++) {
            c->levels[k] = lb.kept[k];
            lb.kept[k] = NULL;
            s->resident_bytes += (uint64_t)s->level_dims[k][0] * s->level_dims[k][1] * s->level_dims[k][2] * bpv;
        }
        vxl_level_build_free(&lb);
        rc = vxl_brick_source_build_index(s, NULL, e);
    }
    if (rc) {
        vxl_brick_source_free(s);
        return rc;
    }
    *out = s;
    return VXL_OK;
}

int vxl_volume_stream_copy(const vxl_volume *whole, uint32_t n_levels, vxl_volume **out)
{
    if (!out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (!whole || !whole->texels) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "stream copy needs a whole volume");
    if (n_levels > VXL_SOURCE_MAX_LEVELS)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "%u levels: at most %u", n_levels, VXL_SOURCE_MAX_LEVELS);
    vxl_volume *v = malloc(sizeof *v);
    if (!v) return vxl_fail(NULL, VXL_ERR_NO_MEMORY, "out of memory for a volume header");
    *v = *whole;
    v->texels = NULL;
    v->source = NULL;
    v->colour = NULL;
    v->channels = NULL; /* channels do not stream: the copy is of the scalar (docs/channels.md) */
    v->channel_count = 0;
    /* a colour volume streams its scalar; its colour stays whole in memory */
    const size_t colour_bytes = whole->colour ? (size_t)vxl_volume_colour_bytes(whole) : 0;
    if (colour_bytes && !(v->colour = malloc(colour_bytes))) {
        free(v);
        return vxl_fail(NULL, VXL_ERR_NO_MEMORY, "out of memory for the colour of a stream copy");
    }
    if (colour_bytes) memcpy(v->colour, whole->colour, colour_bytes);
    int rc = vxl_brick_source_from_volume(whole, n_levels, &v->source, NULL);
    if (rc) {
        free(v->colour);
        free(v);
        return rc;
    }
    *out = v;
    return VXL_OK;
}
