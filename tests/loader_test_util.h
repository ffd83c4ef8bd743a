/* loader_test_util.h - helpers the loader tests share: removing their temp
 * tree, and reading a loaded volume's data values back from its texels
 * (layout from volume.h), so byte-order, offset or ordering mistakes show up
 * as wrong values. */
#ifndef VXL_LOADER_TEST_UTIL_H
#define VXL_LOADER_TEST_UTIL_H

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
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
static double voxel(const vxl_volume *v, uint64_t i)
{
    double t;
    if (v->texture_bits == 8) t = ((const uint8_t *)v->texels)[i] / 255.0;
    else if (v->texture_bits == 16) t = ((const uint16_t *)v->texels)[i] / 65535.0;
    else t = ((const float *)v->texels)[i];
    return v->tex_lo + t * (v->tex_hi - v->tex_lo);
}

#endif
