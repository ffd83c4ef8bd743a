/* cli_environment.c - --environment and --environment-rotation
 * (cli_environment.h). A value of three or four numbers is a uniform colour
 * (and strength); anything else names a map file, read by the library
 * (vxl_environment_image_load: Radiance .hdr, or OpenEXR .exr through the
 * library's OpenImageIO helper). */
#include "cli_environment.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void vxl_cli_environment_init(vxl_cli_environment *m)
{
    memset(m, 0, sizeof *m);
    m->strength = 1;
}

/* "R,G,B[,STRENGTH]": 1 when val is that (m filled), 0 when it is not numbers at all, -1 when malformed. */
static int parse_colour(const char *val, vxl_cli_environment *m)
{
    float v[4] = {0, 0, 0, 1};
    char extra;
    int n = sscanf(val, "%f,%f,%f,%f%c", &v[0], &v[1], &v[2], &v[3], &extra);
    if (n < 1) return 0; /* a file name */
    int commas = 0;
    for (const char *c = val; *c; c++) commas += *c == ',';
    if (n < 3 || n > 4 || commas != n - 1) return strchr(val, '.') && !commas ? 0 : -1;
    for (int k = 0; k < 4; k++)
        if (!(v[k] >= 0 && v[k] < 1e30f)) return -1;
    memcpy(m->colour, v, sizeof m->colour);
    m->strength = v[3];
    return 1;
}

int vxl_cli_environment_option(int argc, char **argv, int *i, vxl_cli_environment *m, char *err, size_t err_size)
{
    const char *o = argv[*i];
    if (strcmp(o, "--environment") && strcmp(o, "--environment-rotation")) return 0;
    if (*i + 1 >= argc) {
        snprintf(err, err_size, "%s needs a value", o);
        return -1;
    }
    const char *val = argv[++*i];
    if (!strcmp(o, "--environment-rotation")) {
        char *end;
        double d = strtod(val, &end);
        if (end == val || *end || !isfinite(d)) {
            snprintf(err, err_size, "bad --environment-rotation '%s': degrees about world +Z", val);
            return -1;
        }
        m->rotation_deg = (float)d;
        return 1;
    }
    m->given = 1;
    m->path = NULL;
    int c = parse_colour(val, m);
    if (c < 0) {
        snprintf(err, err_size, "bad --environment '%s': FILE.hdr, or R,G,B[,STRENGTH] with each >= 0", val);
        return -1;
    }
    if (c == 0) m->path = val;
    return 1;
}

int vxl_cli_environment_apply(vxl_cli_environment *m, vxl_render_params *p, char *err, size_t err_size)
{
    if (!m->given) return 0;
    uint32_t w = 1, h = 1;
    if (m->path) {
        if (vxl_environment_image_load(m->path, NULL, 0, &w, &h)) {
            snprintf(err, err_size, "%s", vxl_last_error());
            return 1;
        }
        m->rgb = malloc((size_t)w * h * 3 * sizeof *m->rgb);
        if (!m->rgb) {
            snprintf(err, err_size, "out of memory for a %ux%u environment map", w, h);
            return 1;
        }
        if (vxl_environment_image_load(m->path, m->rgb, (uint64_t)w * h, &w, &h)) {
            snprintf(err, err_size, "%s", vxl_last_error());
            return 1;
        }
    }
    m->env = (vxl_environment){.struct_size = sizeof m->env, .width = w, .height = h,
                               .rgb = m->path ? m->rgb : m->colour, .strength = m->strength,
                               .rotation_deg = m->rotation_deg};
    p->environment = &m->env;
    return 0;
}

void vxl_cli_environment_free(vxl_cli_environment *m)
{
    free(m->rgb);
    m->rgb = NULL;
}
