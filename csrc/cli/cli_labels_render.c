/* cli_labels_render.c - the render command's label options (cli_labels_render.h). */
#include "cli_labels_render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "files.h"

void vxl_cli_labels_init(vxl_cli_labels *l)
{
    memset(l, 0, sizeof *l);
    l->mode = VXL_LABEL_MODE_SURFACE;
}

void vxl_cli_labels_free(vxl_cli_labels *l)
{
    free(l->entries);
    l->entries = NULL;
}

int vxl_cli_labels_option(int argc, char **argv, int *i, vxl_cli_labels *l, char *err, size_t err_size)
{
    const char *o = argv[*i];
    const char **slot = !strcmp(o, "--labels")        ? &l->path
                        : !strcmp(o, "--label-lut")     ? &l->lut
                        : !strcmp(o, "--hide-labels")   ? &l->hide
                        : !strcmp(o, "--label-opacity") ? &l->opacity
                                                        : NULL;
    if (!slot && strcmp(o, "--label-mode") && strcmp(o, "--label-surface")) return 0;
    if (*i + 1 >= argc) {
        snprintf(err, err_size, "%s needs a value", o);
        return -1;
    }
    const char *val = argv[++*i];
    if (slot) {
        *slot = val;
        return 1;
    }
    if (!strcmp(o, "--label-surface")) {
        if (strcmp(val, "smooth") && strcmp(val, "voxels")) {
            snprintf(err, err_size, "unknown --label-surface '%s' (smooth, voxels)", val);
            return -1;
        }
        l->boundary = !strcmp(val, "voxels") ? VXL_LABEL_BOUNDARY_VOXELS : VXL_LABEL_BOUNDARY_SMOOTH;
        l->boundary_set = 1;
        return 1;
    }
    if (vxl_label_mode_from_name(val, &l->mode) != VXL_OK) {
        snprintf(err, err_size, "unknown --label-mode '%s' (surface, mask, tint)", val);
        return -1;
    }
    return 1;
}

/* The lookup file beside the label image: stems "a.nii.gz" -> "a.nii", "a". */
static int find_lut(const char *image, char *out, size_t out_size)
{
    static const char *const suffixes[] = {".lut", ".txt", ".ctbl", ".label"};
    char stem[1024];
    snprintf(stem, sizeof stem, "%s", image);
    size_t n = strlen(stem);
    if (n > 3 && !strcasecmp(stem + n - 3, ".gz")) stem[n -= 3] = '\0';
    for (int pass = 0; pass < 2; pass++) {
        const char *slash = strrchr(stem, '/');
        for (size_t s = 0; s < sizeof suffixes / sizeof *suffixes; s++) {
            if ((size_t)snprintf(out, out_size, "%s%s", stem, suffixes[s]) >= out_size) continue;
            if (strcmp(out, image) && vxl_is_file(out)) return 1;
        }
        char *dot = strrchr(stem, '.');
        if (!dot || (slash && dot < slash) || dot == stem) break;
        *dot = '\0'; /* the next stem: one extension less */
    }
    out[0] = '\0';
    return 0;
}

/* A colour per id that neighbours tell apart: golden-ratio hues. */
static void palette(int id, float rgb[3])
{
    double h = fmod(id * 0.6180339887, 1.0) * 6;
    int k = (int)h;
    float f = (float)(h - k), q = 1 - f;
    const float t[6][3] = {{1, f, 0}, {q, 1, 0}, {0, 1, f}, {0, q, 1}, {f, 0, 1}, {1, 0, q}};
    for (int c = 0; c < 3; c++) rgb[c] = 0.15f + 0.85f * t[k % 6][c];
}

static vxl_label_entry *find_entry(vxl_cli_labels *l, long id)
{
    for (uint32_t i = 0; i < l->count; i++)
        if (l->entries[i].id == id) return &l->entries[i];
    return NULL;
}

