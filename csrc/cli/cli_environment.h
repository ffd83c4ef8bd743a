/* cli_environment.h - the render command's World light: --environment
 * FILE.hdr|R,G,B[,STRENGTH] and --environment-rotation DEG (about world +Z,
 * voxlight.h's vxl_environment convention). */
#ifndef VXL_CLI_ENVIRONMENT_H
#define VXL_CLI_ENVIRONMENT_H

#include <stddef.h>

#include "voxlight.h"

typedef struct vxl_cli_environment {
    const char *path;   /* --environment FILE; NULL with a colour or none */
    int given;          /* --environment was given */
    float colour[3];    /* --environment R,G,B */
    float strength;
    float rotation_deg; /* --environment-rotation */
    float *rgb;         /* the file's pixels, read by vxl_cli_environment_apply */
    vxl_environment env;
} vxl_cli_environment;

void vxl_cli_environment_init(vxl_cli_environment *m);
/* argv[*i] is one of the options: 1 (and *i past its value); a bad value: -1
 * with the message in err; not one of them: 0. */
int vxl_cli_environment_option(int argc, char **argv, int *i, vxl_cli_environment *m, char *err, size_t err_size);
/* Reads the file (if any) and points p->environment at it: 0, else 1 with the message in err. */
int vxl_cli_environment_apply(vxl_cli_environment *m, vxl_render_params *p, char *err, size_t err_size);
void vxl_cli_environment_free(vxl_cli_environment *m);

#endif
