/* channel_volume.h - multi-channel volumes on the CPU side
 * (docs/channels.md): up to VXL_MAX_CHANNELS scalars on one grid, each
 * normalised over its own range into 16 bits and packed four channels to a
 * texel, so the GL side holds them in ceil(n / 4) textures that one ray
 * march samples together. The volume's ordinary scalar (everything that is
 * not multi-channel drawing renders it) is one chosen channel, built by
 * vxl_volume_build exactly as a one-channel volume would be. */
#ifndef VXL_CHANNEL_VOLUME_H
#define VXL_CHANNEL_VOLUME_H

#include <stdint.h>

#include "volume.h"

#define VXL_CHANNEL_BYTES 2u      /* 16 bits a channel a voxel */
#define VXL_CHANNELS_PER_GROUP 4u /* one RGBA16 texel */

/* Builds a volume of `channels` (2..VXL_MAX_CHANNELS) scalars of dtype per
 * voxel, planar (channel slowest) or interleaved (channel fastest).
 * slope/inter scale every channel. opt's scalar_channel picks the scalar
 * (out of range: VXL_ERR_INVALID_ARGUMENT). The budget is checked with the
 * scalar's texels plus 2 bytes a channel a voxel before allocating. `what`
 * names the input in the note ("NIfTI 5D"); NULL adds no note. */
int vxl_volume_build_channels(const void *raw, uint32_t dtype, uint32_t channels, int interleaved,
                              const uint32_t dims[3], const double spacing[3], const double *affine, double slope,
                              double inter, const vxl_load_options *opt, const char *what, vxl_volume **out,
                              vxl_err *e);

/* opt's channels mode and scalar channel (struct_size covering them; else
 * AUTO and 0); an unknown mode is VXL_ERR_INVALID_ARGUMENT. */
int vxl_load_channels_mode(const vxl_load_options *opt, uint32_t *mode, uint32_t *scalar_channel, vxl_err *e);

/* Texture groups of v's channels (0 without), and the channels in group g. */
static inline uint32_t vxl_channel_groups(const vxl_volume *v)
{
    return (v->channel_count + VXL_CHANNELS_PER_GROUP - 1) / VXL_CHANNELS_PER_GROUP;
}
static inline uint32_t vxl_channel_group_width(const vxl_volume *v, uint32_t g)
{
    const uint32_t left = v->channel_count - g * VXL_CHANNELS_PER_GROUP;
    return left < VXL_CHANNELS_PER_GROUP ? left : VXL_CHANNELS_PER_GROUP;
}
/* Group g's texels (width channels a voxel, interleaved). */
static inline const uint16_t *vxl_channel_group(const vxl_volume *v, uint32_t g)
{
    return v->channels + (uint64_t)g * VXL_CHANNELS_PER_GROUP * v->dims[0] * v->dims[1] * v->dims[2];
}
/* The stored normalised value in [0, 1] of channel c at voxel i. */
double vxl_channel_texel(const vxl_volume *v, uint32_t c, uint64_t i);

/* Channel c of v alone as a 16-bit volume of v's dims (texels and dims
 * only: what the CPU passes over its voxels read, the brick min-max and the
 * page bricks); the caller frees one->texels. */
int vxl_channel_alone(const vxl_volume *v, uint32_t c, vxl_volume *one, vxl_err *e);

/* Bytes of v's channels (0 without). */
uint64_t vxl_volume_channel_bytes(const vxl_volume *v);

#endif
