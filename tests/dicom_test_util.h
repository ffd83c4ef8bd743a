/* dicom_test_util.h - what the DICOM tests share: a scratch folder per
 * case, loading through the public API, and comparing volumes voxel for
 * voxel (through the texels, volume.h) or within a bound in data units. */
#ifndef VXL_DICOM_TEST_UTIL_H
#define VXL_DICOM_TEST_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "loader_test_util.h"
#include "volume.h"
#include "voxlight.h"

/* A fresh folder root/name, its path in buf. */
static inline const char *dicom_folder(const char *root, char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", root, name);
    mkdir(buf, 0755);
    return buf;
}

static inline int contains(const char *s, const char *sub) { return strstr(s, sub) != NULL; }

/* The volume at path (series: NULL, an index or a UID), NULL on failure
 * (vxl_last_error says why). */
static inline vxl_volume *load_dicom(const char *path, const char *series, uint32_t frame)
{
    vxl_load_options opt = {.struct_size = sizeof opt, .series = series, .frame = frame};
    vxl_volume *v = NULL;
    if (vxl_volume_load(path, &opt, &v) != VXL_OK) return NULL;
    return v;
}

/* a and b hold the same voxels (same size, range and texels). */
static inline int same_volume(const vxl_volume *a, const vxl_volume *b)
{
    const size_t bytes = (size_t)a->dims[0] * a->dims[1] * a->dims[2] * (a->texture_bits / 8);
    return !memcmp(a->dims, b->dims, sizeof a->dims) && a->texture_bits == b->texture_bits &&
           a->value_min == b->value_min && a->value_max == b->value_max && a->texels && b->texels &&
           !memcmp(a->texels, b->texels, bytes);
}

/* Largest |a - b| over the voxels in data units; -1 when the sizes differ. */
static inline double max_difference(const vxl_volume *a, const vxl_volume *b)
{
    if (memcmp(a->dims, b->dims, sizeof a->dims)) return -1;
    const uint64_t n = (uint64_t)a->dims[0] * a->dims[1] * a->dims[2];
    double worst = 0;
    for (uint64_t i = 0; i < n; i++) worst = fmax(worst, fabs(voxel(a, i) - voxel(b, i)));
    return worst;
}

/* Every file IMkkkk.dcm (k < slices) of src through `tool` (a command
 * line taking IN OUT, e.g. one of dcmtk's encoders, independent of our
 * decoders) into the fresh folder root/name, its path in out. */
static inline int convert_series(const char *root, const char *src, int slices, const char *name, const char *tool,
                                 char *out, size_t n)
{
    dicom_folder(root, out, n, name);
    char cmd[1400];
    for (int k = 0; k < slices; k++) {
        snprintf(cmd, sizeof cmd, "%s %s/IM%04d.dcm %s/IM%04d.dcm", tool, src, k, out, k);
        if (system(cmd) != 0) return -1;
    }
    return 0;
}

/* The volume's notes (what the reader decided), "" when none. */
static inline const char *volume_notes(const vxl_volume *v, vxl_volume_info *info)
{
    *info = (vxl_volume_info){.struct_size = sizeof *info};
    return vxl_volume_get_info(v, info) == VXL_OK ? info->notes : "";
}

#endif
