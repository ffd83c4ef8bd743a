/* helper_main.h - the helper processes' side of reader_stream.h: each
 * helper (helper_oiio.c, helper_dicom.c) lists the commands it serves and
 * hands its argv to vxl_helper_main, which runs the in-process reader and
 * streams the result to libvoxlight. Helpers only: nothing here is linked
 * into libvoxlight.so. */
#ifndef VXL_HELPER_MAIN_H
#define VXL_HELPER_MAIN_H

#include <stdint.h>

#include "volume.h"

typedef struct vxl_helper_command {
    const char *name; /* argv[1], a VXL_CMD_* */
    /* exactly one of: */
    int (*read)(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
    int (*list)(const char *path, vxl_dicom_series **out, uint32_t *count, vxl_err *e);
    /* an image of at most max_pixels pixels as malloc'd linear RGB float
     * (3 a pixel, row 0 at the bottom) */
    int (*image)(const char *path, uint64_t max_pixels, float **rgb, uint32_t *width, uint32_t *height, vxl_err *e);
} vxl_helper_command;

/* main() of a helper: parses argv (reader_stream.h), runs the command and
 * writes the reply to stdout. Returns the exit status. */
int vxl_helper_main(const char *helper, int argc, char **argv, const vxl_helper_command *cmds, int n_cmds);

/* The in-process readers the helpers run; same contract as the loaders in
 * volume.h (*out NULL on failure, a vxl_fail naming the file, limits checked
 * before allocating). */
/* TIFF/PNG through OpenImageIO: a multi-page TIFF, a numbered series
 * (slice_0001.tif ...) or a folder of images; in image_stack.cpp. */
int vxl_image_stack_read(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* OpenVDB scalar grid through OpenImageIO's OpenVDB reader; in vdb.cpp. */
int vxl_vdb_read(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* An OpenEXR World map through OpenImageIO; in environment_exr.cpp. */
int vxl_environment_exr_read(const char *path, uint64_t max_pixels, float **rgb, uint32_t *width, uint32_t *height,
                             vxl_err *e);
/* DICOM through dcmtk: a folder, a DICOMDIR or one file of a series; in
 * dicom.cpp. */
int vxl_dicom_read(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* Every series under path, sorted by UID: *out is malloc'd (free() it),
 * *count entries, each with struct_size = sizeof(vxl_dicom_series). */
int vxl_dicom_read_series(const char *path, vxl_dicom_series **out, uint32_t *count, vxl_err *e);

#endif
