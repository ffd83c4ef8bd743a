/* cli_path.h - the render command's options of the PATH shading model
 * (--shading path): --samples N, --sample-offset K, --bounces B, --seed S,
 * each the vxl_render_params field of the same meaning. */
#ifndef VXL_CLI_PATH_H
#define VXL_CLI_PATH_H

#include <stddef.h>

#include "voxlight.h"

/* argv[*i] is one of the options: 1 (and *i past its value); a bad value: -1
 * with the message in err; not one of them: 0. */
int vxl_cli_path_option(int argc, char **argv, int *i, vxl_render_params *p, char *err, size_t err_size);

#endif
