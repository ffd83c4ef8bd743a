/* volume.h - the CPU-side volume: voxels already converted to the texture
 * format they will be uploaded in, plus geometry and value range. */
#ifndef VXL_VOLUME_H
#define VXL_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "voxlight.h"

#define VXL_DEFAULT_BUDGET (2ull << 30) /* 2 GiB */
#define VXL_DEFAULT_MAX_DIM 65536u

struct vxl_volume {
    uint32_t dims[3];
    uint32_t src_dtype;     /* VXL_DTYPE_* of the source */
    uint32_t texture_bits;  /* 8, 16: unsigned normalised; 32: float in [0,1] */
    uint32_t nifti_version;
    uint32_t affine_source;
    void *texels;           /* dims product * texture_bits/8 bytes */
    uint64_t storage_bytes;
    /* data value = tex_lo + t * (tex_hi - tex_lo) for stored t in [0,1] */
    double tex_lo, tex_hi;
    double value_min, value_max; /* finite data range */
    uint64_t nan_count, inf_count;
    double spacing[3];
    double affine[16];      /* column-major voxel -> world */
    uint32_t frame_count;   /* volumes in the 4D input (0 is read as 1) */
    uint32_t frame;         /* the one this is */
};

/* Checks dims against max_dim and the budget before anything is allocated.
 * bytes_per_voxel is what the texture will cost. */
int vxl_volume_check_limits(const uint32_t dims[3], uint32_t bytes_per_voxel,
                            const vxl_load_options *opt, vxl_err *e);

/* The stored normalised value of voxel i (x fastest), as the GL texture reads it. */
double vxl_volume_texel(const vxl_volume *v, size_t i);

/* Texture bits used for a source dtype. */
uint32_t vxl_texture_bits_for(uint32_t dtype);
uint32_t vxl_dtype_size(uint32_t dtype);

/* Builds a volume from raw native-endian typed data (x fastest). Applies
 * slope/inter (slope 0 = none), counts and neutralises NaN/Inf, normalises
 * into the texture format. affine may be NULL (diag(spacing)). */
int vxl_volume_build(const void *raw, uint32_t dtype, const uint32_t dims[3], const double spacing[3],
                     const double *affine_colmajor, double slope, double inter,
                     const vxl_load_options *opt, vxl_volume **out, vxl_err *e);

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
/* OpenVDB scalar grid (vdb.cpp in voxlight-read-oiio). */
int vxl_vdb_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* DICOM: a folder, a DICOMDIR or one file of a series (dicom.cpp in
 * voxlight-read-dicom). */
int vxl_dicom_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);
/* Whether a folder holds DICOM (a DICOMDIR, or "DICM" files) or a file is
 * DICOM, for the dispatch; in dicom_detect.c. */
int vxl_dicom_path_is_dicom(const char *path, int is_dir);

#endif
