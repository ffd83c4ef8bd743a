/* cli_cut.c - --clip-plane, --crop and --no-caps (cli_cut.h). */
#include "cli_cut.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void vxl_cli_cut_init(vxl_cli_cut *c)
{
    memset(c, 0, sizeof *c);
    c->cut.struct_size = sizeof c->cut;
}

/* "A,B,C,D" or "A,B,C,D,T": four or five finite numbers. */
static int clip_plane(const char *val, vxl_cli_cut *c, char *err, size_t err_size)
{
    if (c->cut.clip_plane_count >= VXL_MAX_CLIP_PLANES)
        return snprintf(err, err_size, "more than %d --clip-plane options", VXL_MAX_CLIP_PLANES), -1;
    double v[5] = {0, 0, 0, 0, 0};
    int n = 0;
    const char *s = val;
    for (;;) {
        char *end;
        double x = strtod(s, &end);
        if (n == 5 || end == s || !isfinite(x) || (*end && *end != ','))
            return snprintf(err, err_size, "bad --clip-plane '%s': use A,B,C,D (keeps A x + B y + C z + D >= 0, "
                                           "world mm) and an optional slab thickness T", val), -1;
        v[n++] = x;
        if (!*end) break;
        s = end + 1;
    }
    if (n < 4)
        return snprintf(err, err_size, "bad --clip-plane '%s': four numbers A,B,C,D and an optional thickness", val), -1;
    if (v[0] == 0 && v[1] == 0 && v[2] == 0)
        return snprintf(err, err_size, "bad --clip-plane '%s': the normal A,B,C cannot be zero", val), -1;
    if (v[4] < 0) return snprintf(err, err_size, "bad --clip-plane '%s': the thickness must be >= 0", val), -1;
    vxl_clip_plane *q = &c->cut.clip_planes[c->cut.clip_plane_count++];
    for (int k = 0; k < 4; k++) q->plane[k] = (float)v[k];
    q->thickness = (float)v[4];
    return 1;
}

/* "X0:X1,Y0:Y1,Z0:Z1": voxel indices, X0 <= X1 each. */
static int crop(const char *val, vxl_cli_cut *c, char *err, size_t err_size)
{
    const char *s = val;
    for (int a = 0; a < 3; a++) {
        char *end;
        for (int k = 0; k < 2; k++) {
            long x = strtol(s, &end, 10);
            char want = k == 0 ? ':' : (a < 2 ? ',' : '\0');
            if (end == s || *end != want || x < 0 || x > 1000000000L)
                return snprintf(err, err_size, "bad --crop '%s': use X0:X1,Y0:Y1,Z0:Z1 (voxel indices from 0, "
                                               "inclusive)", val), -1;
            c->crop[a][k] = x;
            s = end + 1;
        }
        if (c->crop[a][0] > c->crop[a][1])
            return snprintf(err, err_size, "bad --crop '%s': %c0 %ld is after %c1 %ld", val, "XYZ"[a], c->crop[a][0],
                            "XYZ"[a], c->crop[a][1]), -1;
    }
    c->has_crop = 1;
    return 1;
}

int vxl_cli_cut_option(int argc, char **argv, int *i, vxl_cli_cut *c, char *err, size_t err_size)
{
    const char *o = argv[*i];
    if (!strcmp(o, "--no-caps")) {
        c->cut.caps_off = 1;
        c->any = 1;
        return 1;
    }
    if (strcmp(o, "--clip-plane") && strcmp(o, "--crop")) return 0;
    if (*i + 1 >= argc) return snprintf(err, err_size, "%s needs a value", o), -1;
    const char *val = argv[++*i];
    c->any = 1;
    return !strcmp(o, "--crop") ? crop(val, c, err, err_size) : clip_plane(val, c, err, err_size);
}

int vxl_cli_cut_apply(vxl_cli_cut *c, const vxl_volume *v, vxl_render_params *p, char *err, size_t err_size)
{
    if (!c->any) return 0;
    if (c->has_crop) {
        vxl_volume_info in = {.struct_size = sizeof in};
        if (vxl_volume_get_info(v, &in)) return snprintf(err, err_size, "%s", vxl_last_error()), 1;
        for (int a = 0; a < 3; a++)
            if (c->crop[a][1] >= (long)in.dims[a])
                return snprintf(err, err_size, "--crop: %c1 = %ld is outside the volume (%c has %u voxels: 0..%u)",
                                "XYZ"[a], c->crop[a][1], "XYZ"[a], in.dims[a], in.dims[a] - 1), 1;
        /* the box [-1, 1]^3 onto voxels [X0 - 0.5, X1 + 0.5] (their whole extent), then the affine */
        double box[16] = {0};
        for (int a = 0; a < 3; a++) {
            box[a * 5] = (c->crop[a][1] - c->crop[a][0] + 1) / 2.0;
            box[12 + a] = (c->crop[a][0] + c->crop[a][1]) / 2.0;
        }
        box[15] = 1;
        for (int col = 0; col < 4; col++)
            for (int row = 0; row < 4; row++) {
                double s = 0;
                for (int k = 0; k < 4; k++) s += in.affine[k * 4 + row] * box[col * 4 + k];
                c->cut.crop_box[col * 4 + row] = (float)s;
            }
        c->cut.has_crop = 1;
    }
    p->cutaway = &c->cut;
    return 0;
}
