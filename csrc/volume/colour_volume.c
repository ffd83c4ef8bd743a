/* colour_volume.c - a colour volume's scalar and RGB8 colour from raw
 * channels (colour_volume.h). */
#include "colour_volume.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>

/* Rec. 709 luma weights: the luminance every grey conversion of colour in
 * the library uses (the DICOM reader's too), so a colour volume's scalar
 * equals what it rendered as before colour was kept. */
#define LUMA_R 0.2126
#define LUMA_G 0.7152
#define LUMA_B 0.0722

static double raw_get(const void *raw, uint32_t dtype, uint64_t i)
{
    switch (dtype) {
    case VXL_DTYPE_U8: return ((const uint8_t *)raw)[i];
    case VXL_DTYPE_I8: return ((const int8_t *)raw)[i];
    case VXL_DTYPE_U16: return ((const uint16_t *)raw)[i];
    case VXL_DTYPE_I16: return ((const int16_t *)raw)[i];
    case VXL_DTYPE_U32: return ((const uint32_t *)raw)[i];
    case VXL_DTYPE_I32: return ((const int32_t *)raw)[i];
    case VXL_DTYPE_F32: return ((const float *)raw)[i];
    default: return ((const double *)raw)[i];
    }
}

/* Integer types get the nearest value within their range, so a luminance of
 * 8-bit channels stays an exact 8-bit texel. */
static void raw_put(void *raw, uint32_t dtype, uint64_t i, double v)
{
    if (dtype != VXL_DTYPE_F32 && dtype != VXL_DTYPE_F64) v = isfinite(v) ? floor(v + 0.5) : 0.0;
#define PUT(T, lo, hi) ((T *)raw)[i] = (T)(v < (lo) ? (lo) : v > (hi) ? (hi) : v)
    switch (dtype) {
    case VXL_DTYPE_U8: PUT(uint8_t, 0.0, 255.0); break;
    case VXL_DTYPE_I8: PUT(int8_t, -128.0, 127.0); break;
    case VXL_DTYPE_U16: PUT(uint16_t, 0.0, 65535.0); break;
    case VXL_DTYPE_I16: PUT(int16_t, -32768.0, 32767.0); break;
    case VXL_DTYPE_U32: PUT(uint32_t, 0.0, 4294967295.0); break;
    case VXL_DTYPE_I32: PUT(int32_t, -2147483648.0, 2147483647.0); break;
    case VXL_DTYPE_F32: ((float *)raw)[i] = (float)v; break;
    default: ((double *)raw)[i] = v; break;
    }
#undef PUT
}

void vxl_load_opacity_source(const vxl_load_options *opt, uint32_t *source, uint32_t *channel)
{
    *source = VXL_OPACITY_SOURCE_LUMINANCE;
    *channel = 0;
    if (opt && (opt->struct_size == 0 ||
                opt->struct_size >= offsetof(vxl_load_options, opacity_channel) + sizeof opt->opacity_channel)) {
        *source = opt->opacity_source;
        *channel = opt->opacity_channel;
    }
}

int vxl_colour_opacity_source(const vxl_load_options *opt, uint32_t components, uint32_t *source, uint32_t *channel,
                              vxl_err *e)
{
    vxl_load_opacity_source(opt, source, channel);
    if (*source >= VXL_OPACITY_SOURCE_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown opacity source %u (0 luminance, 1 channel, 2 alpha)",
                        *source);
    if (*source == VXL_OPACITY_SOURCE_ALPHA) {
        if (components != 4)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "opacity source alpha needs RGBA data; this has %u channels",
                            components);
        *channel = 3;
    }
    if (*source == VXL_OPACITY_SOURCE_CHANNEL && *channel >= components)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "opacity channel %u: the data has channels 0..%u", *channel,
                        components - 1);
    return VXL_OK;
}

uint64_t vxl_volume_colour_bytes(const vxl_volume *v)
{
    return v->colour ? (uint64_t)v->dims[0] * v->dims[1] * v->dims[2] * VXL_COLOUR_BYTES_PER_VOXEL : 0;
}

/* The RGB8 colour of n voxels: 8-bit unsigned kept exactly, anything else
 * windowed over the finite range of its R, G and B into [0, 255]. Returns
 * whether it windowed (lo, hi: the window). */
