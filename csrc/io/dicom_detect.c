/* dicom_detect.c - vxl_dicom_path_is_dicom: whether a path is DICOM, for the
 * loader dispatch (volume_load.c) and vxl_dicom_list_series. In the library
 * and in C, so that deciding costs no helper process (reader_stream.h);
 * the rules are those the reader applies (dicom.cpp). */
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "loaders.h"
#include "files.h"

/* "DICM" at byte 128: a Part 10 file. */
static int has_dicm_magic(const char *path)
{
    FILE *f = vxl_fopen(path, "rb");
    if (!f) return 0;
    unsigned char b[132];
    int ok = fread(b, 1, sizeof b, f) == sizeof b && memcmp(b + 128, "DICM", 4) == 0;
    fclose(f);
    return ok;
}

static int is_dicomdir_name(const char *path)
{
    const char *slash = vxl_path_last_separator(path);
    return strcasecmp(slash ? slash + 1 : path, "DICOMDIR") == 0;
}

int vxl_dicom_path_is_dicom(const char *path, int is_dir)
{
    if (!path) return 0;
    if (!is_dir) return has_dicm_magic(path) || is_dicomdir_name(path);
    char p[4096];
    if (snprintf(p, sizeof p, "%s/DICOMDIR", path) < (int)sizeof p && vxl_is_file(p)) return 1;
    /* the first few files decide: a slice folder is DICOM all through */
    vxl_dir *dir = vxl_dir_open(path);
    if (!dir) return 0;
    int seen = 0, found = 0;
    const char *name;
    while (!found && seen < 16 && (name = vxl_dir_next(dir)) != NULL) {
        if (name[0] == '.') continue;
        if (snprintf(p, sizeof p, "%s/%s", path, name) >= (int)sizeof p || !vxl_is_file(p)) continue;
        seen++;
        found = has_dicm_magic(p);
    }
    vxl_dir_close(dir);
    return found;
}
