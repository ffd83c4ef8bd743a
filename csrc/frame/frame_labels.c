/* frame_labels.c - params.labels checked into f->labels (frame.h).
 * The table is read where the caller keeps it (the frame lives for one
 * render call); its hash keys the GL side's table texture, so hiding or
 * recolouring a label re-uploads only that table. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "frame.h"
#include "hash.h"

int vxl_frame_resolve_labels(vxl_frame *f, const vxl_render_params *p, vxl_err *e)
{
    const vxl_label_style *s = p->labels;
    if (!s) return VXL_OK;
    if (s->mode >= VXL_LABEL_MODE_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown label mode %u (0 surface, 1 mask, 2 tint)", s->mode);
    if (s->reserved) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "labels.reserved is %u: it must be 0", s->reserved);
    uint32_t boundary = VXL_LABEL_BOUNDARY_SMOOTH;
    if (s->struct_size >= offsetof(vxl_label_style, reserved2) + sizeof s->reserved2) {
        if (s->boundary > VXL_LABEL_BOUNDARY_VOXELS)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown label boundary %u (0 smooth, 1 voxels)", s->boundary);
        if (s->reserved2)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "labels.reserved2 is %u: it must be 0", s->reserved2);
        boundary = s->boundary;
    }
    if (s->entry_count && !s->entries)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "labels.entries is NULL with entry_count %u", s->entry_count);
    if (s->entry_count > VXL_MAX_LABEL_ID + 1u)
        return vxl_fail(e, VXL_ERR_LIMIT, "labels.entry_count %u exceeds %u", s->entry_count, VXL_MAX_LABEL_ID + 1u);
    if (f->technique != VXL_TECHNIQUE_RAYCAST || f->mode != VXL_MODE_DVR)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "labels need the ray caster's DVR mode (technique 0, mode dvr)");
    uint32_t stride = s->entry_count ? s->entries[0].struct_size : 0;
    if (stride == 0) stride = sizeof(vxl_label_entry);
    if (stride < offsetof(vxl_label_entry, visible) + sizeof(uint32_t))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "labels.entries[0].struct_size %u is too small", stride);
    /* one bit per possible id finds duplicates in one pass */
    uint8_t *seen = calloc((VXL_MAX_LABEL_ID + 1) / 8, 1);
    if (!seen) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory checking the labels");
    uint64_t h = 1469598103934665603ull;
    int rc = VXL_OK;
    for (uint32_t i = 0; i < s->entry_count && !rc; i++) {
        const vxl_label_entry *en = (const vxl_label_entry *)((const char *)s->entries + (size_t)i * stride);
        if (en->id < 0 || en->id > VXL_MAX_LABEL_ID) {
            rc = vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "labels.entries[%u].id %d is outside [0, %d]", i, en->id,
                          VXL_MAX_LABEL_ID);
            break;
        }
        for (int c = 0; c < 4; c++)
            if (!(en->color[c] >= 0.0f && en->color[c] <= 1.0f)) {
                rc = vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                              "labels.entries[%u] (id %d): color[%d] = %g is not in [0, 1]", i, en->id, c,
                              (double)en->color[c]);
                break;
            }
        if (rc) break;
        if (seen[en->id >> 3] & (1u << (en->id & 7))) {
            rc = vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "labels.entries[%u]: id %d is listed twice", i, en->id);
            break;
        }
        seen[en->id >> 3] |= (uint8_t)(1u << (en->id & 7));
        const float *m = vxl_label_material(en, stride);
        if (m && !(m[0] >= 0 && m[1] >= 0 && m[2] >= 0 && m[3] > 0 && m[0] < 1e6f && m[1] < 1e6f && m[2] < 1e6f &&
                   m[3] < 1e6f)) {
            rc = vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                          "labels.entries[%u] (id %d): material (%g, %g, %g, %g) needs ambient, diffuse, specular "
                          ">= 0 and shininess > 0, all finite",
                          i, en->id, (double)m[0], (double)m[1], (double)m[2], (double)m[3]);
            break;
        }
        if (m) h = vxl_fnv(h, m, 4 * sizeof(float));
        const uint32_t vis = en->visible != 0;
        h = vxl_fnv(h, &en->id, sizeof en->id);
        h = vxl_fnv(h, en->color, sizeof en->color);
        h = vxl_fnv(h, &vis, sizeof vis);
    }
    free(seen);
    if (rc) return rc;
    f->labels.on = 1;
    f->labels.mode = s->mode;
    f->labels.voxels = boundary == VXL_LABEL_BOUNDARY_VOXELS;
    f->labels.entries = s->entries;
    f->labels.count = s->entry_count;
    f->labels.stride = stride;
    f->labels.key = h;
    /* Correct first: the skipping grid and the screen bound follow the
     * intensity volume, which says nothing of where the labels are. MASK and
     * TINT only take opacity away, so their skipping stays valid. */
    if (s->mode == VXL_LABEL_MODE_SURFACE) f->skip = 0;
    return VXL_OK;
}
