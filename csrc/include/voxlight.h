/*
 * voxlight.h - the one public header of libvoxlight.
 *
 * Conventions (chosen so ctypes can bind everything from this file alone):
 *  - Opaque handles; destroy(NULL) is a no-op.
 *  - Parameter structs are plain data with fixed-width fields only (no enums,
 *    no bitfields). Their all-zero value means "default" for every field.
 *    Each starts with `struct_size`, which the caller sets to sizeof(struct);
 *    0 is accepted and means "the size of this ABI version". A smaller
 *    size, that of an older release of the struct, is accepted too: the
 *    library reads (or, for output structs, writes) only the bytes it covers
 *    and gives the fields beyond it their defaults.
 *  - Every call returns an int: VXL_OK (0) or a VXL_ERR_* code. The message of
 *    the last failure is available per handle (vxl_renderer_error) and, for
 *    every failing call including those before a handle exists, from the
 *    calling thread's vxl_last_error().
 *  - Every enumeration the CLI and the add-on offer has its names declared
 *    below it, so no caller keeps its own list: vxl_*_name(value) returns
 *    NULL past the last value (list them by counting up to the first NULL);
 *    vxl_*_from_name(name, &value) is case-insensitive and fails with
 *    VXL_ERR_INVALID_ARGUMENT for an unknown name.
 *  - Test and benchmark hooks (the gradient probe, phantoms, the reference
 *    renderer, the pre-integration table and the developer fields marked
 *    "developer hook" below) are declared in voxlight_dev.h, not here.
 *  - Output buffers are allocated by the caller.
 *  - Matrices are 4x4, column-major, OpenGL convention.
 *  - Images are row 0 = bottom (OpenGL and Blender Image.pixels order).
 *  - Voxel space: voxel (i,j,k) has its centre at integer coordinates; the
 *    volume box is [-0.5, dim-0.5] on each axis. The volume's model matrix
 *    maps voxel space to world space (NIfTI: millimetres).
 */
#ifndef VOXLIGHT_H
#define VOXLIGHT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define VXL_API __attribute__((visibility("default")))
#else
#define VXL_API
#endif

#define VXL_ABI_VERSION 1u

/* ---- error codes ---- */
#define VXL_OK 0
#define VXL_ERR_INVALID_ARGUMENT 1 /* a bad parameter value */
#define VXL_ERR_IO 2               /* cannot open / read / write a file */
#define VXL_ERR_FORMAT 3           /* file is corrupt, truncated or unsupported */
#define VXL_ERR_LIMIT 4            /* over the memory budget or a size limit */
#define VXL_ERR_NO_MEMORY 5        /* an allocation failed */
#define VXL_ERR_BACKEND 6          /* no usable OpenGL context backend */
#define VXL_ERR_GL 7               /* an OpenGL call failed */
#define VXL_ERR_SHADER 8           /* a shader failed to compile or link */
#define VXL_ERR_STATE 9            /* call made in the wrong state (e.g. no volume) */
#define VXL_ERR_CANCELLED 10       /* the caller's progress callback asked to stop */

/* ---- data types of voxels ---- */
#define VXL_DTYPE_U8 1
#define VXL_DTYPE_I8 2
#define VXL_DTYPE_U16 3
#define VXL_DTYPE_I16 4
#define VXL_DTYPE_U32 5
#define VXL_DTYPE_I32 6
#define VXL_DTYPE_F32 7
#define VXL_DTYPE_F64 8
#define VXL_DTYPE_COUNT 9 /* one past the last; 0 is no type */
/* "uint8" ... "float64"; NULL for 0 (no type) as well as past the last. */
VXL_API const char *vxl_dtype_name(uint32_t dtype);

/* ---- backends ---- */
#define VXL_BACKEND_AUTO 0   /* Linux: EGL on a GPU, then OSMesa, then EGL on Mesa; Windows: WGL */
#define VXL_BACKEND_OSMESA 1
#define VXL_BACKEND_EGL 2
#define VXL_BACKEND_WGL 3    /* Windows' OpenGL */
#define VXL_BACKEND_COUNT 4
VXL_API const char *vxl_backend_name(uint32_t backend); /* "auto", "osmesa", "egl" */
VXL_API int vxl_backend_from_name(const char *name, uint32_t *out);

/* ---- gradient filters ---- */
#define VXL_FILTER_CENTRAL 0     /* 6 taps, the default */
#define VXL_FILTER_FORWARD3 1    /* 3 taps against the centre sample */
#define VXL_FILTER_SOBEL8 2      /* 8 trilinear taps at (+-d,+-d,+-d) */
#define VXL_FILTER_SOBEL14 3     /* 6 faces + 8 corners */
#define VXL_FILTER_SOBEL26 4     /* classic weighted 26-neighbour Sobel */
#define VXL_FILTER_PRECOMPUTED 5 /* blur + Sobel once per volume, stored */
#define VXL_FILTER_CUBIC 6       /* derivative of the interpolating cubic B-spline, 64 texel reads */
#define VXL_FILTER_CUBIC_SMOOTH 7 /* derivative of the approximating cubic B-spline (no prefilter):
                                     smooth normals on noisy and 8-bit scans, 64 texel reads */
#define VXL_FILTER_COUNT 8
VXL_API const char *vxl_filter_name(uint32_t filter); /* "central", ..., "cubic-smooth" */
VXL_API int vxl_filter_from_name(const char *name, uint32_t *out);

/* ---- classification modes ---- */
#define VXL_CLASSIFY_POST 0    /* interpolate the value, then look it up (default) */
#define VXL_CLASSIFY_PRE 1     /* classify voxels first, then interpolate RGBA; shading uses the data gradient */
#define VXL_CLASSIFY_PREINT 2  /* pre-integrated segments from a 2D (front, back) table */
#define VXL_CLASSIFY_COUNT 3
VXL_API const char *vxl_classify_name(uint32_t mode); /* "post", "pre", "preint" */
VXL_API int vxl_classify_from_name(const char *name, uint32_t *out);

/* ---- gradient-magnitude opacity ---- */
#define VXL_GOPACITY_OFF 0
#define VXL_GOPACITY_BOUNDARY 1
#define VXL_GOPACITY_ISO 2
#define VXL_GOPACITY_COUNT 3
VXL_API const char *vxl_gradient_opacity_name(uint32_t mode); /* "off", "boundary", "iso" */
VXL_API int vxl_gradient_opacity_from_name(const char *name, uint32_t *out);

/* ---- transfer-function presets ---- */
#define VXL_PRESET_AUTO 0 /* MRI or CT default, chosen from the data range */
#define VXL_PRESET_GRAY 1
#define VXL_PRESET_BONE 2
#define VXL_PRESET_HOT 3
#define VXL_PRESET_MRI 4
#define VXL_PRESET_CT 5
#define VXL_PRESET_COUNT 6
VXL_API const char *vxl_preset_name(uint32_t preset); /* "auto", "gray", ... */
VXL_API int vxl_preset_from_name(const char *name, uint32_t *out);

/* ---- precomputed gradient storage ---- */
#define VXL_GRADIENT_STORE_8BIT 0  /* RGBA8 signed-normalised, raw gradient / global max */
#define VXL_GRADIENT_STORE_16F 1   /* RGBA16F, same scaling */
#define VXL_GRADIENT_STORE_32F 2   /* RGBA32F, same scaling: exact, for tests and references */
#define VXL_GRADIENT_STORE_COUNT 3
VXL_API const char *vxl_gradient_store_name(uint32_t store); /* "8bit", "16f", "32f" */
VXL_API int vxl_gradient_store_from_name(const char *name, uint32_t *out);

/* ---- volume storage on the GL side (vxl_renderer_options.storage) ---- */
#define VXL_STORAGE_AUTO 0    /* one texture when it fits the texture limit and budget, else bricked,
                                 else sparse */
#define VXL_STORAGE_DENSE 1   /* one 3D texture */
#define VXL_STORAGE_BRICKED 2 /* bricks with a ghost border in a pool texture, a page table maps them;
                                 constant bricks cost nothing */
#define VXL_STORAGE_SPARSE 3  /* bricked, and only the bricks the classification can see are resident;
                                 over the budget, a 2x/4x/8x coarser level (stats.lod_level) */
#define VXL_STORAGE_COMPRESSED 4 /* bricked, each data brick a palette of <= 256 values and 8-bit codes;
                                    decoded on the GL side into a linear cache the ray caster filters
                                    natively (deferred filtering) */
#define VXL_STORAGE_COUNT 5
VXL_API const char *vxl_storage_name(uint32_t storage); /* "auto", "dense", ... */
VXL_API int vxl_storage_from_name(const char *name, uint32_t *out);

#define VXL_MAX_LIGHTS 8

typedef struct vxl_volume vxl_volume;
typedef struct vxl_renderer vxl_renderer;

/* ---------------------------------------------------------------- volumes */

