/* cli_path.c - --samples, --sample-offset, --bounces and --seed (cli_path.h).
 * The library checks the ranges and names the field; here only that each
 * is a whole number. */
#include "cli_path.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int vxl_cli_path_option(int argc, char **argv, int *i, vxl_render_params *p, char *err, size_t err_size)
{
    static const char *const names[] = {"--samples", "--sample-offset", "--bounces", "--seed"};
    uint32_t *const fields[] = {&p->path_samples, &p->path_sample_offset, &p->path_bounces, &p->path_seed};
    const char *o = argv[*i];
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        if (strcmp(o, names[k])) continue;
        if (*i + 1 >= argc) {
            snprintf(err, err_size, "%s needs a value", o);
            return -1;
        }
        const char *val = argv[++*i];
        char *end;
        unsigned long v = strtoul(val, &end, 10);
        if (end == val || *end || val[0] == '-' || v > UINT32_MAX) {
            snprintf(err, err_size, "bad %s '%s': a whole number from 0", o, val);
            return -1;
        }
        *fields[k] = (uint32_t)v;
        return 1;
    }
    return 0;
}
