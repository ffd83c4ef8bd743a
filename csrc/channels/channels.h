/* channels.h - the GL side of multi-channel volumes (docs/channels.md): a
 * multi-channel volume's channels in groups of up to four 16-bit normalised
 * channels (R16, RG16, RGB16 or RGBA16) on the scalar's grid, so one ray
 * march samples every channel with one fetch per group
 * (shaders/lib/channels.glsl). Stored as the scalar is: dense storage holds
 * each group as one 3D texture; the paged modes (bricked, sparse,
 * compressed) hold each group as a pool of the scalar's page bricks behind
 * one page table (channel_pages.h); sparse storage gives a brick its own
 * slot only when a frame's drawn channels can see it. Beside them, per channel, the brick
 * min-max grid (CPU, planned with the volume) and, per frame, its transfer
 * function texture; the drawn channels' occupancies are joined into one
 * distance map (empty-space skipping over the union), re-derived only when
 * a drawn channel's classification key or the set of drawn channels
 * changes. Everything is one budget holding (VXL_HOLD_CHANNELS). Set with
 * the volume (vxl_renderer_set_volume); a volume without channels removes
 * them. Streamed volumes have none (their loaders read channels whole). */
#ifndef VXL_CHANNELS_H
#define VXL_CHANNELS_H

#include <stdint.h>

#include "bricks.h"
#include "channel_pages.h"
#include "frame.h"
#include "gpu.h"
#include "storage.h"
#include "volume.h"

#define VXL_CHANNEL_GROUPS_MAX 2 /* VXL_MAX_CHANNELS / 4 */

/* What vxl_channels_plan prepares on the CPU before the renderer lets go
 * of its current volume, and vxl_channels_set uploads. */
typedef struct vxl_channel_plan {
    vxl_bricks bricks[VXL_MAX_CHANNELS]; /* per channel its brick min-max (apron 1) */
    vxl_channel_pages pages;             /* paged storage: the groups' bricks (layout.brick 0: dense) */
    uint64_t bytes;                      /* the channels' textures or pools on the GL side */
} vxl_channel_plan;
void vxl_channel_plan_free(vxl_channel_plan *p);

typedef struct vxl_channels_state {
    vxl_gpu *gpu;
    vxl_storage_state *storage;             /* the scalar's storage: its pool layout and page-table upload */
    uint32_t count, groups;                 /* the volume's channels; 0 without */
    GLuint tex[VXL_CHANNEL_GROUPS_MAX];     /* group g (channels 4g..): its texture, or (paged) its pool */
    GLuint page_tex;                        /* paged: the page table every group's pool shares; 0 dense */
    uint32_t pool_dims[3];                  /* paged: each pool's size in texels */
    /* Sparse storage: the pages, re-laid out when a frame can see a brick
     * without its own slot, and the channels kept on the CPU to fill them
     * (a volume of the set one's dims and channel count, its own copy). */
    vxl_channel_pages pages;
    vxl_volume kept;
    int stale;                              /* the pools failed to follow the pages: lay them out anew */
    GLuint tf_tex[VXL_MAX_CHANNELS];        /* channel c's table of the last frame that drew it */
    uint64_t tf_key[VXL_MAX_CHANNELS];
    uint64_t tf_entry_bytes[VXL_MAX_CHANNELS];
    vxl_volume_geom geom[VXL_MAX_CHANNELS]; /* each channel's value mapping (the volume's grid and affine) */
    vxl_bricks bricks[VXL_MAX_CHANNELS];    /* min-max per brick (apron 1), occupancy under its table */
    GLuint distance_tex;                    /* R8UI union distance map */
    uint64_t distance_key;                  /* the drawn channels and their keys */
    uint32_t occupied, bricks_total;        /* of the union map, for the frame's statistics */
    uint64_t volume_bytes, tf_bytes, distance_bytes;
    uint64_t bytes;                         /* the holding */
    uint64_t uploads;                       /* channel textures uploaded */
} vxl_channels_state;

/* Wires s to the GL services and the scalar's storage, and registers its
 * bytes with the budget. */
void vxl_channels_init(vxl_channels_state *s, vxl_gpu *g, vxl_storage_state *storage);
/* Prepares v's channels to be held as the storage plan sp holds the
 * scalar (dense textures, or pools of sp's page bricks), and asks the
 * budget for them beside sp->bytes of the scalar and what a new volume
 * keeps: refuses before anything is allocated on the GL side. Changes
 * nothing in s; *out is empty for a volume without channels. */
int vxl_channels_plan(vxl_channels_state *s, const vxl_volume *v, const vxl_storage_plan *sp, vxl_channel_plan *out);
/* Uploads v's channels as planned, taking the plan's min-max grids (the
 * caller frees the plan after). A volume without channels removes them. */
int vxl_channels_set(vxl_channels_state *s, const vxl_volume *v, vxl_channel_plan *plan);
/* The program flags of frame f (the group count in CHANNEL_GROUPS) into
 * *flags: VXL_ERR_STATE when f draws channels of a volume without them or
 * names a channel it does not have. */
int vxl_channels_flags(const vxl_channels_state *s, const vxl_frame *f, uint32_t *flags);
/* Uploads what f's channels need (tables, in sparse storage the bricks the
 * drawn channels can see, the union map when f->skip),
 * binds the textures and sets prog's channel uniforms. Nothing when f draws
 * no channels. */
int vxl_channels_prepare(vxl_channels_state *s, const vxl_frame *f, GLuint prog);
void vxl_channels_release(vxl_channels_state *s);

#endif
