/* files.c - what files.h does the same on every OS. */
#include "files.h"

#include <string.h>

const char *vxl_path_last_separator(const char *path)
{
    const char *slash = strrchr(path, '/'), *back = strrchr(path, '\\');
    return back > slash ? back : slash;
}

int vxl_path_is_separator(char c) { return c == '/' || c == '\\'; }

int vxl_is_file(const char *path)
{
    vxl_path_info i;
    return vxl_path_stat(path, &i) == 0 && i.kind == VXL_PATH_FILE;
}

int vxl_is_dir(const char *path)
{
    vxl_path_info i;
    return vxl_path_stat(path, &i) == 0 && i.kind == VXL_PATH_DIR;
}
