/* scenes.h - render parameters the tests share, without anything of one
 * OS, so the Windows build's programs (tests/render_scene.c) use them too. */
#ifndef VXL_TEST_SCENES_H
#define VXL_TEST_SCENES_H

#include <string.h>

#include "voxlight.h"

static inline vxl_render_params default_params(uint32_t w, uint32_t h)
{
    vxl_render_params p;
    memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.width = w;
    p.height = h;
    return p;
}

/* The phantom scene the skipping and storage tests share: the bone preset
 * over the window [0.35, 0.75] (the phantoms' 0.5 iso-region), seen from
 * azimuth 20, elevation 25, with the given filter and classification. */
static inline vxl_render_params phantom_scene(uint32_t w, uint32_t h, uint32_t filter, uint32_t mode)
{
    vxl_render_params p = default_params(w, h);
    p.filter = filter;
    p.classify = mode;
    p.preset = VXL_PRESET_BONE;
    p.has_window = 1;
    p.window_low = 0.35f;
    p.window_high = 0.75f;
    p.azimuth_deg = 20;
    p.elevation_deg = 25;
    return p;
}

#endif
