/* loaders.h - the file loaders, and the dispatch (volume_load.c) that picks
 * one for a path. Arrows go one way: the dispatch calls the loaders, the
 * loaders call volume.h (limits, building a volume), and volume.c knows no
 * loader. */
#ifndef VXL_LOADERS_H
#define VXL_LOADERS_H

#include "error.h"
#include "volume.h"
#include "voxlight.h"

/* NIfTI-1/2 reader (.nii, .nii.gz, .hdr/.img[.gz]); in nifti.c. */
int vxl_nifti_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);

/* The other file loaders, same contract as vxl_nifti_load: *out is NULL on
 * failure, every failure is a vxl_fail naming the file, sizes from headers
 * pass vxl_volume_check_limits before any allocation. */
/* NRRD (.nrrd attached, .nhdr detached; raw/gzip); in nrrd.c. */
int vxl_nrrd_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* MetaImage (.mha, .mhd + ElementDataFile; raw/zlib); in metaimage.c. */
int vxl_metaimage_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* The readers that need OpenImageIO or dcmtk run in helper processes, so
 * this library links only the C runtime (reader_stream.h); these start the
 * helper and rebuild its volume after checking everything it sent; in
 * remote_readers.c. A missing helper or library is an error naming it.
 * TIFF/PNG: a multi-page TIFF, a numbered series (slice_0001.tif ...) or a
 * folder of images (image_stack.cpp in voxlight-read-oiio). */
int vxl_image_stack_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* 0 where vxl_image_stack_load cannot run (its library has no build for
 * this OS): a TIFF that can stream then streams whatever its size. */
int vxl_image_stack_reader_runs_here(void);
/* OpenVDB scalar grid (vdb.cpp in voxlight-read-oiio). */
int vxl_vdb_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* An OpenEXR World map of at most max_pixels pixels (environment_exr.cpp in
 * voxlight-read-oiio): *rgb is malloc'd linear RGB float, 3 a pixel, row 0
 * at the bottom (free() it). */
int vxl_environment_exr_load(const char *path, uint64_t max_pixels, float **rgb, uint32_t *width, uint32_t *height,
                             vxl_err *e);
/* DICOM: a folder, a DICOMDIR or one file of a series (dicom.cpp in
 * voxlight-read-dicom). */
int vxl_dicom_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* OME-Zarr (v2 and v3): the image's folder, optionally "#level=N&c=N"
 * (zarr_read.c in voxlight-read-zarr; docs/zarr.md). */
int vxl_zarr_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* The dispatch's OME-Zarr entry: a streamed volume over the store's chunks
 * (zarr_source.c) when vxl_load_options.streaming asks for one, else
 * vxl_zarr_load. */
int vxl_zarr_load_any(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* Whether path (a folder, maybe followed by "#options") is a Zarr store:
 * it holds .zattrs, .zgroup or zarr.json; in zarr_detect.c. The path may
 * also name one of those files (the store is its folder). */
int vxl_zarr_path_is_zarr(const char *path);
/* 1 for "zarr.json", ".zattrs" and ".zgroup". */
int vxl_zarr_metadata_name(const char *name);
/* Whether a folder holds DICOM (a DICOMDIR, or "DICM" files) or a file is
 * DICOM, for the dispatch; in dicom_detect.c. */
int vxl_dicom_path_is_dicom(const char *path, int is_dir);

#endif
