/* volume.h - the CPU-side volume: voxels already converted to the texture
 * format they will be uploaded in, plus geometry and value range. */
#ifndef VXL_VOLUME_H
#define VXL_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "brick_source.h"
#include "error.h"
#include "voxlight.h"

#define VXL_DEFAULT_BUDGET (2ull << 30) /* 2 GiB */
#define VXL_DEFAULT_MAX_DIM 65536u
#define VXL_VOLUME_NOTES_MAX 512 /* vxl_volume.notes, NUL included */

/* What a file says about one of its channels (OME-Zarr omero, OME-XML),
 * all zero when it says nothing: vxl_volume_info's channel_* fields. */
typedef struct vxl_channel_meta {
    double window[2];                /* display window, data units, low < high */
    float color_srgb[3];             /* the file's sRGB display colour in [0, 1], not decoded */
    uint8_t has_color, has_window;
    uint8_t hidden;                  /* the file marks it not shown (omero "active": false) */
    uint8_t reserved;
    char name[VXL_CHANNEL_NAME_MAX]; /* UTF-8, terminated, no control characters */
} vxl_channel_meta; /* no padding: the helper stream sends it as it is (reader_stream.h) */

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
    /* Streamed: texels is NULL and the voxels are read on demand
     * from source (owned; storage_bytes is what reading it whole would take).
     * Code that needs every voxel either reads through source a box at a
     * time or refuses a streamed volume with a clear error. */
    vxl_brick_source *source;
    /* What the reader decided for the user to know: a sentence per decision
     * ("4 slices interpolated where a slice is missing"), joined by "; ". ""
     * when nothing was. Reported by `info`, the add-on and the statistics. */
    char notes[VXL_VOLUME_NOTES_MAX];
    /* A colour volume (colour_volume.h): the voxels' own colour beside the
     * scalar texels, RGB8 interleaved (3 bytes a voxel, x fastest), always in
     * memory (a streamed colour volume streams only its scalar); NULL for a
     * grey volume. The texels are the opacity source's scalar. */
    uint8_t *colour;
    uint32_t components;     /* 1 grey (0 is read as 1), 3 RGB, 4 RGBA: what the source held */
    uint32_t opacity_source; /* VXL_OPACITY_SOURCE_* the texels came from (colour volumes) */
    /* A multi-channel volume (channel_volume.h): channel_count scalars on the
     * grid as 16-bit normalised texels, packed four to a texel in groups
     * (group g at channels + 4 * g * n_voxels holds min(4, count - 4g)
     * channels interleaved, x fastest), always whole in memory; NULL and 0
     * otherwise. The texels above are channel scalar_channel's. */
    uint16_t *channels;
    uint32_t channel_count;
    uint32_t scalar_channel;
    double ch_tex_lo[VXL_MAX_CHANNELS], ch_tex_hi[VXL_MAX_CHANNELS]; /* data = lo + t (hi - lo) per channel */
    double ch_min[VXL_MAX_CHANNELS], ch_max[VXL_MAX_CHANNELS];       /* finite data range per channel */
    vxl_channel_meta ch_meta[VXL_MAX_CHANNELS];                      /* names, colours from the file */
};

/* Appends one note (printf format) to v->notes, "; "-separated; cut with
 * "..." when the notes are full, so the first decisions always survive. */
void vxl_volume_note(vxl_volume *v, const char *fmt, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

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

/* The conversion vxl_volume_build makes, in pieces, for sources that see a
 * volume a slab at a time (io/raw_source.c): the range of raw
 * values first (accumulated over calls into *mn, *mx and the counts; start
 * with mn = +inf, mx = -inf), then the map it fixes, then texels. raw is
 * native-endian dtype; slope 0 = unscaled. */
typedef struct vxl_texel_map {
    uint32_t dtype, bits;
    double slope, inter;    /* slope 0 already replaced by 1 (inter 0) */
    double mn, mx;          /* the finite range (0, 0 when nothing was finite): value_min/max */
    double inv;             /* 32-bit texels: 1 / (mx - mn), 0 for a flat volume */
    double type_lo;         /* 8/16-bit texels: the type's minimum (code = raw - type_lo) */
    double tex_lo, tex_hi;  /* as vxl_volume's */
} vxl_texel_map;

void vxl_raw_range(uint32_t dtype, const void *raw, uint64_t n, double slope, double inter, double *mn, double *mx,
                   uint64_t *nan_count, uint64_t *inf_count);
void vxl_texel_map_init(vxl_texel_map *m, uint32_t dtype, double slope, double inter, double mn, double mx);
void vxl_texels_from_raw(const vxl_texel_map *m, const void *raw, uint64_t n, void *texels);
/* dims, dtype, texture_bits, storage_bytes, spacing (0 -> 1) and affine
 * (NULL: diag(spacing)) of v, as vxl_volume_build sets them. */
void vxl_volume_set_geometry(vxl_volume *v, const uint32_t dims[3], uint32_t dtype, const double spacing[3],
                             const double *affine);
/* value_min/max and tex_lo/hi from a map. */
void vxl_volume_set_values(vxl_volume *v, const vxl_texel_map *m);

/* The loaders that build volumes from files are declared in loaders.h:
 * they call this file, never the reverse. */

#endif