typedef struct vxl_load_options {
    uint32_t struct_size;
    uint32_t max_dim;             /* largest size of any axis; 0 = 65536 */
    uint64_t memory_budget_bytes; /* largest voxel storage; 0 = 2 GiB */
    /* Appended after ABI 1's first release; read only when struct_size
     * covers it (0 = all of this header's struct). */
    double voxel_size[3];         /* x, y, z in mm for inputs without geometry
                                     (TIFF/PNG stacks); 0 = 1 mm */
    /* 4D inputs (NIfTI dim[4..7] > 1): which volume to read, 0 = the first.
     * Only that volume is read (seek in .nii, stream through .nii.gz);
     * vxl_volume_info.frame_count says how many there are. */
    uint32_t frame;
    uint32_t reserved0;
    /* DICOM folders holding several series: the SeriesInstanceUID, or the
     * 0-based index in vxl_dicom_list_series order, as a string. NULL or ""
     * = the only series (an error listing them when there are several). */
    const char *series;
    /* Appended (data larger than memory); read only when
     * struct_size covers them. A streamed volume is described by a brick
     * source that reads bricks on demand (docs/streaming.md): its voxels are
     * never all in memory at once, on the CPU side or the GL side.
     *   AUTO  stream when the voxels (in texture format) exceed half of
     *         memory_budget_bytes, else read whole (today's path)
     *   OFF   read whole; over the budget is VXL_ERR_LIMIT (today's)
     *   ON    stream whatever the size
     * Uncompressed NIfTI, NRRD and MetaImage are read by offset;
     * gzip-compressed files (.nii.gz, detached gzip NRRD data) are streamed
     * through once into a bricked cache (compressed per brick, with the
     * min-max and a downsampled pyramid) that later opens read; OME-Zarr
     * reads its chunks and uses its multiscale pyramid as the levels.
     * Formats without random access or a cache (TIFF/PNG stacks, DICOM,
     * OpenVDB, gzip data attached to a NRRD header, zlib MetaImage) are
     * read whole, and over the budget are VXL_ERR_LIMIT saying streaming
     * is not available for them. */
    uint32_t streaming;           /* VXL_STREAMING_* */
    uint32_t reserved1;           /* must be 0 */
    const char *cache_dir;        /* where bricked caches go; NULL or "": beside the source file
                                     (a read-only folder: $XDG_CACHE_HOME/voxlight, else ~/.cache/voxlight) */
    /* Called now and then during long work (the first pass over a file, a
     * cache being written) with the fraction done in [0, 1] and what is being
     * done; a nonzero return cancels: the call fails with VXL_ERR_CANCELLED
     * and leaves no partial cache behind. NULL: no progress. May be called
     * from the calling thread only. */
    int (*progress)(void *user, double fraction, const char *stage);
    void *progress_user;
    /* Appended (colour volumes); read only when struct_size covers them. A
     * colour volume (RGB or RGBA: NIfTI RGB24/RGBA32 and vector NIfTI, or
     * vxl_volume_desc.components 3/4) is one scalar volume that goes through
     * the whole pipeline (filters, classification, skipping, gradients,
     * storage, cutaways, shading) plus the voxels' own colour, which replaces
     * the transfer function's colour (vxl_render_params.color_source). The
     * scalar is the opacity source: its transfer function gives opacity, its
     * gradient the normals. Choosing it at load time (not per frame) is what
     * keeps every derived volume a derived volume of one scalar.
     *   LUMINANCE (0)  Rec. 709 luminance 0.2126 R + 0.7152 G + 0.0722 B
     *   CHANNEL        channel opacity_channel (0 R, 1 G, 2 B, 3 A)
     *   ALPHA          the alpha channel (RGBA only)
     * Grey volumes ignore both. docs/colour.md. */
    uint32_t opacity_source;      /* VXL_OPACITY_SOURCE_* */
    uint32_t opacity_channel;     /* CHANNEL: 0..components-1 */
    /* Appended (multi-channel volumes, docs/channels.md); read only when
     * struct_size covers them. A multi-channel volume holds up to
     * VXL_MAX_CHANNELS scalars on one grid (fluorescence: nuclei, membranes,
     * a protein), each classified on its own when params.channels lists it;
     * its scalar (what everything else renders, `info` and the histogram
     * report) is channel scalar_channel. Which inputs load as channels:
     *   AUTO (0)  an axis that cannot be colour: NIfTI 5D whose dim[5] > 1
     *             is not an RGB(A) vector (dim[4] counts the frames), NRRD
     *             whose component axis and MetaImage whose
     *             ElementNumberOfChannels is 2 or 5..8, an OME-Zarr c axis
     *             of 2..8 (without "#c=N"), a TIFF of 2..8 grey samples,
     *             an OME-TIFF whose OME-XML says SizeC 2..8
     *   ON        also a 2..4-entry axis that AUTO leaves as it was (colour,
     *             RGB(A) or grey+alpha samples, or a 5D NIfTI's frames)
     *   OFF       none: NIfTI 5D counts every volume as a frame, NRRD and
     *             MetaImage refuse what cannot be colour, OME-Zarr reads
     *             channel 0, TIFF its first samples and OME-TIFF its pages
     *             as slices, as before channels
     * The volume's notes say which was chosen and why. */
    uint32_t channels;            /* VXL_CHANNELS_* */
    uint32_t scalar_channel;      /* which channel is the scalar; 0 = the first */
} vxl_load_options;

#define VXL_CHANNELS_AUTO 0
#define VXL_CHANNELS_ON 1
#define VXL_CHANNELS_OFF 2
#define VXL_CHANNELS_COUNT 3
#define VXL_MAX_CHANNELS 8 /* channels of one volume, sampled in one ray march */
#define VXL_CHANNEL_NAME_MAX 64 /* vxl_volume_info.channel_names[c], its NUL included */
VXL_API const char *vxl_channels_mode_name(uint32_t mode); /* "auto", "on", "off" */
VXL_API int vxl_channels_mode_from_name(const char *name, uint32_t *out);

#define VXL_OPACITY_SOURCE_LUMINANCE 0
#define VXL_OPACITY_SOURCE_CHANNEL 1
#define VXL_OPACITY_SOURCE_ALPHA 2
#define VXL_OPACITY_SOURCE_COUNT 3
VXL_API const char *vxl_opacity_source_name(uint32_t source); /* "luminance", "channel", "alpha" */
VXL_API int vxl_opacity_source_from_name(const char *name, uint32_t *out);

#define VXL_STREAMING_AUTO 0
#define VXL_STREAMING_OFF 1
#define VXL_STREAMING_ON 2
#define VXL_STREAMING_COUNT 3
VXL_API const char *vxl_streaming_name(uint32_t mode); /* "auto", "off", "on" */
VXL_API int vxl_streaming_from_name(const char *name, uint32_t *out);

/* A volume handed over from memory (e.g. a numpy array). Data is x fastest:
 * index = i + dims[0]*(j + dims[1]*k), native byte order. */
typedef struct vxl_volume_desc {
    uint32_t struct_size;
    uint32_t dtype;        /* VXL_DTYPE_*; 0 is invalid */
    uint32_t dims[3];
    uint32_t has_affine;   /* 0: affine = diag(spacing) */
    const void *data;
    double spacing[3];     /* voxel size in mm; 0 = 1 */
    double affine[16];     /* voxel -> world, column-major */
    double scl_slope;      /* value = raw*slope + inter; slope 0 = no scaling */
    double scl_inter;
    /* Appended (colour volumes); read only when struct_size covers them.
     * 0 or 1: grey; 3 (RGB) or 4 (RGBA): `components` values per voxel,
     * interleaved (index = c + components * voxel), of dtype each; the
     * scalar is chosen by vxl_load_options.opacity_source. */
    uint32_t components;
    uint32_t reserved;     /* must be 0 */
    /* Appended (multi-channel volumes, docs/channels.md); read only when
     * struct_size covers them. 0 or 1: one scalar; 2..VXL_MAX_CHANNELS:
     * that many scalars of dtype on the grid (components must then be 0 or
     * 1), planar (channel slowest: index = voxel + n_voxels * c, as NIfTI 5D
     * and a numpy (C, Z, Y, X) array store them) or interleaved
     * (index = c + channels * voxel). scl_slope/scl_inter apply to all. */
    uint32_t channels;
    uint32_t channels_interleaved; /* 1: interleaved; 0: planar */
} vxl_volume_desc;

#define VXL_NOTES_MAX 512 /* vxl_volume_info.notes, its NUL included */

