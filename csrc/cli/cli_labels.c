/* cli_labels.c - `voxlight labels FILE` (cli_labels.h): the table from
 * vxl_label_table_load, counted first, then read whole. */
#include "cli_labels.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "voxlight.h"

int vxl_cli_labels_print(const char *path, FILE *out, char *err, size_t err_size)
{
    uint32_t n = 0;
    if (vxl_label_table_load(path, NULL, 0, &n)) return snprintf(err, err_size, "%s", vxl_last_error()), 1;
    vxl_label_entry *t = calloc(n, sizeof *t);
    if (!t) return snprintf(err, err_size, "out of memory for %u labels", n), 1;
    t[0].struct_size = sizeof *t;
    if (vxl_label_table_load(path, t, n, &n)) {
        snprintf(err, err_size, "%s", vxl_last_error());
        free(t);
        return 1;
    }
    fprintf(out, "%u labels in %s\n%11s  %3s %3s %3s %3s  %s  %s\n", n, path, "id", "R", "G", "B", "A", "vis", "name");
    for (uint32_t i = 0; i < n; i++) {
        int c[4];
        for (int k = 0; k < 4; k++) c[k] = (int)lroundf(t[i].color[k] * 255.0f);
        fprintf(out, "%11d  %3d %3d %3d %3d  %3s  %s\n", (int)t[i].id, c[0], c[1], c[2], c[3],
                t[i].visible ? "yes" : "no", t[i].name);
    }
    free(t);
    return 0;
}
