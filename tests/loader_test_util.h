/* loader_test_util.h - helpers the loader tests share: removing their temp
 * tree, and reading a loaded volume's data values back from its texels
 * (layout from volume.h), so byte-order, offset or ordering mistakes show up
 * as wrong values. */
#ifndef VXL_LOADER_TEST_UTIL_H
#define VXL_LOADER_TEST_UTIL_H

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "volume.h"

static void remove_tree(const char *path)
{
    DIR *d = opendir(path);
    if (d) {
        struct dirent *ent;
        char p[1024];
        while ((ent = readdir(d)) != NULL) {
            if (!strcmp(ent->d_name, ".") || !strcmp(ent->d_name, "..")) continue;
            snprintf(p, sizeof p, "%s/%s", path, ent->d_name);
            remove_tree(p);
        }
        closedir(d);
        rmdir(path);
    } else {
        unlink(path);
    }
}

/* Data value of voxel i, reconstructed from the stored texel. */
static inline double voxel(const vxl_volume *v, uint64_t i)
{
    double t;
    if (v->texture_bits == 8) t = ((const uint8_t *)v->texels)[i] / 255.0;
    else if (v->texture_bits == 16) t = ((const uint16_t *)v->texels)[i] / 65535.0;
    else t = ((const float *)v->texels)[i];
    return v->tex_lo + t * (v->tex_hi - v->tex_lo);
}

/* Peak resident set of this process (kB), after clearing it when reset. */
static inline long peak_rss_kb(int reset)
{
    if (reset) {
        FILE *c = fopen("/proc/self/clear_refs", "w");
        if (c) {
            fputs("5", c); /* resets VmHWM to the current RSS */
            fclose(c);
        }
    }
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return -1;
    char line[256];
    long kb = -1;
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, "VmHWM:", 6)) kb = strtol(line + 6, NULL, 10);
    fclose(f);
    return kb;
}

#endif