typedef struct vxl_volume_info {
    uint32_t struct_size;
    uint32_t dtype;             /* VXL_DTYPE_* of the source data */
    uint32_t dims[3];
    uint32_t nifti_version;     /* 1 or 2 for NIfTI files, 0 otherwise */
    double spacing[3];          /* voxel size (mm) */
    double affine[16];          /* voxel -> world (mm), column-major */
    double value_min;           /* finite range after scl_slope/scl_inter */
    double value_max;
    uint64_t nan_count;         /* NaN voxels (treated as value_min) */
    uint64_t inf_count;         /* +-Inf voxels (clamped to the finite range) */
    uint64_t storage_bytes;     /* bytes of voxel storage (texture) */
    uint32_t texture_bits;      /* 8, 16 (normalised) or 32 (float) */
    uint32_t affine_source;     /* 0 none (spacing), 1 qform, 2 sform */
    /* Appended: written only when the caller's struct_size covers them. */
    uint32_t frame_count;       /* volumes in a 4D input; 1 for 3D */
    uint32_t frame;             /* which of them this volume is */
    /* Appended. */
    uint32_t streamed;          /* 1: read on demand from a brick source (vxl_load_options.streaming) */
    uint32_t level_count;       /* resolution levels the source offers (1 = full only) */
    uint64_t resident_bytes;    /* CPU bytes the volume holds now (whole: its voxels; streamed: its
                                   index, coarse level and brick cache) */
    uint64_t bytes_read;        /* bytes read from the file (or cache) so far, by all users */
    /* Appended: what the reader decided for the user to know, so an import
     * never guesses silently ("PixelSpacing missing: 1 mm assumed"): UTF-8,
     * one line, a sentence per decision joined by "; ", cut with "..." when
     * full; "" when it decided nothing. Written only when struct_size covers
     * all of it. */
    char notes[VXL_NOTES_MAX];
    /* Appended (colour volumes): written only when struct_size covers them. */
    uint32_t components;        /* 1 grey, 3 RGB, 4 RGBA: what the source holds */
    uint32_t opacity_source;    /* VXL_OPACITY_SOURCE_* the scalar came from (colour volumes; 0 grey) */
    uint64_t color_bytes;       /* bytes of the voxels' own colour (RGB8, 3 a voxel; 0 grey) */
    /* Appended (multi-channel volumes): written only when struct_size covers them. */
    uint32_t channel_count;     /* 0: not a multi-channel volume; else 2..VXL_MAX_CHANNELS */
    uint32_t scalar_channel;    /* the channel the scalar is */
    double channel_min[VXL_MAX_CHANNELS]; /* each channel's finite data range (after scaling) */
    double channel_max[VXL_MAX_CHANNELS];
    uint64_t channel_bytes;     /* bytes of the channels on the GL side (16 bits a channel a voxel) */
    /* Appended (what a multi-channel file says about its channels: OME-Zarr's
     * "omero" metadata, OME-TIFF's OME-XML <Channel>): written only when
     * struct_size covers them; zero (and "" names) where the file says
     * nothing, for channels >= channel_count and for volumes without
     * channels. docs/channels.md lists what each format fills. */
    char channel_names[VXL_MAX_CHANNELS][VXL_CHANNEL_NAME_MAX]; /* UTF-8, NUL-terminated; "" unnamed */
    /* The file's display colour as it wrote it: sRGB, display-referred, each
     * component in [0, 1] (OME's "RRGGBB" / 0xRRGGBBAA divided by 255), NOT
     * decoded to linear. A renderer working in scene-linear decodes it
     * (vxl_render_params' channel colours are linear). Meaningful only where
     * channel_color_known[c] is 1. */
    float channel_colors[VXL_MAX_CHANNELS][3];
    uint32_t channel_color_known[VXL_MAX_CHANNELS];
    /* The file's display window (data units of that channel: omero
     * "window" start/end), meaningful where channel_window_known[c] is 1. */
    double channel_window_low[VXL_MAX_CHANNELS];
    double channel_window_high[VXL_MAX_CHANNELS];
    uint32_t channel_window_known[VXL_MAX_CHANNELS];
    /* 1: shown at first (the file says so, or says nothing); 0: the file
     * marks the channel hidden (omero "active": false). Only for
     * c < channel_count. */
    uint32_t channel_active[VXL_MAX_CHANNELS];
} vxl_volume_info;

VXL_API int vxl_volume_load(const char *path, const vxl_load_options *opt, vxl_volume **out);
VXL_API int vxl_volume_create(const vxl_volume_desc *desc, const vxl_load_options *opt,
                              vxl_volume **out);
VXL_API int vxl_volume_get_info(const vxl_volume *vol, vxl_volume_info *out);
/* Counts of the volume's voxels (data units, NaN voxels excluded) in `bins`
 * equal bins over [lo, hi]; values outside are not counted. Works for every
 * loader, so a UI can show the histogram of any format. */
VXL_API int vxl_volume_histogram(const vxl_volume *vol, uint32_t bins, double lo, double hi,
                                 uint64_t *counts);
/* The same counts of one channel of a multi-channel volume (data units of
 * that channel, from the 16 bits it is drawn from; docs/channels.md), for a
 * UI's per-channel histogram. VXL_ERR_STATE for a volume without channels,
 * VXL_ERR_INVALID_ARGUMENT for a channel it does not have. */
VXL_API int vxl_volume_channel_histogram(const vxl_volume *vol, uint32_t channel, uint32_t bins, double lo,
                                         double hi, uint64_t *counts);
VXL_API void vxl_volume_destroy(vxl_volume *vol);

/* ---------------------------------------------------------------- DICOM */

/* One series of a DICOM folder (vxl_volume_load takes a folder, a DICOMDIR
 * or one file of the series; see vxl_load_options.series). */
typedef struct vxl_dicom_series {
    uint32_t struct_size;
    uint32_t slice_count;       /* images in the series (a multi-frame file counts its frames) */
    uint32_t dims[3];           /* columns, rows, slices the volume will have (positions, or the
                                   even grid an uneven series is resampled to) */
    uint32_t loadable;          /* 1: passes every check made before pixels are read */
    uint32_t frame_count;       /* time points (4D: as many files at every position) */
    double gantry_tilt_deg;     /* angle between the slice normal and the stacking
                                   direction; loads with a sheared affine */
    char uid[72];               /* SeriesInstanceUID */
    char modality[20];
    char description[72];       /* SeriesDescription */
    char problem[256];          /* why it does not load; "" when loadable */
} vxl_dicom_series;

/* Lists the series under path (folder, DICOMDIR or one file: its folder),
 * sorted by UID. Up to max entries go to out (stride out[0].struct_size, 0 =
 * sizeof); *count receives how many series there are. out may be NULL with
 * max 0 to count. */
VXL_API int vxl_dicom_list_series(const char *path, vxl_dicom_series *out, uint32_t max, uint32_t *count);

/* ------------------------------------------------------- label tables */

/* One entry of a label lookup table: what a label id of a
 * segmentation is called and how it looks. */
typedef struct vxl_label_entry {
    uint32_t struct_size;
    int32_t id;                 /* the label's value in the label volume */
    float color[4];             /* straight RGBA in [0, 1]; alpha 1 unless the file gives one */
    uint32_t visible;           /* 1 unless the file hides it (ITK-SNAP's VIS column) */
    char name[64];              /* UTF-8, NUL-terminated, cut to fit; "" when the file names none */
    /* Appended, read only when struct_size covers them: the
     * label's own material when has_material is 1 (ambient, diffuse,
     * specular, shininess as params' material: >= 0 each, shininess > 0),
     * used wherever the label's samples are lit (SURFACE, and MASK/TINT
     * samples inside it); 0: the frame's. The table files set none. */
    uint32_t has_material;
    float material[4];
} vxl_label_entry;

/* Reads a label lookup table: FreeSurfer's LUT.txt, ITK-SNAP label
 * descriptions, 3D Slicer colour tables (.ctbl), and MRIcron's .lut
 * (binary 256-entry palette; the names come from the .txt of the same
 * stem beside it when there is one). The format is detected from the
 * content. Entries are sorted by id, ids unique. Up to max entries go to
 * out (stride out[0].struct_size, 0 = sizeof); *count receives how many
 * the file has. out may be NULL with max 0 to count. */
VXL_API int vxl_label_table_load(const char *path, vxl_label_entry *out, uint32_t max, uint32_t *count);

/* -------------------------------------------------------------- renderer */

typedef struct vxl_renderer_options {
    uint32_t struct_size;
    uint32_t backend;             /* VXL_BACKEND_*; env VOXLIGHT_BACKEND overrides AUTO */
    uint64_t memory_budget_bytes; /* GPU storage budget; 0 = 2 GiB */
    const char *shader_dir;       /* developer override: load shaders from disk.
                                     NULL = embedded (env VOXLIGHT_SHADER_DIR overrides) */
    /* Appended; read only when struct_size covers them. */
    uint32_t storage;             /* VXL_STORAGE_*; 0 = AUTO */
    uint32_t page_brick;          /* voxels per brick edge when bricked: 8, 16, 32 or 64; 0 = 32 */
    /* Appended. Developer hook (voxlight_dev.h): leave 0. */
    uint32_t compressed_domain;
} vxl_renderer_options;

