/* dynlib_win32.c - dynlib.h on Windows: LoadLibraryExW with the library's
 * own folder searched for its dependencies, names in UTF-8. A bare name is
 * looked for first beside the module this code is linked into (voxlight.dll
 * ships zlib1.dll there): Windows' own search starts in the folder of the
 * program, which inside Blender is Blender's. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <windows.h>

#include "dynlib.h"
#include "files.h"
#include "utf16_win32.h"

/* LoadLibraryExW of a UTF-8 name or path. */
static HMODULE load(const char *name, DWORD flags)
{
    wchar_t *w = malloc(VXL_WPATH * sizeof *w);
    HMODULE h = NULL;
    if (w && vxl_utf8_to_utf16(name, w, VXL_WPATH)) h = LoadLibraryExW(w, NULL, flags);
    free(w);
    return h;
}

/* name in the folder of the module holding this code, into out; 0 or -1. */
static int beside_this_module(const char *name, char *out, size_t size)
{
    if (vxl_dynlib_path_of((const void *)&beside_this_module, out, size)) return -1;
    const char *slash = vxl_path_last_separator(out);
    if (!slash) return -1;
    const size_t dir = (size_t)(slash + 1 - out);
    if (dir + strlen(name) + 1 > size) return -1;
    memcpy(out + dir, name, strlen(name) + 1);
    return 0;
}

vxl_dynlib *vxl_dynlib_open(const char *name, char *why, size_t why_size)
{
    /* a path: its own folder first for what it needs */
    const DWORD path_flags = LOAD_LIBRARY_SEARCH_DLL_LOAD_DIR | LOAD_LIBRARY_SEARCH_DEFAULT_DIRS;
    HMODULE h = NULL;
    if (strchr(name, '\\') || strchr(name, '/')) {
        h = load(name, path_flags);
    } else {
        char *beside = malloc(VXL_WPATH * 3);
        if (beside && beside_this_module(name, beside, VXL_WPATH * 3) == 0) h = load(beside, path_flags);
        free(beside);
        if (!h) h = load(name, 0); /* the system's search */
    }
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
