/* channels.h - the GL side of multi-channel volumes (docs/channels.md): a
 * multi-channel volume's channels as one or two dense 3D textures of up to
 * four 16-bit normalised channels each (R16, RG16, RGB16 or RGBA16) on the
 * scalar's grid, so one ray march samples every channel with one fetch per
 * texture (shaders/lib/channels.glsl). Beside them, per channel, the brick
 * min-max grid (CPU, at set time) and, per frame, its transfer function
 * texture; the drawn channels' occupancies are joined into one distance map
 * (empty-space skipping over the union), re-derived only when a drawn
 * channel's classification key or the set of drawn channels changes.
 * Everything is one budget holding (VXL_HOLD_CHANNELS). Set with the volume
 * (vxl_renderer_set_volume); a volume without channels removes them. Only
 * dense storage draws channels: in the paged modes (bricked, sparse,
 * compressed, streamed) the volume's scalar renders as any volume's, and a
 * frame that draws channels is refused with why (no silent fallback). */
#ifndef VXL_CHANNELS_H
#define VXL_CHANNELS_H

#include <stdint.h>

#include "bricks.h"
#include "frame.h"
#include "gpu.h"
#include "volume.h"

#define VXL_CHANNEL_GROUPS_MAX 2 /* VXL_MAX_CHANNELS / 4 */

typedef struct vxl_channels_state {
    vxl_gpu *gpu;
    uint32_t count, groups;                 /* the volume's channels; 0 without (groups 0 in paged storage) */
    uint32_t storage_mode;                  /* the volume's VXL_STORAGE_*: only dense draws channels */
    GLuint tex[VXL_CHANNEL_GROUPS_MAX];     /* group g: channels 4g.. */
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

/* Wires s to the GL services and registers its bytes with the budget. */
void vxl_channels_init(vxl_channels_state *s, vxl_gpu *g);
/* Whether v's channels can be held beside `storage_bytes` of the volume
 * that comes with it, stored in `storage_mode` (VXL_STORAGE_*, resolved):
 * the texture limit and the budget. Changes nothing; OK for a volume
 * without channels, and for paged storage, which holds the scalar only. */
int vxl_channels_plan(vxl_channels_state *s, const vxl_volume *v, uint32_t storage_mode, uint64_t storage_bytes);
/* Uploads v's channels and builds their min-max grids (after
 * vxl_channels_plan) when storage_mode is dense; in paged storage only
 * what a frame needs to refuse drawing them is kept. A volume without
 * channels removes them. */
int vxl_channels_set(vxl_channels_state *s, const vxl_volume *v, uint32_t storage_mode);
/* The program flags of frame f (the group count in CHANNEL_GROUPS) into
 * *flags: VXL_ERR_STATE when f draws channels of a volume without them or
 * names a channel it does not have; VXL_ERR_INVALID_ARGUMENT, naming why,
 * when the volume is in paged storage. */
int vxl_channels_flags(const vxl_channels_state *s, const vxl_frame *f, uint32_t *flags);
/* Uploads what f's channels need (tables, the union map when f->skip),
 * binds the textures and sets prog's channel uniforms. Nothing when f draws
 * no channels. */
int vxl_channels_prepare(vxl_channels_state *s, const vxl_frame *f, GLuint prog);
void vxl_channels_release(vxl_channels_state *s);

#endif
