/* budget.h - the renderer's memory budget on the GL side: one accountant,
 * one formula, one message. Every allocation of GL memory asks it first.
 *
 * The formula: `bytes` asked for by holder `who` fit when
 *     bytes + what every holder that `who` does not replace holds now <= limit.
 * The storage (the volume texture, or the brick pool with its page table
 * and compressed codes) replaces everything: a new volume releases every
 * derived volume, and a sparse frame's ask already includes what that frame
 * derives; so the storage asks with held NULL. A derived volume (gradients,
 * B-spline coefficients, the classified volume) replaces only itself: the
 * others stay resident beside it and are charged (holdings.h: each holder
 * registers how to read its bytes). This file knows no renderer, so the
 * storage can ask without depending on what is derived from it. */
#ifndef VXL_BUDGET_H
#define VXL_BUDGET_H

#include <stdarg.h>
#include <stdint.h>

#include "error.h"
#include "voxlight.h"

typedef enum vxl_holder {
    VXL_HOLD_STORAGE,    /* volume texture, or brick pool + page table + codes and palettes */
    VXL_HOLD_GRADIENTS,  /* precomputed gradients (texture, or pool + page table) */
    VXL_HOLD_BSPLINE,    /* cubic B-spline coefficients (texture, or pool + page table) */
    VXL_HOLD_CLASSIFIED, /* the pre-classified volume (RGBA8) */
    VXL_HOLD_ILLUMINATION, /* the illumination volumes: extinction, the lights' transmittance, occlusion */
    VXL_HOLD_SCENE_SHADOWS, /* the lights' shadow maps of the scene's occluders, transmittance images */
    VXL_HOLD_MATCAP,     /* the MatCap image */
    VXL_HOLD_MODE_BRICKS, /* the brick min-max grid as a texture (MIP, MinIP, ISO skipping) */
    VXL_HOLD_CUTAWAY,    /* the cutters' per-pixel crossing layers and their vertex buffer */
    VXL_HOLD_LABELS,     /* the label volume (R16UI, dense) and the per-label table */
    VXL_HOLD_OVERLAYS,   /* the overlay volumes (dense), their transfer functions and skipping maps */
    VXL_HOLD_COLOUR,     /* a colour volume's own colour (RGB8, dense, 3 bytes a voxel: colour/colour.c) */
    VXL_HOLD_PATH_MAJORANT, /* the PATH model's extinction majorant per skipping brick (R32F, render/path.c) */
    VXL_HOLD_CHANNELS,   /* a multi-channel volume's channels (16 bits each, dense), tables and union skip map: channels/channels.c */
    VXL_HOLD_COUNT
} vxl_holder;

/* bytes plus what the holders `who` does not replace hold (held: bytes per
 * holder now, NULL for none); UINT64_MAX when that overflows. */
uint64_t vxl_budget_in_all(const uint64_t *held, vxl_holder who, uint64_t bytes);
/* Whether `bytes` for `who` fit within limit (a question: no error set). */
int vxl_budget_fits(uint64_t limit, const uint64_t *held, vxl_holder who, uint64_t bytes);
/* The same question, answered VXL_OK or VXL_ERR_LIMIT with the one message
 * every refusal uses: "<what>: X MiB (Y MiB in all with what the renderer
 * holds), over the renderer's memory budget of Z MiB<hint>". what is a
 * printf format; hint (may be NULL) follows as it is. */
int vxl_budget_ask(uint64_t limit, const uint64_t *held, vxl_holder who, uint64_t bytes, vxl_err *e, const char *hint,
                   const char *what, ...) __attribute__((format(printf, 7, 8)));
int vxl_budget_vask(uint64_t limit, const uint64_t *held, vxl_holder who, uint64_t bytes, vxl_err *e, const char *hint,
                    const char *what, va_list ap) __attribute__((format(printf, 7, 0)));

#endif
