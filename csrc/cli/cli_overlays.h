/* cli_overlays.h - the render command's overlay options:
 * --overlay FILE[:PRESET][:LO:HI] (repeatable, up to VXL_MAX_OVERLAYS),
 * and after each of them --overlay-blend over|add|max and
 * --overlay-opacity X for that overlay. Each file goes into its own slot
 * with vxl_renderer_set_overlay and params.overlays lists them, so the base
 * volume and the overlays are composited along each ray (docs/overlays.md). */
#ifndef VXL_CLI_OVERLAYS_H
#define VXL_CLI_OVERLAYS_H

#include <stddef.h>
#include <stdint.h>

#include "voxlight.h"

typedef struct vxl_cli_overlays {
    uint32_t count;
    char path[VXL_MAX_OVERLAYS][1024];           /* the FILE part of each --overlay */
    vxl_overlay_style style[VXL_MAX_OVERLAYS];   /* what params.overlays points at */
} vxl_cli_overlays;

void vxl_cli_overlays_init(vxl_cli_overlays *o);
/* argv[*i] is one of the options: 1 (and *i past its value); a bad value: -1
 * with the message in err; not one of them: 0. */
int vxl_cli_overlays_option(int argc, char **argv, int *i, vxl_cli_overlays *o, char *err, size_t err_size);
/* Loads every overlay onto r and points p->overlays at their styles (each
 * lit unless p->shading_off). 0, or 1 with the message in err naming the
 * file. Nothing without --overlay. */
int vxl_cli_overlays_apply(vxl_cli_overlays *o, vxl_renderer *r, vxl_render_params *p, char *err, size_t err_size);

#endif
