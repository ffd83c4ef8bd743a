/* utf8_temp.h - a folder under the system's temporary folder whose name is
 * not ASCII, for tests of the platform room's UTF-8 paths on every OS
 * (Windows' wide-character calls, POSIX's bytes). */
#ifndef VXL_TEST_UTF8_TEMP_H
#define VXL_TEST_UTF8_TEMP_H

#include <stdio.h>
#include <stdlib.h>

/* "<TMPDIR, TEMP or TMP>/voxlight-<what>-José-ü" into out. */
static inline void utf8_temp_folder(const char *what, char *out, size_t n)
{
    const char *env[] = {"TMPDIR", "TEMP", "TMP"};
    const char *base = NULL;
    for (int i = 0; i < 3 && !base; i++) base = getenv(env[i]);
    snprintf(out, n, "%s/voxlight-%s-José-ü", base && *base ? base : "/tmp", what);
}

#endif
