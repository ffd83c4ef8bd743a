/* channel_pages.h - a multi-channel volume's channel groups in paged storage
 * (docs/channels.md, "Storage"): cut into the storage's page bricks with
 * their ghost borders (paging.h: the scalar's brick size and page grid),
 * one pool texture per group, every pool with the same slot layout, so one
 * page table translates a position for all groups at once and
 * shaders/lib/channels.glsl reads it through the scalar's page-table
 * lookup (page_entry_at in shaders/lib/common.glsl).
 *
 * A brick where any channel varies (ghost included) has a slot of its own.
 * A brick where every channel is constant shares one slot with every other
 * brick of the same constants (a background: one slot for all of it). So
 * every brick is resident in every paged mode: the scalar's "w = the
 * brick's one value" entry cannot stand for up to eight channels, and a
 * constant slot costs one brick per distinct background. Sparse storage
 * gives a slot only to the varying bricks the drawn channels' tables can
 * see (within the gradient taps' reach), as it pages the scalar; a brick
 * they cannot see reads its channels' minima from a shared slot, which
 * those tables make transparent. Compressed storage keeps the groups
 * uncompressed: its codec is one palette of one scalar per brick.
 * CPU side only until vxl_channel_pages_upload. */
#ifndef VXL_CHANNEL_PAGES_H
#define VXL_CHANNEL_PAGES_H

#include <stdint.h>

#include "paging.h"
#include "storage.h"
#include "volume.h"

/* A group of w (1..4) 16-bit channels as one texture: its internal format
 * and its pixel layout. */
static inline GLenum vxl_channel_group_format(uint32_t w)
{
    static const GLenum f[4] = {GL_R16, GL_RG16, GL_RGB16, GL_RGBA16};
    return f[w - 1];
}
static inline GLenum vxl_channel_group_layout(uint32_t w)
{
    static const GLenum f[4] = {GL_RED, GL_RG, GL_RGB, GL_RGBA};
    return f[w - 1];
}

typedef struct vxl_channel_pages {
    vxl_pages layout;    /* brick, grid; data_index[i] = brick i's slot; n_data = slots in use */
    uint32_t varying;    /* slots 0..varying-1: bricks with data of their own, in brick order */
    uint16_t *constants; /* slot varying + k: channel_count codes of the k-th distinct tuple of minima */
    uint32_t slots[3];   /* the pools' slot layout (each group's pool the same) */
    uint64_t bytes;      /* the pools and the page table on the GL side */
    uint8_t *varies;     /* per brick: some channel varies over it (ghost included) */
    uint16_t *low;       /* per brick, channel_count codes: each channel's minimum there */
} vxl_channel_pages;

/* Cuts v's channels into page bricks of `brick` voxels and lays out the
 * slots within st's texture limit (VXL_ERR_LIMIT when they cannot fit):
 * every varying brick has its own slot, or (sparse) none yet. */
int vxl_channel_pages_plan(vxl_channel_pages *cp, const vxl_volume *v, uint32_t brick, int sparse,
                           const vxl_storage_state *st);
/* Sparse: when need[] (varying bricks a frame can read) marks a brick
 * without a slot of its own, lays the slots out anew for exactly need[]
 * (every other brick on the slot of its channels' minima, which the frame's
 * tables make transparent) and sets *changed (force: in any case);
 * nothing is uploaded. */
int vxl_channel_pages_resident(vxl_channel_pages *cp, uint32_t channels, const uint8_t *need,
                               const vxl_storage_state *st, int force, int *changed);
/* Uploads group g's pool into pools[g] (R16..RGBA16 by its width) for
 * every group of v, and the page table into *page_tex. */
int vxl_channel_pages_upload(const vxl_channel_pages *cp, const vxl_volume *v, vxl_storage_state *st, GLuint *pools,
                             GLuint *page_tex);
void vxl_channel_pages_free(vxl_channel_pages *cp);

#endif
