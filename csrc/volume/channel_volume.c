/* channel_volume.c - a multi-channel volume's packed 16-bit channels and its
 * scalar (channel_volume.h). */
#include "channel_volume.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

int vxl_load_channels_mode(const vxl_load_options *opt, uint32_t *mode, uint32_t *scalar_channel, vxl_err *e)
{
    *mode = VXL_CHANNELS_AUTO;
    *scalar_channel = 0;
    if (opt && (opt->struct_size == 0 ||
                opt->struct_size >= offsetof(vxl_load_options, scalar_channel) + sizeof opt->scalar_channel)) {
        *mode = opt->channels;
        *scalar_channel = opt->scalar_channel;
    }
    if (*mode >= VXL_CHANNELS_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown channels mode %u (0 auto, 1 on, 2 off)", *mode);
    return VXL_OK;
}

uint64_t vxl_volume_channel_bytes(const vxl_volume *v)
{
    return v->channels ? (uint64_t)v->dims[0] * v->dims[1] * v->dims[2] * v->channel_count * VXL_CHANNEL_BYTES : 0;
}

double vxl_channel_texel(const vxl_volume *v, uint32_t c, uint64_t i)
{
    const uint32_t g = c / VXL_CHANNELS_PER_GROUP, w = vxl_channel_group_width(v, g);
    return vxl_channel_group(v, g)[i * w + c % VXL_CHANNELS_PER_GROUP] / 65535.0;
}

int vxl_channel_alone(const vxl_volume *v, uint32_t c, vxl_volume *one, vxl_err *e)
{
    const uint64_t n = (uint64_t)v->dims[0] * v->dims[1] * v->dims[2];
    memset(one, 0, sizeof *one);
    memcpy(one->dims, v->dims, sizeof one->dims);
    one->texture_bits = 16;
    one->storage_bytes = n * VXL_CHANNEL_BYTES;
    uint16_t *t = malloc((size_t)(n ? n * VXL_CHANNEL_BYTES : 1));
    if (!t)
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for channel %u alone (%.1f MiB)", c, n * 2 / 1048576.0);
    const uint32_t g = c / VXL_CHANNELS_PER_GROUP, w = vxl_channel_group_width(v, g);
    const uint16_t *src = vxl_channel_group(v, g) + c % VXL_CHANNELS_PER_GROUP;
    for (uint64_t i = 0; i < n; i++) t[i] = src[i * w];
    one->texels = t;
    return VXL_OK;
}

/* One channel's texels (texture format of its dtype, as vxl_volume_build
 * makes them) into its 16-bit slot of the group: 8-bit codes widen
 * exactly (c * 257 / 65535 = c / 255), 16-bit stay, float rounds. */
static void pack_channel(vxl_volume *v, uint32_t c, const void *texels, uint32_t bits)
{
    const uint64_t n = (uint64_t)v->dims[0] * v->dims[1] * v->dims[2];
    const uint32_t g = c / VXL_CHANNELS_PER_GROUP, w = vxl_channel_group_width(v, g), k = c % VXL_CHANNELS_PER_GROUP;
    uint16_t *dst = (uint16_t *)vxl_channel_group(v, g) + k;
    for (uint64_t i = 0; i < n; i++) {
        uint16_t t;
        if (bits == 8) t = (uint16_t)(((const uint8_t *)texels)[i] * 257u);
        else if (bits == 16) t = ((const uint16_t *)texels)[i];
        else {
            const float f = ((const float *)texels)[i];
            t = (uint16_t)(f <= 0.0f ? 0.0 : f >= 1.0f ? 65535.0 : floor(f * 65535.0 + 0.5));
        }
        dst[i * w] = t;
    }
}

/* Channel c's n values: a plane of raw, or gathered from interleaved raw
 * into `plane` (NULL for planar input). */
static const void *channel_plane(const void *raw, void *plane, int interleaved, uint32_t c, uint64_t n, uint32_t size,
                                 uint32_t channels)
{
    if (!interleaved) return (const char *)raw + (size_t)(c * n * size);
    for (uint64_t i = 0; i < n; i++) memcpy((char *)plane + i * size, (const char *)raw + (i * channels + c) * size, size);
    return plane;
}

int vxl_volume_build_channels(const void *raw, uint32_t dtype, uint32_t channels, int interleaved,
                              const uint32_t dims[3], const double spacing[3], const double *affine, double slope,
                              double inter, const vxl_load_options *opt, const char *what, vxl_volume **out,
                              vxl_err *e)
{
    if (!out) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (!raw) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "voxel data is NULL");
    const uint32_t size = vxl_dtype_size(dtype);
    if (!size) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown data type %u", dtype);
    if (channels < 2 || channels > VXL_MAX_CHANNELS)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "%u channels: a multi-channel volume has 2 to %d", channels,
                        VXL_MAX_CHANNELS);
    uint32_t mode, scalar;
    int rc = vxl_load_channels_mode(opt, &mode, &scalar, e);
    if (rc) return rc;
    if (scalar >= channels)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "scalar channel %u: the data has channels 0..%u", scalar,
                        channels - 1);
    const uint32_t bits = vxl_texture_bits_for(dtype);
    /* everything this volume holds, before anything is allocated */
    if ((rc = vxl_volume_check_limits(dims, bits / 8 + channels * VXL_CHANNEL_BYTES, opt, e))) return rc;
    if (!isfinite(slope) || !isfinite(inter))
        return vxl_fail(e, VXL_ERR_FORMAT, "scl_slope/scl_inter are not finite (%g, %g)", slope, inter);
    if (slope == 0.0) {
        slope = 1.0;
        inter = 0.0;
    }
    const uint64_t n = (uint64_t)dims[0] * dims[1] * dims[2];
    /* one channel's raw values (interleaved input is gathered) and texels */
    void *plane = interleaved ? malloc((size_t)(n * size)) : NULL;
    void *texels = malloc((size_t)(n * (bits / 8)));
    /* groups of four then the rest: exactly 2 bytes a channel a voxel */
    uint16_t *packed = malloc((size_t)(n * channels * VXL_CHANNEL_BYTES));
    vxl_volume *v = NULL;
    if ((interleaved && !plane) || !texels || !packed) {
        rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for %u channels of %llu voxels", channels,
                      (unsigned long long)n);
        goto done;
    }
    /* the scalar first, as a one-channel volume of that channel */
    if ((rc = vxl_volume_build(channel_plane(raw, plane, interleaved, scalar, n, size, channels),
                               dtype, dims, spacing, affine, slope, inter, opt, &v, e)))
        goto done;
    v->channels = packed;
    packed = NULL;
    v->channel_count = channels;
    v->scalar_channel = scalar;
    int lossy = 0;
    for (uint32_t c = 0; c < channels; c++) {
        const void *src = channel_plane(raw, plane, interleaved, c, n, size, channels);
        double mn = INFINITY, mx = -INFINITY;
        uint64_t nan_count = 0, inf_count = 0;
        vxl_raw_range(dtype, src, n, slope, inter, &mn, &mx, &nan_count, &inf_count);
        vxl_texel_map m;
        vxl_texel_map_init(&m, dtype, slope, inter, mn, mx);
        vxl_texels_from_raw(&m, src, n, texels);
        pack_channel(v, c, texels, bits);
        v->ch_tex_lo[c] = m.tex_lo;
        v->ch_tex_hi[c] = m.tex_hi;
        v->ch_min[c] = m.mn;
        v->ch_max[c] = m.mx;
        lossy |= bits == 32 && mx > mn;
    }
    if (what)
        vxl_volume_note(v, "%s: %u channels (channel %u is the scalar)%s", what, channels, scalar,
                        lossy ? ", each stored as 16 bits over its own range" : "");
done:
    free(plane);
    free(texels);
    free(packed);
    if (rc) {
        vxl_volume_destroy(v);
        return rc;
    }
    *out = v;
    return VXL_OK;
}
