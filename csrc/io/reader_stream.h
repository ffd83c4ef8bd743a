/* reader_stream.h - the readers that need heavy C++ libraries run in helper
 * processes, so that libvoxlight.so links only the C runtime and a reader
 * that crashes (Debian's libopenvdb aborts on some corrupt files) or whose
 * library is missing cannot take the host (Blender) down:
 *   voxlight-read-oiio   TIFF/PNG stacks and OpenVDB, through OpenImageIO
 *   voxlight-read-dicom  DICOM, through dcmtk
 *   voxlight-read-zarr   OME-Zarr, through libzstd and libblosc (zarr.h)
 * One helper per library, so a missing library breaks only its formats.
 * reader_spawn.c starts a helper next to libvoxlight.so and checks what it
 * sends; helper_main.c is the helpers' side. This is the pipe protocol both
 * sides share. Both ends are the same build on the same machine: native
 * layout, no versioning beyond the magic. */
#ifndef VXL_READER_STREAM_H
#define VXL_READER_STREAM_H

#include <stdint.h>
#include <string.h>

#include "volume.h" /* VXL_VOLUME_NOTES_MAX */

/* The helpers' file names; they sit next to libvoxlight.so. The variable
 * named like the file (upper case, '-' as '_') overrides where one is
 * (tests, unusual installs). */
#define VXL_HELPER_OIIO "voxlight-read-oiio"
#define VXL_HELPER_OIIO_ENV "VOXLIGHT_READ_OIIO"
#define VXL_HELPER_DICOM "voxlight-read-dicom"
#define VXL_HELPER_DICOM_ENV "VOXLIGHT_READ_DICOM"
#define VXL_HELPER_ZARR "voxlight-read-zarr" /* OME-Zarr: libzstd, libblosc (zarr.h) */
#define VXL_HELPER_ZARR_ENV "VOXLIGHT_READ_ZARR"
/* Overrides every helper's time limit in seconds (tests). */
#define VXL_READER_TIMEOUT_ENV "VOXLIGHT_READER_TIMEOUT"

/* The helpers' commands (argv[1]). */
#define VXL_CMD_STACK "stack"              /* TIFF/PNG stack -> a volume */
#define VXL_CMD_VDB "vdb"                  /* OpenVDB grid -> a volume */
#define VXL_CMD_DICOM "dicom"              /* DICOM series -> a volume */
#define VXL_CMD_DICOM_SERIES "dicom-series" /* DICOM folder -> vxl_dicom_series[] */
#define VXL_CMD_ZARR "zarr"                /* OME-Zarr level -> a volume */
#define VXL_CMD_ENVIRONMENT "environment"  /* OpenEXR World map -> an image */

/* argv: HELPER COMMAND PATH MAX_DIM BUDGET_BYTES VOXEL_X VOXEL_Y VOXEL_Z
 * FRAME SERIES OPACITY_SOURCE OPACITY_CHANNEL CHANNELS SCALAR_CHANNEL
 * (SERIES may be ""): the load options, defaults resolved. The opacity
 * source travels because it decides what a colour volume's scalar is, which
 * the helper builds; the channels mode and scalar channel likewise decide
 * whether an axis is channels and which is the scalar. */
#define VXL_HELPER_ARGC 14

/* 04: the header carries a multi-channel volume's channels, whose packed
 * 16-bit texels follow the colour (03 added a colour volume's components and
 * RGB8 colour, 02 the notes); a helper left over from an older build is
 * refused as sending no valid header, not misread. */
#define VXL_READER_MAGIC "VXLRD04"
#define VXL_READER_MSG_MAX 1024 /* longest error message a helper may send */

#define VXL_REPLY_VOLUME 1u /* body: the volume's texels */
#define VXL_REPLY_SERIES 2u /* body: count vxl_dicom_series records */
/* body: dims[0] x dims[1] pixels of linear RGB float (components 3, dims[2]
 * 1), row 0 at the bottom; at most BUDGET_BYTES / 12 pixels */
#define VXL_REPLY_IMAGE 3u