typedef struct vxl_renderer_info {
    uint32_t struct_size;
    uint32_t backend;          /* the backend actually opened */
    int32_t max_3d_texture_size;
    uint32_t reserved;
    char backend_name[32];
    char gl_renderer[128];
    char gl_version[128];
} vxl_renderer_info;

typedef struct vxl_light {
    float position[4];  /* world space; w = 0: direction the light travels FROM
                           (towards the light), w = 1: position of a point light */
    float color[3];     /* 0,0,0 = white */
    float intensity;    /* 0 = 1 */
} vxl_light;

/* How a light is shaped. params.light_shapes[i] goes with
 * params.lights[i]; all zero is a plain light (today's). The array's stride
 * is light_shapes[0].struct_size. */
typedef struct vxl_light_shape {
    uint32_t struct_size;
    float spot_direction[3]; /* point light (w = 1) only: world direction the spot points along
                                (a cone on a directional light is an error) */
    float spot_angle;        /* full cone angle, radians (Blender's spot_size); 0 = no cone */
    float spot_blend;        /* 0..1, soft edge as Blender's spot_blend: the cone's mask is
                                smoothstep(0, 1, (cos a - cos(angle/2)) / ((1 - cos(angle/2)) * blend)),
                                a hard edge at 0 */
    float size;              /* softness of its shadows: a directional light's angular diameter
                                (radians, Blender's sun angle), a point light's radius (world
                                units, Blender's shadow_soft_size); 0 = hard */
} vxl_light_shape;

/* Shading models, params.shading_model. With T_i the transmittance
 * from the sample to light i through the classified volume (exp of minus the
 * optical depth, opacity per voxel of path as the ray caster composites it;
 * the path ends where it leaves the volume, or at a point light's position),
 * averaged over the light's extent when its shape has a size (a sun: the
 * directions of a cone of angular diameter size around its direction; a
 * point light: the points of a disc of radius size at its position, facing
 * the sample), AO the ambient occlusion (the mean transmittance over all
 * directions of the sphere, uniformly in voxel space, along rays of
 * ambient_occlusion voxels from the sample; 1 when that is 0) and s the
 * occlusion_strength; n the unit normal (the gradient's direction, turned
 * to face the eye), l and h the unit vectors towards light i and halfway
 * between it and the eye, and L_i the light's colour * intensity * its spot
 * mask (vxl_light_shape.spot_blend, with a the angle between spot_direction
 * and the direction from the light to the sample; 1 for a light without a
 * cone):
 *   PHONG     today's local shading: ambient + sum of the lights' diffuse and
 *             specular terms (L_i * (diffuse * max(n.l, 0) * colour + specular
 *             * max(n.h, 0)^shininess), 0 where n.l <= 0); no shadows, and
 *             light_shapes are ignored (no spot mask: L_i without it).
 *   SHADOWED  ambient * (1 - s (1 - AO)) + sum of T_i * (the light's diffuse
 *             and specular terms).
 *   SCATTER   ambient * (1 - s (1 - AO)) + sum of T_i * (w * (the light's
 *             diffuse and specular terms) + (1 - w) * L_i * diffuse * colour
 *             * 4 pi * HG(cos t, g)), the
 *             hybrid of Kroes et al. 2012: w = min(1, |grad| / gradient_ref) of
 *             the normalised value per voxel (gradient_ref 0 = 0.05), HG the
 *             Henyey-Greenstein phase function with g = anisotropy and t the
 *             angle between the light's travel and the direction to the eye
 *             (g > 0 scatters forward, towards a viewer facing the light):
 *             4 pi HG = (1 - g^2) / (1 + g^2 - 2 g cos t)^1.5, 1 for g = 0.
 *   PATH      multiple scattering by Monte Carlo volume path tracing of the
 *             medium of docs/physical_model.md: from the eye, delta tracking
 *             against a majorant per skipping brick finds where the path
 *             collides (extinction -ln(1 - a) per voxel of path, a the
 *             table's opacity times opacity_scale); every collision adds
 *             SCATTER's terms there (lamps times T_i, the ambient or the
 *             World, with w), unclamped, times the path's throughput, and the
 *             path goes on (up to path_bounces collisions) in a direction
 *             drawn from HG(g) (probability 1 - w, throughput * colour) or
 *             cosine-weighted about n (probability w, throughput * min(diffuse,
 *             1) * colour). path_bounces 1 is SCATTER's sum without its clamp,
 *             integrated exactly along the ray instead of in steps. The alpha
 *             and depth are the ray's opacity as the emission-absorption
 *             march gives it (no noise). The image is the mean of samples
 *             path_sample_offset .. + path_samples - 1, each a function of
 *             (path_seed, pixel, sample index) only: the same call gives the
 *             same image bit for bit, and vxl_path_accumulate merges
 *             consecutive calls into the mean of all their samples (see
 *             there). PATH classifies after interpolation whatever
 *             `classify` says; clip planes and the crop box remove the medium
 *             from every segment of a path (no caps); it refuses gradient
 *             opacity, modes other than DVR, the slicing techniques, the
 *             MatCap, cutter meshes, label maps and overlays
 *             (VXL_ERR_INVALID_ARGUMENT, naming them).
 * "ambient" is the material's ambient * colour; each model's result is
 * clamped to [0, 1] per channel (PATH's sum is not). A sample whose gradient vanishes has no
 * normal: PHONG and SHADOWED leave it unlit (its colour, as today), SCATTER
 * and PATH keep only their ambient and phase terms (w = 0).
 * shading_off still gives pure emission-absorption. */
#define VXL_SHADING_PHONG 0
#define VXL_SHADING_SHADOWED 1
#define VXL_SHADING_SCATTER 2
#define VXL_SHADING_PATH 3
#define VXL_SHADING_COUNT 4
VXL_API const char *vxl_shading_model_name(uint32_t model); /* "phong", "shadowed", "scatter", "path" */
VXL_API int vxl_shading_model_from_name(const char *name, uint32_t *out);

/* Rendering techniques, params.technique. The slice-based ones are
 * comparison modes for the benchmark (Engel et al., Real-Time Volume Graphics,
 * ch. 3), with the ray caster's classification and shading. */
#define VXL_TECHNIQUE_RAYCAST 0
#define VXL_TECHNIQUE_SLICES2D 1 /* object-aligned slice stacks, the stack chosen by view direction */
#define VXL_TECHNIQUE_SLICES3D 2 /* view-aligned slices, proxy polygons clipped to the box */
#define VXL_TECHNIQUE_COUNT 3
VXL_API const char *vxl_technique_name(uint32_t technique); /* "raycast", "slices2d", "slices3d" */
VXL_API int vxl_technique_from_name(const char *name, uint32_t *out);

/* Render modes, params.mode. The projections classify the value
 * they project: colour = the transfer function's colour at it (after the
 * window), opacity = its opacity (times opacity_scale, clamped to 1) as one
 * opaque-or-not layer, not per voxel of path; depth = where the projected
 * sample lies (MIP, MinIP), where the ray enters the kept volume (AVERAGE).
 *   DVR      emission-absorption ray casting (today's)
 *   MIP      the largest value along the ray inside the kept volume
 *   MINIP    the smallest (at or above minip_floor when minip_floor_on)
 *   AVERAGE  the mean of the samples
 *   ISO      the first crossing of iso_value (data units) along the ray,
 *            refined below the step by bisection (and a last secant step) on
 *            the reconstruction every sample reads, the trilinear one (the
 *            filter gives the surface's normal), shaded as a surface (the
 *            material, lights, shading model or MatCap) with the transfer
 *            function's colour at iso_value, opacity 1; depth = the exact hit.
 * A projection's depth, like DVR's, is written where its opacity reaches
 * depth_threshold (+inf elsewhere). docs/modes.md. */
#define VXL_MODE_DVR 0
#define VXL_MODE_MIP 1
#define VXL_MODE_MINIP 2
#define VXL_MODE_AVERAGE 3
#define VXL_MODE_ISO 4
#define VXL_MODE_COUNT 5
VXL_API const char *vxl_mode_name(uint32_t mode); /* "dvr", "mip", "minip", "average", "iso" */
VXL_API int vxl_mode_from_name(const char *name, uint32_t *out);

/* Cutaways, params.cutaway. A sample is kept when it is inside
 * every clip plane's kept region, inside the crop box (when there is one)
 * and not removed by any cutter; the ray caster, every mode, skipping and
 * early termination see only kept samples. */
#define VXL_MAX_CLIP_PLANES 6
#define VXL_MAX_CUTTERS 4

typedef struct vxl_clip_plane {
    float plane[4];   /* world space a, b, c, d: keeps a x + b y + c z + d >= 0 ((a, b, c) need
                         not be unit length; it must not be zero) */
    float thickness;  /* 0: the half-space; > 0: only the slab of that thickness (world units)
                         on the kept side, 0 <= signed distance <= thickness */
    uint32_t reserved; /* must be 0 */
} vxl_clip_plane;

