/* colour.h - the GL side of colour volumes (docs/colour.md): the voxels'
 * own colour as an RGB8 3D texture on the scalar volume's grid, which the
 * ray caster samples at the same voxel position as the scalar and uses in
 * place of the transfer function's colour (shaders/lib/colour.glsl). It is
 * dense whatever the scalar's storage (3 bytes a voxel, charged to the
 * budget as a holding), so every storage mode reads it the same way.
 * Set with the volume (vxl_renderer_set_volume); a grey volume removes it. */
#ifndef VXL_COLOUR_H
#define VXL_COLOUR_H

#include <stdint.h>

#include "frame.h"
#include "gpu.h"
#include "volume.h"

typedef struct vxl_colour_state {
    vxl_gpu *gpu;
    GLuint tex;          /* RGB8; 0 without a colour volume */
    uint64_t bytes;      /* the holding */
    uint64_t uploads;    /* colour textures uploaded */
} vxl_colour_state;

/* Wires s to the GL services and registers its bytes with the budget. */
void vxl_colour_init(vxl_colour_state *s, vxl_gpu *g);
/* Whether v's colour can be held beside `storage_bytes` of the volume that
 * comes with it (the texture limit, the budget with what a new volume does
 * not release: labels, overlays, ...); changes nothing. OK for grey v. */
int vxl_colour_plan(vxl_colour_state *s, const vxl_volume *v, uint64_t storage_bytes);
/* Uploads v's colour (after vxl_colour_plan); a grey v removes the texture. */
int vxl_colour_set(vxl_colour_state *s, const vxl_volume *v);
/* The program flag of frame f (VXL_FLAG_DATA_COLOUR or 0) into *flags:
 * VXL_ERR_STATE when f asks for the data's colour of a grey volume. */
int vxl_colour_flags(const vxl_colour_state *s, const vxl_frame *f, uint32_t *flags);
/* Binds the colour texture for prog when flags has VXL_FLAG_DATA_COLOUR. */
void vxl_colour_bind(vxl_colour_state *s, uint32_t flags, GLuint prog);
void vxl_colour_release(vxl_colour_state *s);

#endif
