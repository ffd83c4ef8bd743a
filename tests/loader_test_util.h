/* loader_test_util.h - helpers the loader tests share: removing their temp
 * tree, reading and writing whole files, a volume's info, and reading a loaded volume's data values back from its texels
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

__attribute__((unused)) static void remove_tree(const char *path)
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

/* A whole file, malloc'd (*size bytes), or NULL. */
static inline unsigned char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    unsigned char *buf = NULL;
    size_t cap = 0, n = 0;
    for (;;) {
        if (n == cap) {
            cap = cap ? cap * 2 : 4096;
            unsigned char *nb = realloc(buf, cap);
            if (!nb) break;
            buf = nb;
        }
        size_t r = fread(buf + n, 1, cap - n, f);
        n += r;
        if (r == 0) break;
    }
    fclose(f);
    *size = n;
    return buf;
}

/* path holding exactly buf[0..n); 0 or -1. */
static inline int write_all(const char *path, const void *buf, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    int ok = fwrite(buf, 1, n, f) == n;
    return (fclose(f) == 0 && ok) ? 0 : -1;
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

/* Everything vxl_volume_get_info says of v (all zero when it fails). */
__attribute__((unused)) static vxl_volume_info volume_info_of(const vxl_volume *v)
{
    vxl_volume_info in;
    memset(&in, 0, sizeof in);
    in.struct_size = sizeof in;
    vxl_volume_get_info(v, &in);
    return in;
}

#endif