/* A closed triangle mesh that removes its inside (or, with remove_outside,
 * everything but its inside). Depth-peeled from the camera each frame: the
 * ray skips the removed depth intervals. Faces wind counter-clockwise seen
 * from outside (a mesh wound inward throughout is turned round); at most 8
 * surface crossings per pixel, a pixel crossed more often is drawn empty
 * (docs/cutaways.md). The array's stride is cutters[0].struct_size. */
typedef struct vxl_cutter {
    uint32_t struct_size;
    uint32_t remove_outside;   /* 0: remove the inside; 1: keep only the inside */
    const float *vertices;     /* world xyz, 3 floats per vertex */
    const uint32_t *indices;   /* 3 per triangle, < vertex_count */
    uint32_t vertex_count;
    uint32_t triangle_count;
} vxl_cutter;

typedef struct vxl_cutaway {
    uint32_t struct_size;
    uint32_t clip_plane_count;  /* <= VXL_MAX_CLIP_PLANES */
    vxl_clip_plane clip_planes[VXL_MAX_CLIP_PLANES];
    uint32_t has_crop;          /* 1: keep only the inside of the crop box */
    float crop_box[16];         /* box -> world, column-major: the box is the cube [-1, 1]^3 of this
                                   (non-singular) matrix, e.g. a Blender cube Empty's matrix_world
                                   times its display size */
    uint32_t cutter_count;      /* <= VXL_MAX_CUTTERS */
    const vxl_cutter *cutters;
    uint32_t caps_off;          /* 0: caps on: the first kept sample (within one step) behind a cut surface is
                                   shaded with the cut's normal (facing the eye) instead of the
                                   data gradient; 1: the data gradient everywhere */
    uint32_t reserved;          /* must be 0 */
} vxl_cutaway;

/* A MatCap, params.matcap: a picture of a lit sphere that fills
 * the image. With one, the shaded colour of a sample (DVR with shading on,
 * ISO) is its classified colour times the MatCap's colour at the view-space
 * normal: texel (0.5 + 0.5 n.x, 0.5 + 0.5 n.y) of the image (linear, row 0
 * = bottom), instead of the material and lights. */
typedef struct vxl_matcap {
    uint32_t struct_size;
    uint32_t width, height;     /* >= 1 each, <= 4096 */
    uint32_t reserved;          /* must be 0 */
    const float *rgba;          /* width*height*4 floats (alpha unused) */
    uint64_t key;               /* nonzero: the caller's name for this image, so the same key is
                                   not uploaded again; 0: the library hashes the pixels */
} vxl_matcap;

/* Scene shadows, params.scene_shadows: the scene's opaque meshes
 * as occluders between the lights and the volume. For each light the
 * library rasterises them as seen from the light into a shadow map and
 * multiplies the light's transmittance T_i (see the shading models) by the
 * map's visibility, so meshes shadow the volume in the SHADOWED and SCATTER
 * models (PHONG has no T_i). Shadow maps are rebuilt only when the
 * occluders (their key), a light or the volume's placement change. */
typedef struct vxl_scene_shadows {
    uint32_t struct_size;
    uint32_t occluder_vertex_count;
    const float *occluder_vertices;  /* world xyz, 3 floats per vertex */
    const uint32_t *occluder_indices; /* 3 per triangle, < occluder_vertex_count */
    uint32_t occluder_triangle_count;
    uint32_t shadow_map_size;        /* texels per side, 16..8192; 0 = 1024 (a point light inside or
                                        beside the volume's box gets a cube of six such maps) */
    uint64_t occluder_key;           /* nonzero: the caller's version of the occluders (same key =
                                        unchanged, no rebuild); 0: the library hashes them */
} vxl_scene_shadows;

/* Label maps, params.labels with a label volume set by
 * vxl_renderer_set_labels. Label ids are never interpolated as numbers.
 * Boundaries (`boundary`):
 *   SMOOTH (0, the default) each label's indicator (1 on its voxels)
 *          smoothed with a Gaussian (sigma 1.2 voxels) when the label volume
 *          is set, with every voxel centre kept inside its own label; the
 *          boundary is its 0.5 level, interpolated trilinearly, the normal
 *          its gradient: no voxel stairs (docs/labels.md).
 *   VOXELS (1) each sample is in the label of its nearest voxel: the
 *          voxels' cube faces, with their face normals.
 * At a sample, the label is the one of the eight surrounding voxels the
 * sample lies deepest in (none where that one is hidden or unlisted).
 * Labels take the DVR mode and the ray caster (technique 0).
 *   SURFACE  label-only: the first visible label the ray meets is shaded as
 *            an opaque-per-alpha surface with its colour and the lights.
 *   MASK     the intensity volume's transfer function, only inside visible
 *            labels (a hidden label cuts its region away).
 *   TINT     as MASK, with the transfer function's colour multiplied by the
 *            label's colour. */
#define VXL_LABEL_MODE_SURFACE 0
#define VXL_LABEL_MODE_MASK 1
#define VXL_LABEL_MODE_TINT 2
#define VXL_LABEL_MODE_COUNT 3
VXL_API const char *vxl_label_mode_name(uint32_t mode); /* "surface", "mask", "tint" */
VXL_API int vxl_label_mode_from_name(const char *name, uint32_t *out);
#define VXL_MAX_LABEL_ID 65535 /* label ids in [0, VXL_MAX_LABEL_ID]; 0 is the background */

typedef struct vxl_label_style {
    uint32_t struct_size;
    uint32_t mode;               /* VXL_LABEL_MODE_* */
    uint32_t entry_count;        /* entries in `entries` */
    uint32_t reserved;           /* must be 0 */
    const vxl_label_entry *entries; /* colour (alpha = opacity per voxel of path) and visibility per id;
                                       ids not listed are hidden; stride entries[0].struct_size. Changing
                                       them re-uploads only a small table, never the label volume */
    /* appended: read only when struct_size covers it (older callers get SMOOTH) */
    uint32_t boundary;           /* VXL_LABEL_BOUNDARY_*: 0 smooth */
    uint32_t reserved2;          /* must be 0 */
} vxl_label_style;
#define VXL_LABEL_BOUNDARY_SMOOTH 0 /* smoothed per label, no voxel stairs */
#define VXL_LABEL_BOUNDARY_VOXELS 1 /* the raw voxels' faces */

/* Overlays: up to VXL_MAX_OVERLAYS more volumes in the same ray
 * march as the renderer's volume, each set with vxl_renderer_set_overlay
 * and drawn when params.overlays lists its slot. Each has its own affine
 * (placement), transfer function, window, interpolation and GL storage;
 * they overlap in space and are sampled together at every step of the ray
 * (in the base volume's voxel steps), which marches over the union of all
 * the volumes' boxes and skips only where every volume is empty (the union
 * of their occupancies). At each step the base volume's sample and each
 * overlay's (classified: colour c_i, opacity per step a_i after the step
 * correction) combine by the overlay's blend:
 *   OVER  one medium: extinctions add and emissions mix by their share,
 *         a = 1 - prod(1 - a_i), colour = sum(w_i c_i) with
 *         w_i = ln(1 - a_i) / sum_j ln(1 - a_j) (the exact mixture of
 *         media each constant over the step)
 *   ADD   the overlay's emission a_i c_i is added to the step's colour
 *         without absorbing anything (a glow: PET hot spots); what lies in
 *         front still attenuates it
 *   MAX   the step takes the overlay's sample where its opacity exceeds
 *         that of the rest of the step
 * OVER overlays mix first, then MAX ones, then ADD ones add. Overlays
 * render in the DVR mode with the ray caster (technique 0); another mode,
 * technique or the SURFACE label mode with overlays is VXL_ERR_INVALID_ARGUMENT.
 * docs/overlays.md. */
#define VXL_MAX_OVERLAYS 3 /* with the base volume, 4 volumes in one ray march */
#define VXL_BLEND_OVER 0
#define VXL_BLEND_ADD 1
#define VXL_BLEND_MAX 2
#define VXL_BLEND_COUNT 3
VXL_API const char *vxl_blend_name(uint32_t blend); /* "over", "add", "max" */
VXL_API int vxl_blend_from_name(const char *name, uint32_t *out);

typedef struct vxl_overlay_style {
    uint32_t struct_size;
    uint32_t slot;              /* < VXL_MAX_OVERLAYS: the volume set by vxl_renderer_set_overlay */
    uint32_t blend;             /* VXL_BLEND_* */
    uint32_t interpolation;     /* VXL_INTERP_*: 0 (nearest) ... see below; the default is LINEAR:
                                   interpolation_set 0 means linear. CUBIC is here the approximating
                                   cubic B-spline (smooth, never overshoots: docs/overlays.md) */
    uint32_t interpolation_set; /* 1: use interpolation as given (so NEAREST, 0, can be asked) */
    uint32_t preset;            /* VXL_PRESET_* used when tf_rgba is NULL */
    uint32_t tf_size;           /* entries in tf_rgba (>= 2) */
    uint32_t has_window;        /* 0: the preset's default window / the data range */
    const float *tf_rgba;       /* straight RGBA, opacity per voxel of the base volume's path */
    float window_low, window_high; /* data units of the overlay */
    float opacity_scale;        /* 0 = 1 */
    uint32_t shading_off;       /* 0: lit like the base volume (the frame's shading model, lights
                                   and material, with its own central-difference gradient); 1: emission only */
    uint32_t has_model;         /* 0: its own affine */
    float model[16];            /* voxel -> world, column-major */
    uint32_t reserved;          /* must be 0 */
} vxl_overlay_style;

