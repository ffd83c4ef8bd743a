/* label_table_input.h - what fuzz_label_table does with one input, shared
 * with tests/test_label_table.c's replay of tests/crashers/label_table/:
 * write the input as the file(s) its first byte picks
 * (label_table_samples.h), load it through vxl_label_table_load, and check
 * the contract: success gives sorted unique ids, colours in [0, 1],
 * visibility 0/1 and NUL-terminated UTF-8 names; failure gives a count of
 * 0 and a message. */
#ifndef VXL_LABEL_TABLE_INPUT_H
#define VXL_LABEL_TABLE_INPUT_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "label_table_samples.h"
#include "voxlight.h"

static inline int lt_write_file(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f) return 1;
    int bad = size && fwrite(data, 1, size, f) != size;
    return fclose(f) != 0 || bad;
}

/* Writes the input's file(s) into dir (removing the previous input's) and
 * puts the path to load in path. Returns 0, or 1 when writing failed. */
static inline int lt_write_input(const char *dir, const uint8_t *data, size_t size, char *path, size_t path_size)
{
    static const char *const names[] = {"input.txt", "input.ctbl", "input.label", "input.lut"};
    char p[512];
    for (int i = 0; i < 4; i++) {
        snprintf(p, sizeof p, "%s/%s", dir, names[i]);
        unlink(p);
    }
    unsigned mode = size ? data[0] % LT_MODE_COUNT : LT_MODE_TXT;
    const uint8_t *body = size ? data + 1 : data;
    size_t n = size ? size - 1 : 0;
    if (mode == LT_MODE_PAIR) {
        size_t lut = n < 768 ? n : 768;
        snprintf(p, sizeof p, "%s/input.txt", dir);
        if (lt_write_file(p, body + lut, n - lut)) return 1;
        n = lut;
        mode = LT_MODE_LUT;
    }
    snprintf(path, path_size, "%s/%s", dir, names[mode]);
    return lt_write_file(path, body, n);
}

static inline int lt_valid_utf8(const unsigned char *s)
{
    while (*s) {
        int len = *s < 0x80 ? 1 : (*s & 0xE0) == 0xC0 ? 2 : (*s & 0xF0) == 0xE0 ? 3 : (*s & 0xF8) == 0xF0 ? 4 : 0;
        if (!len) return 0;
        for (int i = 1; i < len; i++)
            if ((s[i] & 0xC0) != 0x80) return 0;
        s += len;
    }
    return 1;
}

/* Loads path and checks the contract. Returns NULL when it holds, else
 * what broke. *rc receives the load's result. */
static inline const char *lt_check_load(const char *path, int *rc)
{
    uint32_t n = 12345;
    *rc = vxl_label_table_load(path, NULL, 0, &n);
    if (*rc != VXL_OK) return n == 0 && vxl_last_error()[0] ? NULL : "a failure without a message or with a count";
    if (n == 0 || n > 65536) return "a success with no labels or more than the cap";
    vxl_label_entry *t = calloc(n, sizeof *t);
    if (!t) return NULL;
    t[0].struct_size = sizeof *t;
    uint32_t again = 0;
    const char *why = NULL;
    if (vxl_label_table_load(path, t, n, &again) != VXL_OK || again != n) why = "the second read differs";
    for (uint32_t i = 0; !why && i < n; i++) {
        if (i && t[i].id <= t[i - 1].id) why = "ids not sorted and unique";
        for (int c = 0; c < 4; c++)
            if (!(t[i].color[c] >= 0.0f && t[i].color[c] <= 1.0f)) why = "a colour outside [0, 1]";
        if (t[i].visible > 1) why = "visible not 0 or 1";
        if (!memchr(t[i].name, '\0', sizeof t[i].name)) why = "a name without its NUL";
        else if (strlen(t[i].name) > 63 || !lt_valid_utf8((const unsigned char *)t[i].name)) why = "a bad name";
    }
    free(t);
    return why;
}

#endif
