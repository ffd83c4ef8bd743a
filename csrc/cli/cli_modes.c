/* cli_modes.c - --mode, --iso-value, --matcap, --ortho and --view for
 * `voxlight render` (cli_modes.h). Names come from the library
 * (vxl_mode_name), the camera math from axis_view.h, the PNG from
 * matcap_png.c; the library validates the values and names the field. */
#include "cli_modes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "axis_view.h"
#include "matcap_png.h"

void vxl_cli_modes_init(vxl_cli_modes *m)
{
    memset(m, 0, sizeof *m);
    m->view = VXL_AXIS_VIEW_NONE;
}

void vxl_cli_modes_free(vxl_cli_modes *m)
{
    free(m->matcap_rgba);
    m->matcap_rgba = NULL;
}

static int mode_names(char *buf, size_t size)
{
    size_t len = 0;
    buf[0] = '\0';
    for (uint32_t i = 0; vxl_mode_name(i) && len < size; i++)
        len += (size_t)snprintf(buf + len, size - len, "%s%s", i ? ", " : "", vxl_mode_name(i));
    return 0;
}

int vxl_cli_modes_option(int argc, char **argv, int *i, vxl_cli_modes *m, vxl_render_params *p, char *err,
                         size_t err_size)
{
    const char *o = argv[*i];
    if (!strcmp(o, "--ortho")) {
        m->ortho = 1;
        return 1;
    }
    if (strcmp(o, "--mode") && strcmp(o, "--iso-value") && strcmp(o, "--matcap") && strcmp(o, "--view")) return 0;
    if (*i + 1 >= argc) {
        snprintf(err, err_size, "%s needs a value", o);
        return -1;
    }
    const char *val = argv[++*i];
    if (!strcmp(o, "--mode")) {
        if (vxl_mode_from_name(val, &p->mode) == VXL_OK) return 1;
        char names[128];
        mode_names(names, sizeof names);
        snprintf(err, err_size, "unknown --mode '%s' (%s)", val, names);
        return -1;
    }
    if (!strcmp(o, "--iso-value")) {
        char *end;
        double v = strtod(val, &end);
        if (end == val || *end || !isfinite(v)) {
            snprintf(err, err_size, "bad --iso-value '%s': a number in data units", val);
            return -1;
        }
        p->iso_value = (float)v;
        return 1;
    }
    if (!strcmp(o, "--matcap")) {
        m->matcap_path = val;
        return 1;
    }
    m->view = vxl_axis_view_from_name(val);
    if (m->view == VXL_AXIS_VIEW_NONE) {
        snprintf(err, err_size, "bad --view '%s': one of x, -x, y, -y, z, -z", val);
        return -1;
    }
    return 1;
}

int vxl_cli_modes_apply(vxl_cli_modes *m, vxl_renderer *r, const vxl_volume *v, vxl_render_params *p, char *err,
                        size_t err_size)
{
    if (m->matcap_path) {
        uint32_t w, h;
        if (vxl_cli_read_matcap_png(m->matcap_path, &m->matcap_rgba, &w, &h, err, err_size)) return 1;
        m->matcap = (vxl_matcap){.struct_size = sizeof m->matcap, .width = w, .height = h, .rgba = m->matcap_rgba};
        p->matcap = &m->matcap;
    }
    if (!m->ortho && m->view == VXL_AXIS_VIEW_NONE) return 0;
    vxl_volume_info in = {.struct_size = sizeof in};
    if (vxl_volume_get_info(v, &in)) {
        snprintf(err, err_size, "%s", vxl_last_error());
        return 1;
    }
    double lo[3], hi[3];
    vxl_axis_view_box(in.dims, in.affine, lo, hi);
    uint32_t w = p->width ? p->width : 512, h = p->height ? p->height : 512;
    if (m->view != VXL_AXIS_VIEW_NONE) {
        vxl_axis_view_camera(m->view, m->ortho, lo, hi, w, h, p->view, p->proj);
    } else { /* --ortho alone: the default camera's view, projected orthographically */
        float proj[16];
        if (vxl_default_camera(r, p, p->view, proj)) {
            snprintf(err, err_size, "%s", vxl_renderer_error(r));
            return 1;
        }
        vxl_axis_view_ortho_for(p->view, lo, hi, w, h, p->proj);
    }
    p->has_camera = 1;
    return 0;
}
