/* os_win32.c - os.h on Windows. */
#include <io.h>
#include <stdlib.h>
#include <windows.h>
#include <shellapi.h>

#include "os.h"
#include "utf16_win32.h"

const char *vxl_os_name(void) { return "windows"; }
int vxl_os_has_debian_libraries(void) { return 0; }
const char *vxl_os_zlib_name(void) { return "zlib1.dll"; }
const char *vxl_os_openjpeg_name(void) { return "openjp2.dll"; }

int vxl_os_utf8_args(int *argc, char ***argv)
{
    int n = 0;
    wchar_t **w = CommandLineToArgvW(GetCommandLineW(), &n);
    if (!w) return -1;
    /* one block: the pointers, then the strings (UTF-8 takes at most 3
     * bytes per UTF-16 unit) */
    size_t bytes = (size_t)(n + 1) * sizeof(char *);
    for (int i = 0; i < n; i++) bytes += wcslen(w[i]) * 3 + 1;
    char **out = malloc(bytes);
    char *at = out ? (char *)(out + n + 1) : NULL;
    for (int i = 0; out && i < n; i++) {
        const int room = (int)(wcslen(w[i]) * 3 + 1);
        if (!vxl_utf16_to_utf8(w[i], at, room)) {
            free(out);
            out = NULL;
            break;
        }
        out[i] = at;
        at += room;
    }
    LocalFree(w);
    if (!out) return -1;
    out[n] = NULL;
    *argc = n;
    *argv = out;
    return 0;
}

int vxl_os_is_terminal(FILE *f) { return _isatty(_fileno(f)) != 0; }

/* _putenv_s changes the C runtime's copy, which getenv reads, and the
 * process' own; an empty value removes the variable. */
int vxl_os_set_env(const char *name, const char *value) { return _putenv_s(name, value ? value : "") == 0 ? 0 : -1; }