/* One channel of a multi-channel volume in params.channels. Its sample's
 * straight colour is color * the table's rgb at the windowed value, its
 * opacity the table's alpha (per voxel of path) * opacity_scale, lit (the
 * frame's Phong shading and lights) with the channel's own gradient.
 * How the channels combine, params.channel_blend:
 *   ADD (0)  each channel is composited along the ray on its own, and the
 *            pixel is the sum of the channels' images (clamped to 1):
 *            channels glow through each other, as napari's and Imaris's
 *            additive blending; the image equals the sum of the channels
 *            drawn one at a time
 *   MAX      at each step the channel with the largest opacity is the
 *            sample, composited front to back as one medium: the dominant
 *            channel hides what lies behind it
 * A channel not listed, hidden, or (when any listed channel has solo 1)
 * not solo is not drawn and does not count for empty-space skipping, which
 * skips where every drawn channel is empty (the union of their occupancy).
 * Multi-channel drawing takes the ray caster's DVR mode, post
 * classification, dense storage and PHONG shading (or none); anything
 * else is VXL_ERR_INVALID_ARGUMENT naming what. */
typedef struct vxl_channel_style {
    uint32_t struct_size;
    uint32_t channel;           /* < the volume's channel_count; listed once */
    uint32_t hidden;            /* 1: not drawn (stays listed, so a UI can toggle it) */
    uint32_t solo;              /* 1: while any listed channel is solo, only solo ones are drawn */
    uint32_t has_color;         /* 0: the default colour of its index (docs/channels.md) */
    float color[3];             /* linear RGB, each in [0, 1] */
    uint32_t has_window;        /* 0: the channel's data range */
    float window_low, window_high; /* data units of the channel */
    uint32_t preset;            /* VXL_PRESET_* when tf_rgba is NULL; AUTO (0) = GRAY, a ramp */
    uint32_t tf_size;           /* entries in tf_rgba (>= 2) */
    const float *tf_rgba;       /* straight RGBA, opacity per voxel of path */
    float opacity_scale;        /* 0 = 1 */
    uint32_t reserved;          /* must be 0 */
} vxl_channel_style;
#define VXL_CHANNEL_BLEND_ADD 0
#define VXL_CHANNEL_BLEND_MAX 1
#define VXL_CHANNEL_BLEND_COUNT 2
VXL_API const char *vxl_channel_blend_name(uint32_t blend); /* "add", "max" */
VXL_API int vxl_channel_blend_from_name(const char *name, uint32_t *out);

/* The World's light, params.environment: a linear-RGB latitude-longitude
 * map (equirectangular, as Blender's Environment Texture), times strength,
 * turned about world +Z by rotation_deg, lighting every sample from every
 * direction with the volume's own occlusion of it (docs/lighting.md).
 * Pixel (i, j), row j = 0 at the bottom (the nadir), is the radiance
 * arriving from map direction m with azimuth atan2(m.y, m.x) = pi (1 - 2 u)
 * and elevation asin(m.z) = pi (v - 1/2), u = (i + 0.5) / width,
 * v = (j + 0.5) / height: the centre column looks along +X, a quarter to
 * its left along +Y (Cycles' equirectangular mapping). World direction d
 * sees map direction m = Rz(rotation_deg) d, as a Mapping node (type Point)
 * with that Z rotation in front of the texture: rotating by +90 degrees
 * brings what the map shows along +X to world -Y. A 1x1 map is a uniform
 * colour (Blender's Background colour).
 *   SHADOWED, SCATTER  the ambient term is replaced by diffuse * colour *
 *             E(x), E(x) the environment's radiance averaged over the
 *             sphere with each direction's transmittance through the
 *             volume to the box (isotropic: neither the normal nor the
 *             anisotropy weighs it); E = the map's mean radiance where
 *             nothing occludes.
 *   PHONG     the ambient term is replaced by diffuse * colour * the map's
 *             mean radiance (no occlusion).
 * With an environment and light_count 0 there are no lamps: the headlight
 * stands in only when nothing else lights the volume. */
typedef struct vxl_environment {
    uint32_t struct_size;
    uint32_t width, height;     /* >= 1 each; width * height <= 2^26 */
    uint32_t reserved;          /* must be 0 */
    const float *rgb;           /* width*height*3 floats, linear radiance, finite and >= 0 */
    float strength;             /* multiplies rgb; >= 0 (0 = dark: no light from the World) */
    float rotation_deg;         /* about world +Z, see above; finite */
    uint64_t key;               /* nonzero: the caller's name for these pixels (the same key is not
                                   reduced again); 0: the library hashes them */
} vxl_environment;

/* Reads a World map file for vxl_environment: Radiance RGBE (.hdr, .pic;
 * flat or run-length-encoded scanlines, "-Y H +X W" or "+Y H +X W") into
 * linear RGB floats, row 0 at the bottom. *width and *height receive its
 * size; rgb NULL (max_pixels ignored) reads the header only, so a caller
 * can size the buffer: rgb then holds width*height*3 floats, and a map of
 * more than max_pixels pixels is VXL_ERR_LIMIT. A corrupt or truncated file
 * is VXL_ERR_FORMAT saying what is wrong. OpenEXR (.exr, any of its codecs;
 * the first three channels, or a grey one) is read by the OpenImageIO helper
 * process, as TIFF stacks are: negative values read as 0, NaN or infinity is
 * VXL_ERR_FORMAT; where that helper cannot run (Windows, OpenImageIO
 * missing) the error names what to install. Each call reads the whole
 * file, the header-only call too. */
VXL_API int vxl_environment_image_load(const char *path, float *rgb, uint64_t max_pixels, uint32_t *width,
                                       uint32_t *height);

/* 2 words of room: the struct then ends on its 8-byte alignment, with no padding. */
#define VXL_RENDER_PARAMS_RESERVED 2

