/* overlays.h - the GL side of overlays (docs/overlays.md): up to
 * VXL_MAX_OVERLAYS more volumes sampled in the base volume's ray march. Each
 * slot holds its volume as one dense texture of its own texels (R8/R16
 * normalised or R32F, filtered linearly: nearest is a texelFetch, cubic 8
 * trilinear fetches), its affine and value range, and its brick min-max grid
 * (computed on the CPU when the slot is set). Per frame, each listed
 * overlay's transfer function texture and brick occupancy (with its
 * distance map) are re-derived only when its classification key changes.
 * Everything is charged to the budget as one holding (VXL_HOLD_OVERLAYS).
 * shaders/lib/overlays.glsl reads it all. */
#ifndef VXL_OVERLAYS_H
#define VXL_OVERLAYS_H

#include <stdint.h>

#include "bricks.h"
#include "frame.h"
#include "gpu.h"
#include "volume.h"

typedef struct vxl_overlay_slot {
    GLuint tex;                 /* the volume's texels; 0: an empty slot */
    GLuint tf_tex;              /* 1D RGBA32F transfer function of the last frame that drew this slot */
    GLuint distance_tex;        /* R8UI Chebyshev distance to the nearest occupied brick */
    vxl_volume_geom geom;       /* dims, affine (voxel -> world), value mapping */
    vxl_bricks bricks;          /* min-max per brick (apron 1), occupancy under tf_key */
    uint64_t tf_key;            /* key of the table in tf_tex (0: none) */
    uint64_t distance_key;      /* occupancy key + interpolation of the map in distance_tex */
    uint64_t volume_bytes, tf_bytes, distance_bytes;
} vxl_overlay_slot;

typedef struct vxl_overlays_state {
    vxl_gpu *gpu;
    vxl_overlay_slot slots[VXL_MAX_OVERLAYS];
    uint64_t bytes;             /* the holding: every slot's textures */
    uint64_t volume_uploads;    /* overlay volumes uploaded */
    uint64_t table_uploads;     /* transfer functions uploaded */
} vxl_overlays_state;

/* Wires s to the GL services and registers its bytes with the budget. */
void vxl_overlays_init(vxl_overlays_state *s, vxl_gpu *g);
/* Puts v in slot (< VXL_MAX_OVERLAYS); NULL empties it. A refused volume
 * (streamed, bad affine, over the budget) leaves the slot as it was. */
int vxl_overlays_set(vxl_overlays_state *s, uint32_t slot, const vxl_volume *v);
/* geoms[k]: slot k's geometry, NULL when empty (vxl_frame_resolve_overlays). */
void vxl_overlays_geoms(const vxl_overlays_state *s, const vxl_volume_geom *geoms[VXL_MAX_OVERLAYS]);
/* The ray caster's program flags of frame f: the overlay count in OVERLAYS. */
uint32_t vxl_overlays_flags(const vxl_frame *f);
/* Uploads what f's overlays need (tables, occupancy when f->skip), binds
 * their textures and sets prog's overlay uniforms. Nothing without overlays. */
int vxl_overlays_prepare(vxl_overlays_state *s, const vxl_frame *f, GLuint prog);
void vxl_overlays_release(vxl_overlays_state *s);

#endif
