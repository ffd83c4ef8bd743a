/* volume_load.c - vxl_volume_load: picks the loader for a path. NIfTI,
 * NRRD and MetaImage are read in this process; TIFF/PNG stacks, OpenVDB and
 * DICOM in helper processes (remote_readers.c, reader_stream.h), except an
 * uncompressed multi-page TIFF that streams (tiff_layout.h). */
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "loaders.h"
#include "files.h"
#include "stream_load.h"
#include "tiff_layout.h"

/* A single TIFF file: its pages are read by offset when its directories
 * allow it (tiff_layout.h) and the plan streams (ON, or AUTO over half the
 * budget, or AUTO where the OpenImageIO helper cannot run: Windows);
 * otherwise the helper reads it whole, as before, and over the budget the
 * error says why it could not stream. */
static int vxl_tiff_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    const uint32_t mode = vxl_load_streaming(opt);
    if (mode == VXL_STREAMING_OFF) return vxl_image_stack_load(path, opt, out, e);
    vxl_tiff_layout t;
    vxl_err probe = {0};
    int rc = vxl_tiff_layout_probe(path, opt, &t, &probe);
    /* a file shorter than its directories claim: under ON the error names it;
     * under AUTO the whole read answers as it always has */
    if (rc == VXL_ERR_FORMAT && mode == VXL_STREAMING_ON) {
        vxl_tiff_layout_free(&t);
        return vxl_fail(e, rc, "%s", probe.msg);
    }
    if (rc == VXL_OK && t.page_offsets) {
        int stream = 0;
        uint64_t nbytes = 0;
        rc = vxl_stream_plan(path, t.dims, t.dtype, opt, NULL, &stream, &nbytes, e);
        if (!rc && !stream && !vxl_image_stack_reader_runs_here()) stream = 1; /* its only reader here */
        if (rc || stream) {
            vxl_raw_layout l;
            if (!rc) rc = vxl_tiff_raw_layout(path, &t, opt, &l, e);
            if (!rc) rc = vxl_stream_load(&l, opt, out, e); /* the source copies the page table */
            vxl_tiff_layout_free(&t);
            return rc;
        }
    }
    char why[sizeof t.why];
    snprintf(why, sizeof why, "%s", rc == VXL_OK && !t.page_offsets ? t.why : "");
    vxl_tiff_layout_free(&t);
    rc = vxl_image_stack_load(path, opt, out, e);
    return rc == VXL_ERR_LIMIT && why[0] && e ? vxl_fail_not_streamable(e, rc, e->msg, why) : rc;
}

static int has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* Loader dispatch: a folder is an image stack; then the extension; then,
 * for unknown extensions, the first bytes. NIfTI is the default, so its
 * reader names the problem for anything unrecognised. */
typedef int (*vxl_loader_fn)(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);

static vxl_loader_fn vxl_loader_for(const char *path)
{
    if (vxl_zarr_path_is_zarr(path)) return vxl_zarr_load_any; /* before the folder test: "store.zarr#level=1" */
    if (vxl_is_dir(path))
        return vxl_dicom_path_is_dicom(path, 1) ? vxl_dicom_load : vxl_image_stack_load;
    static const struct { const char *ext; vxl_loader_fn fn; } by_ext[] = {
        {".nii", vxl_nifti_load}, {".nii.gz", vxl_nifti_load}, {".hdr", vxl_nifti_load},
        {".img", vxl_nifti_load}, {".hdr.gz", vxl_nifti_load}, {".img.gz", vxl_nifti_load},
        {".nrrd", vxl_nrrd_load}, {".nhdr", vxl_nrrd_load},
        {".mha", vxl_metaimage_load}, {".mhd", vxl_metaimage_load},
        {".tif", vxl_tiff_load}, {".tiff", vxl_tiff_load}, {".png", vxl_image_stack_load},
        {".vdb", vxl_vdb_load},
        {".dcm", vxl_dicom_load}, {".dicom", vxl_dicom_load}, {"DICOMDIR", vxl_dicom_load},
    };
    for (size_t i = 0; i < sizeof by_ext / sizeof by_ext[0]; i++)
        if (has_suffix(path, by_ext[i].ext)) return by_ext[i].fn;
    unsigned char m[16] = {0};
    FILE *f = vxl_fopen(path, "rb");
    if (f) {
        size_t n = fread(m, 1, sizeof m, f);
        fclose(f);
        if (n >= 4 && !memcmp(m, "NRRD", 4)) return vxl_nrrd_load;
        if (n >= 4 && !memcmp(m, " BDV", 4)) return vxl_vdb_load; /* OpenVDB magic 0x56444220, little-endian */
        if (n >= 8 && !memcmp(m, "\x89PNG\r\n\x1a\n", 8)) return vxl_image_stack_load;
        if (n >= 4 && (!memcmp(m, "II*\0", 4) || !memcmp(m, "MM\0*", 4) || !memcmp(m, "II+\0", 4) ||
                       !memcmp(m, "MM\0+", 4)))
            return vxl_tiff_load; /* classic TIFF or BigTIFF */
        if (n >= 5 && (!strncasecmp((const char *)m, "ObjectType", 10) || !strncasecmp((const char *)m, "NDims", 5)))
            return vxl_metaimage_load;
    }
    if (vxl_dicom_path_is_dicom(path, 0)) return vxl_dicom_load; /* "DICM" after the 128-byte preamble */
    return vxl_nifti_load;
}

int vxl_volume_load(const char *path, const vxl_load_options *opt, vxl_volume **out)
{
    if (!out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (!path || !*path) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "path is empty");
    vxl_loader_fn fn = vxl_loader_for(path);
    vxl_err e = {0};
    int rc = fn(path, opt, out, &e);
    /* these formats are read whole even when streaming is asked
     * for; over the budget, say that streaming would not have helped. */
    const char *whole_only = fn == vxl_dicom_load ? "DICOM" : fn == vxl_image_stack_load ? "TIFF/PNG image stacks"
                             : fn == vxl_vdb_load ? "OpenVDB" : NULL;
    if (rc == VXL_ERR_LIMIT && whole_only && vxl_load_streaming(opt) != VXL_STREAMING_OFF)
        return vxl_fail_not_streamable(NULL, rc, e.msg, whole_only);
    return rc;
}