typedef struct vxl_render_params {
    uint32_t struct_size;
    uint32_t width, height;          /* 0 = 512 */
    uint32_t has_camera;             /* 0: default camera framing the volume */
    float view[16];                  /* world -> view */
    float proj[16];                  /* view -> clip */
    float azimuth_deg;               /* default camera only: rotation about world +Z */
    float elevation_deg;             /* default camera only */
    uint32_t has_model;              /* 0: model = the volume's affine */
    float model[16];                 /* voxel -> world */

    /* Optional scene depth, width*height floats, row 0 = bottom: view-space
     * planar distance (positive, along -Z of view) of opaque geometry;
     * +inf = none. Rays stop there. */
    const float *scene_depth;

    uint32_t filter;                 /* VXL_FILTER_* */
    float sample_distance;           /* gradient tap offset in voxels; 0 = 1.0 */
    uint32_t reuse_gradients;        /* 1: keep previous direction when |g| drops */
    uint32_t gradient_store;         /* VXL_GRADIENT_STORE_* (precomputed filter) */
    float step;                      /* ray step in voxels; 0 = 0.5 */
    uint32_t jitter_off;             /* 1: no per-pixel start jitter */
    uint32_t jitter_seed;            /* varies the deterministic jitter pattern */

    /* classification */
    uint32_t preset;                 /* VXL_PRESET_* used when tf_rgba is NULL */
    uint32_t tf_size;                /* entries in tf_rgba (>= 2) */
    const float *tf_rgba;            /* straight RGBA, opacity per voxel of path */
    uint32_t has_window;             /* 0: window = preset default / data range */
    float window_low, window_high;   /* in data units, mapped onto the TF */
    float opacity_scale;             /* 0 = 1 */
    uint32_t classify;               /* VXL_CLASSIFY_* */

    /* shading */
    uint32_t shading_off;            /* 1: pure emission-absorption */
    uint32_t has_material;           /* 0: defaults below */
    float ambient, diffuse, specular, shininess; /* defaults .3 .7 .3 24 */
    uint32_t light_count;            /* 0: headlight */
    vxl_light lights[VXL_MAX_LIGHTS];

    /* termination and output */
    float early_termination;         /* opacity that stops a ray; 0 = 0.99 */
    float depth_threshold;           /* opacity that defines output depth; 0 = 0.5 */
    uint32_t no_skip;                /* developer hook (voxlight_dev.h): leave 0 */
    uint32_t preint_size;            /* developer hook (voxlight_dev.h): leave 0 */

    /* Levoy's opacity functions (gradient-magnitude opacity), VXL_GOPACITY_*:
     * BOUNDARY multiplies opacity by min(1, |grad| / gradient_ref)^gradient_exp
     * (region boundaries, as MRIcroGL's boundExp and VTK's gradient opacity);
     * ISO draws the iso-surface at iso_value with a constant thickness of
     * iso_thickness voxels: opacity = tf(iso) * (1 - |iso - f| / (r |grad|)). */
    uint32_t gradient_opacity;
    float gradient_ref;              /* normalised value per voxel; 0 = 0.05 */
    float gradient_exp;              /* 0 = 1 */
    float iso_value;                 /* data units (gradient_opacity ISO, mode ISO) */
    float iso_thickness;             /* voxels; 0 = 1 (ISO) */
    /* lighting: see VXL_SHADING_* */
    uint32_t shading_model;          /* VXL_SHADING_* */
    const vxl_light_shape *light_shapes; /* NULL, or light_count entries (stride: their struct_size) */
    float ambient_occlusion;         /* occlusion radius, voxels; 0 = off */
    float occlusion_strength;        /* 0..1; 0 = 1 */
    float anisotropy;                /* Henyey-Greenstein g in (-1, 1), SCATTER */
    uint32_t illumination_size;      /* cells along the illumination volumes' longest side; 0 = automatic */
    /* technique: VXL_TECHNIQUE_* */
    uint32_t technique;
    /* VXL_MODE_* (ISO reads iso_value) */
    uint32_t mode;
    const vxl_cutaway *cutaway;      /* NULL: nothing cut away */
    /* NULL: no scene meshes shadow the volume */
    const vxl_scene_shadows *scene_shadows;
    const vxl_matcap *matcap;        /* NULL: the material and lights */
    /* Room for the next features (fields taken from here keep the struct's
     * size and offsets). Must be zero: vxl_render fails with
     * VXL_ERR_INVALID_ARGUMENT naming the word otherwise. */
    uint32_t reserved[VXL_RENDER_PARAMS_RESERVED];
    /* Appended; read only when struct_size covers it. NULL: no
     * labels (a label volume set on the renderer is then not drawn). */
    const vxl_label_style *labels;
    /* Appended: overlay_count entries (stride overlays[0].struct_size), each naming a
     * slot set with vxl_renderer_set_overlay; 0 / NULL: none drawn. */
    uint32_t overlay_count;     /* <= VXL_MAX_OVERLAYS */
    /* Appended: 1: do not wait for streamed bricks (the viewport): the frame renders at
     * once from what is resident, coarser where finer bricks are still loading on the renderer's
     * loader thread, visible bricks large on screen first; stats.refine_pending > 0 says a later
     * frame will be finer. 0: wait until every brick the frame needs is resident at the finest
     * level the budget allows (F12). Only streamed volumes care. */
    uint32_t progressive;
    const vxl_overlay_style *overlays;
    /* Appended: MinIP's floor. With minip_floor_on, MinIP projects the
     * smallest sample at or above minip_floor (data units): the air around
     * an uncropped scan is every ray's minimum otherwise, so MinIP would
     * show only air. A ray with no sample at or above the floor draws
     * nothing. Other modes ignore both. */
    uint32_t minip_floor_on;
    float minip_floor;
    /* Appended (colour volumes): where a sample's colour comes from,
     * VXL_COLOR_SOURCE_*. AUTO: the voxels' colour when the volume has one
     * (RGB, RGBA), else the transfer function's; DATA: the voxels' colour (a
     * grey volume is VXL_ERR_STATE); TF: the transfer function's, as for a
     * grey volume (the colour volume then renders as its opacity source).
     * Opacity always comes from the transfer function of the scalar. */
    uint32_t color_source;
    /* What the colours mean, VXL_COLOR_SPACE_*. DISPLAY (0): the caller's
     * colours and the image are display-referred (sRGB-encoded), as the
     * CLI's PNGs are. LINEAR: the transfer function's, the labels' and the
     * lights' colours, the environment and the MatCap are scene-linear, and
     * so is the image (premultiplied; colour above 1 where the light makes
     * it, alpha at most 1); the library's own display-referred colours (its
     * presets, a colour volume's RGB) are decoded from sRGB. The lit models
     * are physical only in LINEAR (docs/physical_model.md). This field was
     * reserved2, which had to be 0: DISPLAY keeps those callers' images. */
    uint32_t color_space;
    /* Appended: the World's light (vxl_environment); read only when
     * struct_size covers it. NULL: no environment (the lamps and the
     * ambient term only, as before). */
    const vxl_environment *environment;
    /* Appended (shading model PATH); read only when struct_size covers them,
     * ignored by the other models. A call renders samples path_sample_offset
     * .. path_sample_offset + path_samples - 1 of every pixel and returns
     * their mean. F12: one call with N samples. The viewport: call with
     * offset 0, then offsets 1, 2, ... (path_samples 1 each) while nothing
     * changes, merging each image with vxl_path_accumulate, and start again
     * at offset 0 on any change. Both give the same image within float
     * rounding. */
    uint32_t path_samples;       /* samples per pixel in this call; 0 = 1, at most VXL_PATH_MAX_SAMPLES */
    uint32_t path_sample_offset; /* index of this call's first sample */
    uint32_t path_bounces;       /* collisions per path (1 = single scattering); 0 = VXL_PATH_DEFAULT_BOUNCES,
                                    at most VXL_PATH_MAX_BOUNCES */
    uint32_t path_seed;          /* another seed, another (equally good) noise; the same seed, the same image */
    /* Appended (multi-channel volumes, docs/channels.md); read only when
     * struct_size covers them. channel_count > 0 draws the listed channels
     * of a multi-channel volume in one ray march (one sample of every
     * channel per step) instead of its scalar; the frame's own table and
     * window are then unused. 0: the scalar alone, as before. */
    uint32_t channel_count;     /* <= VXL_MAX_CHANNELS entries in channels */
    uint32_t channel_blend;     /* VXL_CHANNEL_BLEND_* */
    const vxl_channel_style *channels; /* stride channels[0].struct_size */
} vxl_render_params;

#define VXL_PATH_MAX_SAMPLES 65536u
#define VXL_PATH_DEFAULT_BOUNCES 4u
#define VXL_PATH_MAX_BOUNCES 64u

/* Merges one PATH call's image into a running mean: acc (n floats, the mean
 * of samples 0 .. offset - 1, anything when offset is 0) becomes the mean of
 * samples 0 .. offset + samples - 1, given img, the call's image of samples
 * offset .. offset + samples - 1 (rgba, or depth: any n floats). Depth and
 * alpha are the same in every call, so they stay. VXL_ERR_INVALID_ARGUMENT
 * for NULL arrays or samples 0. */
VXL_API int vxl_path_accumulate(float *acc, const float *img, size_t n, uint32_t offset, uint32_t samples);

#define VXL_COLOR_SOURCE_AUTO 0
#define VXL_COLOR_SOURCE_DATA 1
#define VXL_COLOR_SOURCE_TF 2
#define VXL_COLOR_SOURCE_COUNT 3
VXL_API const char *vxl_color_source_name(uint32_t source); /* "auto", "data", "tf" */
VXL_API int vxl_color_source_from_name(const char *name, uint32_t *out);

VXL_API int vxl_renderer_create(const vxl_renderer_options *opt, vxl_renderer **out);
VXL_API void vxl_renderer_destroy(vxl_renderer *r);
VXL_API const char *vxl_renderer_error(const vxl_renderer *r);
VXL_API int vxl_renderer_get_info(vxl_renderer *r, vxl_renderer_info *out);

/* Uploads the volume; the renderer keeps its own copy on the GL side, so the
 * vxl_volume may be destroyed afterwards. */
VXL_API int vxl_renderer_set_volume(vxl_renderer *r, const vxl_volume *vol);

/* Label maps: a volume of integer label ids (u8, u16, i16 or
 * i32 data with values in [0, VXL_MAX_LABEL_ID]; anything else is
 * VXL_ERR_INVALID_ARGUMENT) drawn with params.labels. Its own affine places
 * it (the same grid as the intensity volume or another one). Kept on the GL
 * side like the volume; NULL removes it. */
VXL_API int vxl_renderer_set_labels(vxl_renderer *r, const vxl_volume *labels);

/* Overlays: puts vol in overlay slot `slot` (< VXL_MAX_OVERLAYS),
 * kept on the GL side like the volume (charged to the renderer's budget;
 * over it: VXL_ERR_LIMIT, and the slot keeps what it had). NULL empties the
 * slot. Any grid: its affine places it. */
VXL_API int vxl_renderer_set_overlay(vxl_renderer *r, uint32_t slot, const vxl_volume *vol);

/* rgba: width*height*4 floats, premultiplied. depth: width*height floats
 * (view-space planar distance where opacity passes depth_threshold, +inf
 * where it never does) or NULL. */
