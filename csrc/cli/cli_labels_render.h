/* cli_labels_render.h - the render command's label options:
 * --labels FILE, --label-lut FILE, --label-mode surface|mask|tint,
 * --hide-labels ID,..., --label-opacity ID:ALPHA,... and
 * --label-surface smooth|voxels into
 * vxl_renderer_set_labels and params.labels (docs/labels.md). Without
 * --label-lut the lookup file is looked for beside FILE (same stem with
 * .lut, .txt, .ctbl or .label, as plugin/core/label_files.py does); without
 * one, every nonzero id up to the volume's largest gets a palette colour. */
#ifndef VXL_CLI_LABELS_RENDER_H
#define VXL_CLI_LABELS_RENDER_H

#include <stddef.h>
#include <stdint.h>

#include "voxlight.h"

typedef struct vxl_cli_labels {
    const char *path, *lut;          /* --labels, --label-lut */
    uint32_t mode;                   /* --label-mode */
    uint32_t boundary;               /* --label-surface: VXL_LABEL_BOUNDARY_* */
    int boundary_set;
    const char *hide, *opacity;      /* the option values, applied once the table is known */
    vxl_label_entry *entries;        /* the table (owned) */
    uint32_t count;
    vxl_label_style style;
    char lut_used[1024];             /* the lookup file read, "" for the palette */
} vxl_cli_labels;

void vxl_cli_labels_init(vxl_cli_labels *l);
/* argv[*i] is one of the options: 1 (and *i past its value); a bad value: -1
 * with the message in err; not one of them: 0. */
int vxl_cli_labels_option(int argc, char **argv, int *i, vxl_cli_labels *l, char *err, size_t err_size);
/* With --labels: loads the label volume onto r, the table, applies --hide-labels
 * and --label-opacity, and points p->labels at the style. 0, or 1 with the
 * message in err. Nothing without --labels (the other options then fail). */
int vxl_cli_labels_apply(vxl_cli_labels *l, vxl_renderer *r, vxl_render_params *p, char *err, size_t err_size);
void vxl_cli_labels_free(vxl_cli_labels *l);

#endif
