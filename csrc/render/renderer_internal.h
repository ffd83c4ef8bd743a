/* renderer_internal.h - the renderer's state. Everything GL lives on the
 * renderer's own thread; API functions package their arguments into a job. */
#ifndef VXL_RENDERER_INTERNAL_H
#define VXL_RENDERER_INTERNAL_H

#include <stdint.h>

#include "classification.h"
#include "channels.h"
#include "colour.h"
#include "context.h"
#include "cutaway.h"
#include "error.h"
#include "frame.h"
#include "gl_thread.h"
#include "gpu.h"
#include "gradients.h"
#include "illumination.h"
#include "labels.h"
#include "matcap.h"
#include "modes.h"
#include "overlays.h"
#include "path.h"
#include "skipping.h"
#include "storage.h"
#include "voxlight.h"

#define VXL_MAX_SAMPLES_PER_RAY 16384 /* bounds every ray, whatever the step */
#define VXL_MAX_IMAGE_SIDE 16384

/* The renderer composes one struct per subsystem. Each subsystem receives
 * the GL services (gpu) and the lower stages it reads (the storage), never
 * the renderer, and releases only its own state; renderer.c wires them
 * (vxl_*_init) and registers each with the budget and, for the derived
 * volumes, with the storage. */
struct vxl_renderer {
    vxl_gl_thread thread;
    vxl_context ctx;
    vxl_gpu gpu;                             /* gpu.h: function table, error, programs, budget */
    vxl_storage_state storage;               /* storage.h: the volume on the GL side (storage_*.c, paged.c) */
    vxl_gradient_state gradients;            /* gradients.h */
    vxl_bspline_state bspline;
    vxl_skipping_state skipping;             /* skipping.h */
    vxl_classification_state classification; /* classification.h */
    vxl_illumination_state illumination;     /* illumination.h: shadows and occlusion */
    vxl_cut_state cut;                       /* cutaway.h: clip planes, crop box, cutter layers */
    vxl_modes_state modes;                   /* modes.h: render modes (min-max grid texture) */
    vxl_matcap_state matcap;                 /* matcap.h: MatCap image */
    vxl_labels_state labels;                 /* labels.h: label volume and table */
    vxl_overlays_state overlays;             /* overlays.h: overlay volumes */
    vxl_colour_state colour;                 /* colour.h: a colour volume's own colour (RGB8) */
    vxl_path_state path;                     /* path.h: the PATH model's majorant grid */
    vxl_channels_state channels;             /* channels.h: a multi-channel volume's channels (16-bit, dense) */

    GLuint vao, fbo, color_tex, depth_tex, scene_depth_tex, tf_tex;
    uint32_t fb_w, fb_h;
    vxl_render_stats stats;    /* of the last successful frame */
};

/* render.c helpers shared with probe.c */
int vxl_bind_volume_textures(vxl_renderer *r, GLuint prog, uint32_t filter, int store);
/* the frame's transfer function on VXL_TF_UNIT (also scene_transmittance.c) */
void vxl_upload_tf(vxl_renderer *r, const vxl_frame *f);

#endif
