/* cli_labels.h - `voxlight labels FILE`: a label lookup table
 * printed as the library reads it, so a user can check a file. */
#ifndef VXL_CLI_LABELS_H
#define VXL_CLI_LABELS_H

#include <stddef.h>
#include <stdio.h>

/* Prints the table of path to out: a count line, a header line, then one
 * line per label (id, R G B A as 0..255, visibility, name). 0 on success,
 * else 1 with the library's message in err (nothing printed). */
int vxl_cli_labels_print(const char *path, FILE *out, char *err, size_t err_size);

#endif
