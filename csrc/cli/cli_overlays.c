/* cli_overlays.c - the render command's overlay options (cli_overlays.h). */
#include "cli_overlays.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "files.h"

void vxl_cli_overlays_init(vxl_cli_overlays *o)
{
    memset(o, 0, sizeof *o);
}

static int parse_number(const char *s, size_t len, float *out)
{
    char buf[64], *end;
    if (!len || len >= sizeof buf) return 0;
    memcpy(buf, s, len);
    buf[len] = '\0';
    double v = strtod(buf, &end);
    if (end == buf || *end || !isfinite(v)) return 0;
    *out = (float)v;
    return 1;
}

/* "FILE[:PRESET][:LO:HI]" into slot o->count. A value that names an
 * existing file is taken whole (a file name may hold ':'); otherwise FILE
 * ends at the first ':' and the parts after it are PRESET, LO:HI or
 * PRESET:LO:HI. */
static int parse_spec(const char *val, vxl_cli_overlays *o, char *err, size_t err_size)
{
    vxl_overlay_style *s = &o->style[o->count];
    char *path = o->path[o->count];
    vxl_path_info info;
    /* a drive letter's colon ("C:\\scans\\ct.nii:hot") is the path's */
    const int drive =
        ((val[0] | 32) >= 'a' && (val[0] | 32) <= 'z') && val[1] == ':' && (val[2] == '\\' || val[2] == '/');
    const char *colon = vxl_path_stat(val, &info) == 0 ? NULL : strchr(val + (drive ? 2 : 0), ':');
    size_t len = colon ? (size_t)(colon - val) : strlen(val);
    if (!len || len >= sizeof o->path[0])
        return snprintf(err, err_size, "bad --overlay '%s': use FILE[:PRESET][:LO:HI]", val), 1;
    memcpy(path, val, len);
    path[len] = '\0';
    const char *part[4];
    size_t plen[4];
    int n = 0;
    for (const char *c = colon; c; n++) {
        if (n == 3)
            return snprintf(err, err_size, "bad --overlay '%s': use FILE[:PRESET][:LO:HI]", val), 1;
        part[n] = c + 1;
        c = strchr(c + 1, ':');
        plen[n] = c ? (size_t)(c - part[n]) : strlen(part[n]);
    }
    if (n == 1 || n == 3) { /* PRESET first */
        char name[64];
        if (plen[0] >= sizeof name) plen[0] = sizeof name - 1;
        memcpy(name, part[0], plen[0]);
        name[plen[0]] = '\0';
        if (vxl_preset_from_name(name, &s->preset) != VXL_OK) {
            char names[256];
            size_t used = 0;
            names[0] = '\0';
            for (uint32_t k = 0; vxl_preset_name(k) && used < sizeof names; k++)
                used += (size_t)snprintf(names + used, sizeof names - used, "%s%s", k ? ", " : "", vxl_preset_name(k));
            return snprintf(err, err_size, "unknown preset '%s' in --overlay '%s' (%s)", name, val, names), 1;
        }
    }
    if (n >= 2) { /* LO:HI last */
        if (!parse_number(part[n - 2], plen[n - 2], &s->window_low) ||
            !parse_number(part[n - 1], plen[n - 1], &s->window_high) || s->window_low == s->window_high)
            return snprintf(err, err_size, "bad window in --overlay '%s': use LO:HI with LO != HI", val), 1;
        s->has_window = 1;
    }
    return 0;
}

int vxl_cli_overlays_option(int argc, char **argv, int *i, vxl_cli_overlays *o, char *err, size_t err_size)
{
    const char *opt = argv[*i];
    if (strcmp(opt, "--overlay") && strcmp(opt, "--overlay-blend") && strcmp(opt, "--overlay-opacity")) return 0;
    if (*i + 1 >= argc) return snprintf(err, err_size, "%s needs a value", opt), -1;
    const char *val = argv[++*i];
    if (!strcmp(opt, "--overlay")) {
        if (o->count == VXL_MAX_OVERLAYS)
            return snprintf(err, err_size, "more than %d --overlay options", VXL_MAX_OVERLAYS), -1;
        vxl_overlay_style *s = &o->style[o->count];
        memset(s, 0, sizeof *s);
        s->struct_size = sizeof *s;
        s->slot = o->count;
        s->blend = VXL_BLEND_OVER;
        if (parse_spec(val, o, err, err_size)) return -1;
        o->count++;
        return 1;
    }
    /* the other two set the overlay given last */
    if (!o->count) return snprintf(err, err_size, "%s '%s' must follow the --overlay it is for", opt, val), -1;
    vxl_overlay_style *s = &o->style[o->count - 1];
    if (!strcmp(opt, "--overlay-blend")) {
        if (vxl_blend_from_name(val, &s->blend) == VXL_OK) return 1;
        return snprintf(err, err_size, "unknown --overlay-blend '%s' (over, add, max)", val), -1;
    }
    float x;
    /* 0 would mean "the default, 1" in the struct: no overlay is asked for with --overlay */
    if (!parse_number(val, strlen(val), &x) || !(x > 0) || x > 1000)
        return snprintf(err, err_size, "bad --overlay-opacity '%s': a scale of the overlay's opacity, > 0", val), -1;
    s->opacity_scale = x;
    return 1;
}

int vxl_cli_overlays_apply(vxl_cli_overlays *o, vxl_renderer *r, vxl_render_params *p, char *err, size_t err_size)
{
    for (uint32_t k = 0; k < o->count; k++) {
        vxl_volume *v = NULL;
        if (vxl_volume_load(o->path[k], NULL, &v)) {
            const char *msg = vxl_last_error();
            if (strstr(msg, o->path[k])) snprintf(err, err_size, "--overlay: %s", msg);
            else snprintf(err, err_size, "--overlay %s: %s", o->path[k], msg);
            return 1;
        }
        int rc = vxl_renderer_set_overlay(r, k, v);
        vxl_volume_destroy(v);
        if (rc) return snprintf(err, err_size, "--overlay %s: %s", o->path[k], vxl_renderer_error(r)), 1;
        o->style[k].shading_off = p->shading_off;
    }
    if (o->count) {
        p->overlay_count = o->count;
        p->overlays = o->style;
    }
    return 0;
}
