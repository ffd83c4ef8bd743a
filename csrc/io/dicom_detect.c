/* dicom_detect.c - vxl_dicom_path_is_dicom: whether a path is DICOM, for the
 * loader dispatch (volume_load.c) and vxl_dicom_list_series. In the library
 * and in C, so that deciding costs no helper process (reader_stream.h);
 * the rules are those the reader applies (dicom.cpp). */
#include <dirent.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "loaders.h"

/* "DICM" at byte 128: a Part 10 file. */
static int has_dicm_magic(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    unsigned char b[132];
    int ok = fread(b, 1, sizeof b, f) == sizeof b && memcmp(b + 128, "DICM", 4) == 0;
    fclose(f);
    return ok;
}

static int is_regular(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static int is_dicomdir_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return strcasecmp(slash ? slash + 1 : path, "DICOMDIR") == 0;
}

int vxl_dicom_path_is_dicom(const char *path, int is_dir)
{
    if (!path) return 0;
    if (!is_dir) return has_dicm_magic(path) || is_dicomdir_name(path);
    char p[4096];
    if (snprintf(p, sizeof p, "%s/DICOMDIR", path) < (int)sizeof p && is_regular(p)) return 1;
    /* the first few files decide: a slice folder is DICOM all through */
    DIR *dir = opendir(path);
    if (!dir) return 0;
    int seen = 0, found = 0;
    struct dirent *ent;
    while (!found && seen < 16 && (ent = readdir(dir)) != NULL) {
        if (ent->d_name[0] == '.') continue;
        if (snprintf(p, sizeof p, "%s/%s", path, ent->d_name) >= (int)sizeof p || !is_regular(p)) continue;
        seen++;
        found = has_dicm_magic(p);
    }
    closedir(dir);
    return found;
}
