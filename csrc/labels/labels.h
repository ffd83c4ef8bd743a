/* labels.h - the GL side of label maps (docs/labels.md): the
 * label volume as an R16UI texture (nearest, never filtered by the
 * hardware: ids are not numbers), its own voxel -> world affine, and the
 * per-label table (65536 ids as a 256x256 RGBA32F texture: colour and
 * alpha, alpha -1 for a hidden or unlisted id) rebuilt only when the
 * frame's table hash changes. shaders/lib/labels.glsl reads both.
 * Beside the ids, one byte a voxel: how far inside its own label the voxel
 * lies (label_margin.h), which the smooth boundaries interpolate.
 * Storage is dense (3 bytes per voxel), charged to the budget as a holding.
 * Beside them, the label bricks (label_bricks.h): where visible labels can
 * be, re-derived with the table, so the ray caster leaps over the rest. */
#ifndef VXL_LABELS_H
#define VXL_LABELS_H

#include <stdint.h>

#include "frame.h"
#include "gpu.h"
#include "label_bricks.h"

#define VXL_LABEL_TABLE_SIDE 256 /* the table is SIDE x 2 SIDE texels: every id in [0, VXL_MAX_LABEL_ID],
                                    its colour in the first SIDE rows, its material in the next */

typedef struct vxl_labels_state {
    vxl_gpu *gpu;
    GLuint volume_tex;        /* R16UI label ids; 0 without a label volume */
    GLuint margin_tex;        /* R8 per voxel: its margin inside its own label (label_margin.h) */
    GLuint table_tex;         /* RGBA32F id -> colour (alpha -1: hidden) */
    uint32_t dims[3];
    double affine[16];        /* the label volume's voxel -> world, column-major */
    uint64_t table_key;       /* the frame key of the table in table_tex */
    vxl_label_bricks bricks;  /* the label volume's ids per brick */
    GLuint bricks_tex;        /* R32UI per brick: distance, uniform, id (label_bricks.h) */
    uint64_t bricks_key;      /* the frame key bricks_tex was derived under */
    int bricks_stale;         /* a new label volume: derive bricks_tex again */
    uint64_t volume_bytes, table_bytes, bytes; /* bytes = the holding (volume_bytes counts bricks_tex too) */
    uint64_t volume_uploads;  /* label volumes uploaded (the dev stats) */
    uint64_t table_uploads;   /* tables uploaded */
} vxl_labels_state;

/* Wires s to the GL services and registers its bytes with the budget. */
void vxl_labels_init(vxl_labels_state *s, vxl_gpu *g);
/* Uploads v's ids (u8, u16, i16 or i32 with integer values in [0,
 * VXL_MAX_LABEL_ID]); NULL removes the label volume. A refused volume
 * (bad type or value, over the budget) leaves the previous one in place. */
int vxl_labels_set(vxl_labels_state *s, const vxl_volume *v);
/* The ray caster's program flags of frame f (LABELS = mode + 1): 0 without labels. */
uint32_t vxl_labels_flags(const vxl_frame *f);
/* Uploads f's table and derives the label bricks when its key changed (or
 * the label volume did), binds the label textures and sets prog's label
 * uniforms; vox_to_world is the intensity volume's affine.
 * VXL_ERR_STATE when f has labels but no label volume is set. Nothing
 * without labels. */
int vxl_labels_prepare(vxl_labels_state *s, const vxl_frame *f, GLuint prog, const double vox_to_world[16]);
void vxl_labels_release(vxl_labels_state *s);

#endif