VXL_API int vxl_render(vxl_renderer *r, const vxl_render_params *p, float *rgba, float *depth);

/* What the last vxl_render did, counted on the GL side. */
typedef struct vxl_render_stats {
    uint32_t struct_size;
    uint32_t sample_bound;      /* the hard bound on samples per ray in that frame */
    uint64_t samples;           /* samples taken by all rays */
    uint32_t max_ray_samples;   /* samples of the longest ray (<= sample_bound) */
    uint32_t rays;              /* rays that entered the volume */
    float effective_step;       /* step after clamping, voxels */
    uint32_t bricks_total;      /* bricks of the skipping grid (0 when skipping is off) */
    uint32_t bricks_occupied;   /* bricks that can be visible under the classification */
    uint32_t brick_size;        /* voxels per brick edge */
    /* Appended: how the volume is stored on the GL side. */
    uint32_t storage;           /* VXL_STORAGE_* in use (never AUTO) */
    uint64_t resident_bytes;    /* GL memory of the volume: texture, or pool + page table */
    uint32_t page_brick;        /* voxels per page brick edge (0 when dense) */
    uint32_t pages_total;       /* bricks of the page table */
    uint32_t pages_resident;    /* bricks with data in the pool */
    uint32_t pages_constant;    /* bricks stored as one value (no pool space) */
    /* Level-of-detail fallback (sparse storage): 0 = full resolution; k > 0:
     * the visible bricks did not fit the memory budget, so the frame used
     * voxels 2^k times coarser per axis. The page counts above are of that level. */
    uint32_t lod_level;
    uint64_t lod_wanted_bytes;  /* what full resolution would have needed (0 when lod_level is 0) */
    /* Compressed storage: milliseconds the last decode into the linear cache
     * took (GPU, finished), 0 when nothing was decoded for this frame. */
    double decode_ms;
    /* Appended: the illumination volumes of the shadowed and
     * scatter shading models. */
    uint32_t illumination_size;  /* cells along their longest side (coarser than asked when the memory
                                    budget is short); 0 when the frame used none */
    uint32_t illumination_rebuilt; /* volumes (one per light, plus the occlusion) the frame rebuilt: 0
                                      when only the camera moved */
    /* Appended: streamed volumes (0 otherwise). */
    uint32_t refine_pending;    /* bricks the frame wanted finer than it drew (progressive: still loading) */
    uint32_t stream_level;      /* the coarsest level any drawn brick came from (0 = full resolution) */
    uint64_t bytes_read;        /* bytes the frame read from the file or cache */
    double load_ms;             /* milliseconds the frame waited for bricks (progressive: only for the
                                   coarsest level's visible bricks, read once, small) */
    /* Appended: a multi-channel volume's channels on the GL side (0 without):
     * dense textures, or (paged storage) the groups' pools and their page
     * table, as set with the volume (docs/channels.md). */
    uint64_t channel_bytes;
} vxl_render_stats;

VXL_API int vxl_renderer_get_stats(vxl_renderer *r, vxl_render_stats *out);

/* Scene shadows: for every pixel of p->scene_depth (required;
 * seen through p's camera), the transmittance through the volume from that
 * scene point to light `light` (an index into p->lights; with light_count 0
 * the headlight), from the same illumination volume the SHADOWED model
 * reads (built for this light when the frame has none), and cut by
 * p->scene_shadows' occluders as the volume's own shadows are. 1 where the
 * path to the light misses the volume or the depth is +inf (or NaN, or not
 * positive). Exact and approximate parts: docs/scene_shadows.md. out:
 * width*height floats, row 0 = bottom. A compositor multiplies the light's
 * direct contribution by it. */
VXL_API int vxl_scene_transmittance(vxl_renderer *r, const vxl_render_params *p, uint32_t light,
                                    float *out);

/* Slice planes: the volume resampled on a plane. */
#define VXL_INTERP_NEAREST 0
#define VXL_INTERP_LINEAR 1
#define VXL_INTERP_CUBIC 2   /* the interpolating cubic B-spline (as VXL_FILTER_CUBIC) */
#define VXL_INTERP_COUNT 3
VXL_API const char *vxl_interpolation_name(uint32_t interp); /* "nearest", "linear", "cubic" */
VXL_API int vxl_interpolation_from_name(const char *name, uint32_t *out);

typedef struct vxl_slice_params {
    uint32_t struct_size;
    uint32_t interpolation;      /* VXL_INTERP_* */
    float plane_to_world[16];    /* column-major: the slice is the square [-1, 1]^2 at z = 0 of this
                                    matrix (a Blender plane's matrix_world); pixel (x, y) of the output
                                    lies at ((x + 0.5) / width * 2 - 1, (y + 0.5) / height * 2 - 1, 0) */
} vxl_slice_params;

/* Resamples the volume on the slice: p gives the output size (width,
 * height), the volume's placement (has_model / model), the window and the
 * colour map (preset or tf_rgba) and color_source; its camera, shading
 * and mode are not used. rgba (width*height*4 floats, premultiplied): the
 * transfer function's colour at the value (a colour volume's own colour,
 * nearest or trilinear, as color_source says) with alpha 1 inside the
 * volume's box, 0 outside it. plane_to_world must be finite and affine (last row 0 0 0 1)
 * with x and y axes that span an area (its z axis is not used);
 * VXL_ERR_INVALID_ARGUMENT otherwise. Compressed storage has no cubic
 * coefficients (as VXL_FILTER_CUBIC): a cubic slice of it is
 * VXL_ERR_STATE. docs/slicing-planes.md. */
VXL_API int vxl_render_slice(vxl_renderer *r, const vxl_render_params *p, const vxl_slice_params *s,
                             float *rgba);

/* vxl_render_params.color_space */
#define VXL_COLOR_SPACE_DISPLAY 0u /* sRGB-encoded colours in and out (the default) */
#define VXL_COLOR_SPACE_LINEAR 1u  /* scene-linear colours in and out (Blender's, Cycles') */
#define VXL_COLOR_SPACE_COUNT 2u

/* The camera vxl_render uses when has_camera is 0, for callers that want to
 * start from it. */
VXL_API int vxl_default_camera(vxl_renderer *r, const vxl_render_params *p, float view[16],
                               float proj[16]);

/* ---------------------------------------------------- classified grid */

/* The classified volume as a participating medium on a regular grid, for
 * renderers that take density and colour grids (Blender's Volume objects).
 * docs/physical_model.md is the model: with a the transfer function's
 * opacity per voxel of path (after opacity_scale, and the gradient-opacity
 * factor of params.gradient_opacity), the extinction per world unit is
 * -ln(1 - a) / voxel_length, and the albedo is the table's colour made linear. */
typedef struct vxl_grid_params {
    uint32_t struct_size;
    uint32_t dims[3];            /* cells per axis, spread evenly over the volume's box; 0 = the volume's
                                    own voxel count on that axis */
} vxl_grid_params;

typedef struct vxl_grid_info {   /* output */
    uint32_t struct_size;
    uint32_t dims[3];            /* the cells filled */
    double index_to_world[16];   /* column-major: cell (i, j, k)'s centre -> world (the params' model) */
    double voxel_length;         /* world units per voxel of path: the cube root of the model's
                                    determinant (the edge of a cube as large as a voxel) */
    double max_density;          /* the largest density written (0 when density and rgb are NULL) */
} vxl_grid_info;

/* Fills density (dims product floats, x fastest: extinction per world unit,
 * 0 where the clip planes or the crop box of params.cutaway cut the volume
 * away) and rgb (3 floats per cell: the transfer function's straight
 * colour as a linear albedo: decoded from sRGB when p.color_space is
 * DISPLAY, as given when it is LINEAR) for vol classified as p classifies it (preset or
 * table, window, opacity scale, gradient opacity from central differences
 * sample_distance apart). Either buffer may be NULL; both NULL fills info
 * only, so a caller can size its buffers. CPU only: no renderer, no GL.
 * Each cell takes the trilinear value at its centre. Only the DVR mode is a
 * medium; labels and cutter meshes are not baked (VXL_ERR_INVALID_ARGUMENT
 * naming them); a streamed volume is VXL_ERR_STATE (load it whole). */
VXL_API int vxl_classified_grid(const vxl_volume *vol, const vxl_render_params *p, const vxl_grid_params *g,
                                vxl_grid_info *info, float *density, float *rgb);

/* ------------------------------------------------------------------ misc */

VXL_API uint32_t vxl_abi_version(void);
VXL_API const char *vxl_last_error(void);       /* thread-local; "" if none */
VXL_API const char *vxl_error_name(int code);

/* Writes premultiplied RGBA (row 0 = bottom) to .png (straight alpha, 8 bit)
 * or .exr (premultiplied half float, plus a Z channel when depth != NULL). */
VXL_API int vxl_write_image(const char *path, const float *rgba, const float *depth, uint32_t width,
                            uint32_t height);

#ifdef __cplusplus
}
#endif
#endif
