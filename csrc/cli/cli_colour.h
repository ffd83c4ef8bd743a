/* cli_colour.h - colour volumes in the command-line tool (docs/colour.md):
 * --color-source auto|data|tf (render), --opacity-source
 * luminance|alpha|channel:N (render and info: it picks the scalar when the
 * file is read), --color-space display|linear (render: what the colours
 * mean, docs/physical_model.md) and the components line of `info`. */
#ifndef VXL_CLI_COLOUR_H
#define VXL_CLI_COLOUR_H

#include <stddef.h>
#include <stdio.h>

#include "voxlight.h"

/* argv[*i] is one of the options: 1 (and *i past its value); a bad value: -1
 * with the message in err; not one of them: 0. p may be NULL (info: no
 * --color-source). */
int vxl_cli_colour_option(int argc, char **argv, int *i, vxl_render_params *p, vxl_load_options *lo, char *err,
                          size_t err_size);
/* Scene-linear colour (--color-space linear) is written as it is to an
 * EXR, and encoded as sRGB (the straight colour, clamped to [0, 1]) for a
 * PNG, which holds display colour; display colour is written as it is. */
void vxl_cli_colour_for_output(const vxl_render_params *p, const char *output, float *rgba, size_t pixels);
/* `info`: the components, and for colour what the opacity came from. */
void vxl_cli_colour_print_info(const vxl_volume_info *in, FILE *out);

#endif
