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
#include <unistd.h>

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

/* a and b hold the same voxels (same size, range and texels). */
static inline int same_volume(const vxl_volume *a, const vxl_volume *b)
{
    const size_t bytes = (size_t)a->dims[0] * a->dims[1] * a->dims[2] * (a->texture_bits / 8);
    return !memcmp(a->dims, b->dims, sizeof a->dims) && a->texture_bits == b->texture_bits &&
           a->value_min == b->value_min && a->value_max == b->value_max && a->texels && b->texels &&
           !memcmp(a->texels, b->texels, bytes);
}

/* Our own Part 10 parser (the one Windows runs) against dcmtk's: every
 * load through load_dicom or load_dicom_with is made a second time by
 * the helper voxlight-read-dicom-own (build/, beside the tests' folder),
 * which must give the same volume (voxels, affine, spacing, notes) or, when
 * dcmtk refuses the file, refuse it too; a file only dcmtk's codecs decode
 * (JPEG Baseline/Extended, JPEG-LS, colour lossless JPEG) must be refused
 * with the line naming the tool that decompresses it. dcmtk is the
 * independent reference: the tests' generators (dcmtk's tools, pydicom)
 * write every encoding they check. Counted here; each test program ends
 * with own_parser_agrees_with_dcmtk, which fails on any disagreement. */
static int g_own_compared, g_own_refused, g_own_disagreed;

static inline const char *own_parser_helper(void)
{
    static char path[4096];
    if (!path[0]) {
        char self[3072];
        ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
        if (n <= 0) return NULL;
        self[n] = '\0';
        char *slash = strrchr(self, '/');
        if (!slash) return NULL;
        *slash = '\0';
        snprintf(path, sizeof path, "%s/../voxlight-read-dicom-own", self);
    }
    return path;
}

static inline int same_geometry(const vxl_volume *a, const vxl_volume *b)
{
    for (int i = 0; i < 16; i++)
        if (a->affine[i] != b->affine[i]) return 0;
    for (int i = 0; i < 3; i++)
        if (a->spacing[i] != b->spacing[i]) return 0;
    const size_t rgb = (size_t)a->dims[0] * a->dims[1] * a->dims[2] * 3;
    return a->components == b->components && a->frame_count == b->frame_count && !strcmp(a->notes, b->notes) &&
           !a->colour == !b->colour && (!a->colour || !memcmp(a->colour, b->colour, rgb));
}

/* path loaded by our own parser: its volume, or NULL with why in err. */
static inline vxl_volume *load_own_parser(const char *path, const vxl_load_options *opt, char *err, size_t n)
{
    const char *helper = own_parser_helper();
    char *saved = getenv("VOXLIGHT_READ_DICOM") ? strdup(getenv("VOXLIGHT_READ_DICOM")) : NULL;
    setenv("VOXLIGHT_READ_DICOM", helper ? helper : "missing", 1);
    vxl_volume *own = NULL;
    snprintf(err, n, "%s", vxl_volume_load(path, opt, &own) ? vxl_last_error() : "");
    if (saved) setenv("VOXLIGHT_READ_DICOM", saved, 1);
    else unsetenv("VOXLIGHT_READ_DICOM");
    free(saved);
    return own;
}

/* vxl_volume_load of a DICOM path through the dcmtk helper (its message in
 * vxl_last_error on failure), checked against our own parser (above). */
static inline int load_dicom_with(const char *path, const vxl_load_options *opt, vxl_volume **out)
{
    char own_error[2048];
    vxl_volume *own = load_own_parser(path, opt, own_error, sizeof own_error);
    const int rc = vxl_volume_load(path, opt, out);
    const vxl_volume *ref = rc ? NULL : *out;
    g_own_compared++;
    if (ref && own && same_volume(ref, own) && same_geometry(ref, own)) {
        /* agreed */
    } else if (ref && !own && strstr(own_error, "is not decoded on this system") &&
               (strstr(own_error, "dcmdjpeg") || strstr(own_error, "dcmdjpls"))) {
        g_own_refused++;
    } else if (!ref && !own) {
        /* both refused */
    } else {
        g_own_disagreed++;
        fprintf(stderr, "  own parser and dcmtk disagree on '%s' (series %s, frame %u): dcmtk %s, own %s\n", path,
                opt && opt->series ? opt->series : "-", opt ? opt->frame : 0, ref ? "loaded it" : vxl_last_error(),
                own ? "loaded a different volume" : own_error);
    }
    vxl_volume_destroy(own);
    return rc;
}

/* The volume at path (series: NULL, an index or a UID), NULL on failure
 * (vxl_last_error says why). */
static inline vxl_volume *load_dicom(const char *path, const char *series, uint32_t frame)
{
    vxl_load_options opt = {.struct_size = sizeof opt, .series = series, .frame = frame};
    vxl_volume *v = NULL;
    if (load_dicom_with(path, &opt, &v) != VXL_OK) return NULL;
    return v;
}

/* The last test of each DICOM test program: our own parser read every file
 * the program loaded as dcmtk did. */
#define OWN_PARSER_TEST                                                                              \
    TEST(own_parser_agrees_with_dcmtk)                                                                \
    {                                                                                                  \
        fprintf(stderr, "  own parser: %d loads compared, %d refused by name (dcmtk-only codecs)\n",   \
                g_own_compared, g_own_refused);                                                      \
        CHECK(g_own_compared > 0);                                                                   \
        CHECKF(g_own_disagreed == 0, "%d of %d loads differ", g_own_disagreed, g_own_compared);      \
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