/* The helper writes this header to stdout, then either msg_len bytes of
 * error message (status != 0) or nbytes of body, colour_bytes of colour and
 * channel_bytes of channels. For a volume the fields are those of the
 * vxl_volume the in-process reader built (volume.h, colour_volume.h,
 * channel_volume.h): a colour volume's texels are its opacity source's
 * scalar, and its RGB8 colour (3 bytes a voxel, x fastest) follows them; a
 * grey volume has components 1 and no colour. A multi-channel volume's
 * texels are its scalar channel's, and its packed 16-bit channels (the
 * groups of vxl_volume.channels, 2 bytes a channel a voxel) come last; the
 * receiver charges them to the budget with the texels before allocating. */
typedef struct vxl_reader_header {
    char magic[8];          /* VXL_READER_MAGIC, NUL-padded */
    uint32_t status;        /* VXL_OK or the VXL_ERR_* of the failure */
    uint32_t msg_len;
    uint32_t kind;          /* VXL_REPLY_* */
    uint32_t count;         /* series records (VXL_REPLY_SERIES) */
    uint32_t record_size;   /* sizeof(vxl_dicom_series) (VXL_REPLY_SERIES) */
    uint32_t dims[3];
    uint32_t src_dtype, texture_bits, nifti_version, affine_source;
    uint32_t frame_count, frame;
    uint32_t components;    /* 1 grey, 3 RGB, 4 RGBA (vxl_volume.components) */
    uint32_t opacity_source; /* VXL_OPACITY_SOURCE_* of a colour volume's texels; 0 for grey */
    double tex_lo, tex_hi, value_min, value_max;
    double spacing[3];
    double affine[16];      /* column-major voxel -> world */
    uint64_t nan_count, inf_count, storage_bytes;
    uint64_t nbytes;        /* body bytes that follow (a volume: its texels) */
    uint64_t colour_bytes;  /* RGB8 colour bytes after the texels: 3 a voxel, or 0 for grey */
    /* vxl_volume.notes (VXL_REPLY_VOLUME): NUL-terminated inside the array,
     * one line of text; all zero otherwise. The receiver refuses anything
     * else. A fixed array keeps the stream one header and one body. */
    char notes[VXL_VOLUME_NOTES_MAX];
    /* A multi-channel volume's (VXL_REPLY_VOLUME; all zero otherwise):
     * channel_count 0 or 2..VXL_MAX_CHANNELS, and the vxl_volume fields of
     * the same names. */
    uint32_t channel_count, scalar_channel;
    double ch_tex_lo[VXL_MAX_CHANNELS], ch_tex_hi[VXL_MAX_CHANNELS];
    double ch_min[VXL_MAX_CHANNELS], ch_max[VXL_MAX_CHANNELS];
    uint64_t channel_bytes; /* packed channel bytes after the colour */
    vxl_channel_meta ch_meta[VXL_MAX_CHANNELS];
} vxl_reader_header;

/* Copies a multi-channel volume's fields between the header and the
 * volume (to_header 1: v -> h, the helper's side; 0: h -> v, the
 * library's); the channels themselves travel after the colour. */
static inline void vxl_reader_channel_fields(vxl_reader_header *h, vxl_volume *v, int to_header)
{
    const struct { void *h, *v; size_t n; } f[] = {
        {&h->channel_count, &v->channel_count, sizeof h->channel_count},
        {&h->scalar_channel, &v->scalar_channel, sizeof h->scalar_channel},
        {h->ch_tex_lo, v->ch_tex_lo, sizeof h->ch_tex_lo}, {h->ch_tex_hi, v->ch_tex_hi, sizeof h->ch_tex_hi},
        {h->ch_min, v->ch_min, sizeof h->ch_min}, {h->ch_max, v->ch_max, sizeof h->ch_max},
        {h->ch_meta, v->ch_meta, sizeof h->ch_meta}};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; i++)
        memcpy(to_header ? f[i].h : f[i].v, to_header ? f[i].v : f[i].h, f[i].n);
}

/* tests/python/test_vdb_isolation.py packs this layout by hand. */
_Static_assert(sizeof(vxl_channel_meta) == 96, "vxl_channel_meta has padding: the stream would carry junk");
_Static_assert(sizeof(vxl_reader_header) == 1848, "vxl_reader_header layout changed: update the tests' format");

#endif
