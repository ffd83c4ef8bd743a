/* dynlib_win32.c - dynlib.h on Windows: LoadLibraryExW with the library's
 * own folder searched for its dependencies, names in UTF-8. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <windows.h>

#include "dynlib.h"
#include "utf16_win32.h"

vxl_dynlib *vxl_dynlib_open(const char *name, char *why, size_t why_size)
{
    static const int n = VXL_WPATH;
    wchar_t *w = malloc(n * sizeof *w);
    HMODULE h = NULL;
    if (w && vxl_utf8_to_utf16(name, w, n)) {
        /* a path: its own folder first for what it needs; a bare name: the system's search */
        const DWORD flags = strchr(name, '\\') || strchr(name, '/')
                                ? LOAD_LIBRARY_SEARCH_DLL_LOAD_DIR | LOAD_LIBRARY_SEARCH_DEFAULT_DIRS
                                : 0;
        h = LoadLibraryExW(w, NULL, flags);
    }
    free(w);
    if (!h && why_size) snprintf(why, why_size, "%s cannot be loaded (Windows error %lu)", name, GetLastError());
    return (vxl_dynlib *)h;
}

vxl_dynlib_fn vxl_dynlib_symbol(vxl_dynlib *lib, const char *name)
{
    FARPROC p = lib ? GetProcAddress((HMODULE)lib, name) : NULL;
    vxl_dynlib_fn f = NULL;
    if (p) memcpy(&f, &p, sizeof f);
    return f;
}

void vxl_dynlib_close(vxl_dynlib *lib)
{
    if (lib) FreeLibrary((HMODULE)lib);
}

int vxl_dynlib_path_of(const void *address, char *out, size_t size)
{
    HMODULE m = NULL;
    if (!GetModuleHandleExW(GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS | GET_MODULE_HANDLE_EX_FLAG_UNCHANGED_REFCOUNT,
                            (LPCWSTR)address, &m))
        return -1;
    wchar_t *w = malloc(VXL_WPATH * sizeof *w);
    if (!w) return -1;
    DWORD n = GetModuleFileNameW(m, w, VXL_WPATH);
    int rc = n && n < VXL_WPATH && vxl_utf16_to_utf8(w, out, (int)size) ? 0 : -1;
    free(w);
    return rc;
}