/* --hide-labels 3,7 and --label-opacity 3:0.5,7:0.2 on the table. */
static int apply_lists(vxl_cli_labels *l, char *err, size_t err_size)
{
    for (int pass = 0; pass < 2; pass++) {
        const char *s = pass ? l->opacity : l->hide;
        const char *what = pass ? "--label-opacity" : "--hide-labels";
        while (s && *s) {
            char *end;
            long id = strtol(s, &end, 10);
            double alpha = 0;
            int ok = end != s;
            if (ok && pass) {
                ok = *end == ':';
                if (ok) {
                    const char *a = end + 1;
                    alpha = strtod(a, &end);
                    ok = end != a && alpha >= 0 && alpha <= 1;
                }
            }
            if (!ok || (*end && *end != ',')) {
                snprintf(err, err_size, "bad %s '%s': %s", what, pass ? l->opacity : l->hide,
                         pass ? "ID:ALPHA,... with ALPHA in [0, 1]" : "ID,...");
                return 1;
            }
            vxl_label_entry *e = find_entry(l, id);
            if (!e) {
                snprintf(err, err_size, "%s: label %ld is not in the label table", what, id);
                return 1;
            }
            if (pass) e->color[3] = (float)alpha;
            else e->visible = 0;
            s = *end ? end + 1 : end;
        }
    }
    return 0;
}

static int load_table(vxl_cli_labels *l, const vxl_volume *v, char *err, size_t err_size)
{
    const char *lut = l->lut;
    if (!lut && find_lut(l->path, l->lut_used, sizeof l->lut_used)) lut = l->lut_used;
    if (lut) {
        if (lut != l->lut_used) snprintf(l->lut_used, sizeof l->lut_used, "%s", lut);
        uint32_t n = 0;
        if (vxl_label_table_load(lut, NULL, 0, &n) ||
            !(l->entries = calloc(n ? n : 1, sizeof *l->entries))) {
            snprintf(err, err_size, "%s", l->entries || n == 0 ? vxl_last_error() : "out of memory for the label table");
            return 1;
        }
        l->entries[0].struct_size = sizeof *l->entries;
        if (vxl_label_table_load(lut, l->entries, n, &l->count)) {
            snprintf(err, err_size, "%s", vxl_last_error());
            return 1;
        }
        if (l->count > n) l->count = n;
        return 0;
    }
    /* no lookup file: every nonzero id up to the largest visible, palette colours */
    vxl_volume_info info = {.struct_size = sizeof info};
    if (vxl_volume_get_info(v, &info)) {
        snprintf(err, err_size, "%s", vxl_last_error());
        return 1;
    }
    double top = info.value_max < VXL_MAX_LABEL_ID ? info.value_max : VXL_MAX_LABEL_ID;
    uint32_t n = top >= 1 ? (uint32_t)top : 0;
    if (!(l->entries = calloc(n ? n : 1, sizeof *l->entries))) {
        snprintf(err, err_size, "out of memory for the label palette");
        return 1;
    }
    for (uint32_t i = 0; i < n; i++) {
        vxl_label_entry *e = &l->entries[i];
        e->struct_size = sizeof *e;
        e->id = (int32_t)(i + 1);
        palette(e->id, e->color);
        e->color[3] = 1;
        e->visible = 1;
    }
    l->count = n;
    return 0;
}

int vxl_cli_labels_apply(vxl_cli_labels *l, vxl_renderer *r, vxl_render_params *p, char *err, size_t err_size)
{
    if (!l->path) {
        if (l->lut || l->hide || l->opacity || l->boundary_set) {
            snprintf(err, err_size, "--label-lut, --hide-labels, --label-opacity and --label-surface need --labels FILE");
            return 1;
        }
        return 0;
    }
    vxl_volume *v = NULL;
    if (vxl_volume_load(l->path, NULL, &v)) {
        snprintf(err, err_size, "%s", vxl_last_error());
        return 1;
    }
    int rc = load_table(l, v, err, err_size);
    if (!rc && vxl_renderer_set_labels(r, v)) {
        snprintf(err, err_size, "%s: %s", l->path, vxl_renderer_error(r));
        rc = 1;
    }
    vxl_volume_destroy(v);
    if (rc || apply_lists(l, err, err_size)) return 1;
    l->style = (vxl_label_style){.struct_size = sizeof l->style, .mode = l->mode, .entry_count = l->count,
                                 .entries = l->entries, .boundary = l->boundary};
    p->labels = &l->style;
    return 0;
}
