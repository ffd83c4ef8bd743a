/* cli_modes.h - the render command's options: --mode,
 * --iso-value, --matcap FILE.png, --ortho and --view AXIS (axis_view.h). */
#ifndef VXL_CLI_MODES_H
#define VXL_CLI_MODES_H

#include <stddef.h>
#include <stdint.h>

#include "voxlight.h"

typedef struct vxl_cli_modes {
    const char *matcap_path;  /* --matcap */
    int ortho;                /* --ortho */
    int view;                 /* --view: axis_view.h's index, VXL_AXIS_VIEW_NONE without */
    float *matcap_rgba;       /* read by vxl_cli_modes_apply */
    vxl_matcap matcap;
} vxl_cli_modes;

void vxl_cli_modes_init(vxl_cli_modes *m);
/* argv[*i] is one of the options: 1 (and *i past its value); a bad value: -1
 * with the message in err; not one of them: 0. */
int vxl_cli_modes_option(int argc, char **argv, int *i, vxl_cli_modes *m, vxl_render_params *p, char *err,
                         size_t err_size);
/* After the volume is loaded and set on r: reads the MatCap, sets the
 * camera for --view / --ortho (p->width x p->height, 0 = 512). 0 on success,
 * else 1 with the message in err. */
int vxl_cli_modes_apply(vxl_cli_modes *m, vxl_renderer *r, const vxl_volume *v, vxl_render_params *p, char *err,
                        size_t err_size);
void vxl_cli_modes_free(vxl_cli_modes *m);

#endif