static int colour_from_raw(const void *raw, uint32_t dtype, uint32_t components, int planar, uint64_t n, uint8_t *rgb,
                           double *lo, double *hi)
{
    const uint64_t step = planar ? n : 1, stride = planar ? 1 : components;
    if (dtype == VXL_DTYPE_U8) {
        const uint8_t *s = raw;
        for (uint64_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) rgb[3 * i + c] = s[i * stride + c * step];
        return 0;
    }
    double mn = INFINITY, mx = -INFINITY;
    for (uint64_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            double x = raw_get(raw, dtype, i * stride + c * step);
            if (isfinite(x)) {
                mn = x < mn ? x : mn;
                mx = x > mx ? x : mx;
            }
        }
    if (!(mn <= mx)) mn = mx = 0.0; /* nothing finite */
    const double scale = mx > mn ? 255.0 / (mx - mn) : 0.0;
    for (uint64_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            double x = raw_get(raw, dtype, i * stride + c * step);
            /* a flat volume is all one colour: full where it is positive */
            double code = !isfinite(x) ? 0.0 : scale > 0 ? (x - mn) * scale : (mx > 0 ? 255.0 : 0.0);
            rgb[3 * i + c] = (uint8_t)(code < 0 ? 0 : code > 255 ? 255 : floor(code + 0.5));
        }
    *lo = mn;
    *hi = mx;
    return 1;
}

int vxl_volume_build_colour(const void *raw, uint32_t dtype, uint32_t components, int planar, const uint32_t dims[3],
                            const double spacing[3], const double *affine, double slope, double inter,
                            const vxl_load_options *opt, const char *what, vxl_volume **out, vxl_err *e)
{
    if (!out) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (!raw) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "voxel data is NULL");
    const uint32_t size = vxl_dtype_size(dtype);
    if (!size) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown data type %u", dtype);
    if (components != 3 && components != 4)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "%u channels: a colour volume has 3 (RGB) or 4 (RGBA)", components);
    uint32_t source, channel;
    int rc = vxl_colour_opacity_source(opt, components, &source, &channel, e);
    if (rc) return rc;
    /* the scalar's texture and the colour, before anything is allocated */
    rc = vxl_volume_check_limits(dims, vxl_texture_bits_for(dtype) / 8 + VXL_COLOUR_BYTES_PER_VOXEL, opt, e);
    if (rc) return rc;
    const uint64_t n = (uint64_t)dims[0] * dims[1] * dims[2];
    const uint64_t step = planar ? n : 1, stride = planar ? 1 : components;
    void *scalar = malloc((size_t)(n ? n * size : 1));
    uint8_t *rgb = malloc((size_t)(n ? n * VXL_COLOUR_BYTES_PER_VOXEL : 1));
    if (!scalar || !rgb) {
        free(scalar);
        free(rgb);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for a %ux%ux%u colour volume", dims[0], dims[1], dims[2]);
    }
    for (uint64_t i = 0; i < n; i++) {
        const uint64_t at = i * stride;
        double s = source == VXL_OPACITY_SOURCE_LUMINANCE
                       ? LUMA_R * raw_get(raw, dtype, at) + LUMA_G * raw_get(raw, dtype, at + step) +
                             LUMA_B * raw_get(raw, dtype, at + 2 * step)
                       : raw_get(raw, dtype, at + channel * step);
        raw_put(scalar, dtype, i, s);
    }
    double lo = 0, hi = 0;
    const int windowed = colour_from_raw(raw, dtype, components, planar, n, rgb, &lo, &hi);
    vxl_volume *v = NULL;
    rc = vxl_volume_build(scalar, dtype, dims, spacing, affine, slope, inter, opt, &v, e);
    free(scalar);
    if (rc) {
        free(rgb);
        return rc;
    }
    v->colour = rgb;
    v->components = components;
    v->opacity_source = source;
    static const char *const channel_names[4] = {"red", "green", "blue", "alpha"};
    if (source == VXL_OPACITY_SOURCE_LUMINANCE)
        vxl_volume_note(v, "%s: colour from the data, opacity and gradients from luminance (Rec. 709)%s",
                        what ? what : "colour", components == 4 ? ", alpha not used" : "");
    else
        vxl_volume_note(v, "%s: colour from the data, opacity and gradients from the %s channel", what ? what : "colour",
                        channel_names[channel]);
    if (windowed)
        vxl_volume_note(v, "colour stored as 8 bits a channel, windowed over the data's range [%g, %g]", lo, hi);
    *out = v;
    return VXL_OK;
}
