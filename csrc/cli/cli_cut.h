/* cli_cut.h - the render command's cutaway options:
 * --clip-plane A,B,C,D[,T] (repeatable), --crop X0:X1,Y0:Y1,Z0:Z1 and
 * --no-caps, into a vxl_cutaway (docs/cutaways.md). */
#ifndef VXL_CLI_CUT_H
#define VXL_CLI_CUT_H

#include <stddef.h>
#include <stdint.h>

#include "voxlight.h"

typedef struct vxl_cli_cut {
    vxl_cutaway cut;
    int has_crop;            /* --crop given: cut.crop_box is filled in by vxl_cli_cut_apply */
    long crop[3][2];         /* voxel indices, inclusive */
    int any;                 /* any of the options given */
} vxl_cli_cut;

void vxl_cli_cut_init(vxl_cli_cut *c);
/* argv[*i] is one of the options: 1 (and *i past its value); a bad value: -1
 * with the message in err; not one of them: 0. */
int vxl_cli_cut_option(int argc, char **argv, int *i, vxl_cli_cut *c, char *err, size_t err_size);
/* After the volume is loaded: the crop box from its dimensions and affine,
 * and p->cutaway when an option was given. 0, or 1 with the message in err. */
int vxl_cli_cut_apply(vxl_cli_cut *c, const vxl_volume *v, vxl_render_params *p, char *err, size_t err_size);

#endif
