/* zarr_detect.c - whether a path names a Zarr store, for the dispatch in
 * volume_load.c; in the library (no process is started to decide). */
#include <stdio.h>
#include <string.h>

#include "loaders.h"
#include "files.h"

static const char *const marks[] = {"zarr.json", ".zattrs", ".zgroup"};

int vxl_zarr_metadata_name(const char *name)
{
    for (size_t i = 0; i < sizeof marks / sizeof marks[0]; i++)
        if (!strcmp(name, marks[i])) return 1;
    return 0;
}

int vxl_zarr_path_is_zarr(const char *path)
{
    char folder[4096], p[4096 + 16];
    const char *hash = strrchr(path, '#');
    int n = hash ? (int)(hash - path) : (int)strlen(path);
    if (n <= 0 || n >= (int)sizeof folder) return 0;
    snprintf(folder, sizeof folder, "%.*s", n, path);
    /* a file browser hands over the metadata file picked inside the store */
    char *slash = (char *)vxl_path_last_separator(folder);
    if (slash && vxl_zarr_metadata_name(slash + 1)) *slash = '\0';
    if (!vxl_is_dir(folder)) return 0;
    for (size_t i = 0; i < sizeof marks / sizeof marks[0]; i++) {
        snprintf(p, sizeof p, "%s/%s", folder, marks[i]);
        if (vxl_is_file(p)) return 1;
    }
    return 0;
}
