/* files.c - what files.h does the same on every OS. */
#include "files.h"

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
