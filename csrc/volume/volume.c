/* volume.c - turns raw voxels from any source (file loaders, memory) into the
 * normalised storage the GL side uploads. One place for value scaling, NaN
 * handling and size limits, so every loader gets them the same way. */
#include "volume.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "channel_volume.h"
#include "colour_volume.h"
#include "voxlight_dev.h" /* vxl_volume_add_note */

uint32_t vxl_dtype_size(uint32_t dtype)
{
    switch (dtype) {
    case VXL_DTYPE_U8: case VXL_DTYPE_I8: return 1;
    case VXL_DTYPE_U16: case VXL_DTYPE_I16: return 2;
    case VXL_DTYPE_U32: case VXL_DTYPE_I32: case VXL_DTYPE_F32: return 4;
    case VXL_DTYPE_F64: return 8;
    default: return 0;
    }
}

/* 8- and 16-bit integers are stored exactly (unorm of raw - type minimum);
 * everything wider is normalised into a float texture. */
uint32_t vxl_texture_bits_for(uint32_t dtype)
{
    switch (dtype) {
    case VXL_DTYPE_U8: case VXL_DTYPE_I8: return 8;
    case VXL_DTYPE_U16: case VXL_DTYPE_I16: return 16;
    default: return 32;
    }
}

int vxl_volume_check_limits(const uint32_t dims[3], uint32_t bytes_per_voxel,
                            const vxl_load_options *opt, vxl_err *e)
{
    uint32_t max_dim = (opt && opt->max_dim) ? opt->max_dim : VXL_DEFAULT_MAX_DIM;
    uint64_t budget = (opt && opt->memory_budget_bytes) ? opt->memory_budget_bytes : VXL_DEFAULT_BUDGET;
    for (int a = 0; a < 3; a++)
        if (dims[a] == 0)
            return vxl_fail(e, VXL_ERR_FORMAT, "bad dimensions %ux%ux%u: every axis needs at least 1 voxel",
                            dims[0], dims[1], dims[2]);
    /* The budget comes first so an absurd header is refused naming it. Each
     * dim is < 2^32, so the product of three needs overflow care. */
    uint64_t n = (uint64_t)dims[0] * dims[1];
    uint64_t bpv = bytes_per_voxel ? bytes_per_voxel : 1;
    if (n > UINT64_MAX / dims[2] / bpv || n * dims[2] * bpv > budget)
        return vxl_fail(e, VXL_ERR_LIMIT, "volume %ux%ux%u needs %.1f MiB, over the memory budget of %.1f MiB",
                        dims[0], dims[1], dims[2], (double)dims[0] * dims[1] * dims[2] * bpv / 1048576.0,
                        budget / 1048576.0);
    uint64_t bytes = n * dims[2] * bpv;
    for (int a = 0; a < 3; a++)
        if (dims[a] > max_dim)
            return vxl_fail(e, VXL_ERR_LIMIT, "dimensions %ux%ux%u exceed the per-axis limit of %u",
                            dims[0], dims[1], dims[2], max_dim);
    if (bytes > (uint64_t)SIZE_MAX)
        return vxl_fail(e, VXL_ERR_LIMIT, "volume too large for this address space");
    return VXL_OK;
}

/* Integer types of 8/16 bits: stored t = (raw - type_min) / type_span, which
 * is exact; the data value is then affine in t. */
static void int_type_range(uint32_t dtype, double *lo, double *span)
{
    switch (dtype) {
    case VXL_DTYPE_U8: *lo = 0; *span = 255; break;
    case VXL_DTYPE_I8: *lo = -128; *span = 255; break;
    case VXL_DTYPE_U16: *lo = 0; *span = 65535; break;
    default: *lo = -32768; *span = 65535; break; /* I16 */
    }
}

/* The loops below run over every voxel of volumes of billions, so each is
 * written once per raw type (RAW_TYPES expands a statement per type) rather
 * than through a switch per voxel; every value is the same double
 * expression as a per-voxel read would give. */
#define RAW_TYPES(X)                                                                   \
    switch (dtype) {                                                                   \
    case VXL_DTYPE_U8: X(uint8_t); break;                                              \
    case VXL_DTYPE_I8: X(int8_t); break;                                               \
    case VXL_DTYPE_U16: X(uint16_t); break;                                            \
    case VXL_DTYPE_I16: X(int16_t); break;                                             \
    case VXL_DTYPE_U32: X(uint32_t); break;                                            \
    case VXL_DTYPE_I32: X(int32_t); break;                                             \
    case VXL_DTYPE_F32: X(float); break;                                               \
    case VXL_DTYPE_F64: X(double); break;                                              \
    default: break;                                                                    \
    }

void vxl_raw_range(uint32_t dtype, const void *raw, uint64_t n, double slope, double inter, double *mn, double *mx,
                   uint64_t *nan_count, uint64_t *inf_count)
{
    double lo = *mn, hi = *mx;
    uint64_t nans = 0, infs = 0;
    if (n && dtype != VXL_DTYPE_F32 && dtype != VXL_DTYPE_F64) {
        /* Integers: raw * slope + inter is monotonic in raw (as rounded too),
         * so the extremes come from the raw extremes, unless scaling
         * overflows somewhere (then the per-voxel loop counts the Inf). */
        double rlo = INFINITY, rhi = -INFINITY;
#define RAW_EXTREMES(T)                                                   \
    {                                                                     \
        const T *r = raw;                                                 \
        T a = r[0], b = r[0];                                             \
        for (uint64_t i = 1; i < n; i++) {                                \
            a = r[i] < a ? r[i] : a;                                      \
            b = r[i] > b ? r[i] : b;                                      \
        }                                                                 \
        rlo = (double)a;                                                  \
        rhi = (double)b;                                                  \
    }
        RAW_TYPES(RAW_EXTREMES)
#undef RAW_EXTREMES
        const double x0 = rlo * slope + inter, x1 = rhi * slope + inter;
        if (isfinite(x0) && isfinite(x1)) {
            const double a = x0 < x1 ? x0 : x1, b = x0 < x1 ? x1 : x0;
            *mn = a < lo ? a : lo;
            *mx = b > hi ? b : hi;
            return;
        }
    }
#define RANGE_LOOP(T)                                                     \
    {                                                                     \
        const T *r = raw;                                                 \
        for (uint64_t i = 0; i < n; i++) {                                \
            double x = r[i] * slope + inter;                              \
            if (isnan(x)) nans++;                                         \
            else if (isinf(x)) infs++;                                    \
            else {                                                        \
                if (x < lo) lo = x;                                       \
                if (x > hi) hi = x;                                       \
            }                                                             \
        }                                                                 \
    }
    RAW_TYPES(RANGE_LOOP)
#undef RANGE_LOOP
    *mn = lo;
    *mx = hi;
    *nan_count += nans;
    *inf_count += infs;
}

void vxl_texel_map_init(vxl_texel_map *m, uint32_t dtype, double slope, double inter, double mn, double mx)
{
    memset(m, 0, sizeof *m);
    if (slope == 0.0) { slope = 1.0; inter = 0.0; } /* NIfTI: slope 0 means unscaled */
    if (!(mn <= mx)) mn = mx = 0.0; /* nothing finite at all */
    m->dtype = dtype;
    m->bits = vxl_texture_bits_for(dtype);
    m->slope = slope;
    m->inter = inter;
    m->mn = mn;
    m->mx = mx;
    if (m->bits < 32) {
        double tspan;
        int_type_range(dtype, &m->type_lo, &tspan);
        /* integer data is never NaN; scaled endpoints of the type range */
        m->tex_lo = m->type_lo * slope + inter;
        m->tex_hi = (m->type_lo + tspan) * slope + inter;
    } else {
        double span = mx - mn;
        m->tex_lo = mn;
        m->tex_hi = span > 0 ? mx : mn + 1.0;
        m->inv = span > 0 ? 1.0 / span : 0.0;
    }
}

void vxl_texels_from_raw(const vxl_texel_map *m, const void *raw, uint64_t n, void *texels)
{
    const uint32_t dtype = m->dtype;
    if (m->bits < 32) { /* code = raw - type minimum, exact */
        const int32_t tlo = (int32_t)m->type_lo;
#define CODE_LOOP(T)                                                                          \
    {                                                                                         \
        const T *r = raw;                                                                     \
        if (m->bits == 8)                                                                     \
            for (uint64_t i = 0; i < n; i++) ((uint8_t *)texels)[i] = (uint8_t)(r[i] - tlo);  \
        else                                                                                  \
            for (uint64_t i = 0; i < n; i++) ((uint16_t *)texels)[i] = (uint16_t)(r[i] - tlo); \
    }
        switch (dtype) { /* 8/16-bit types only have 8/16-bit texels */
        case VXL_DTYPE_U8: CODE_LOOP(uint8_t); break;
        case VXL_DTYPE_I8: CODE_LOOP(int8_t); break;
        case VXL_DTYPE_U16: CODE_LOOP(uint16_t); break;
        case VXL_DTYPE_I16: CODE_LOOP(int16_t); break;
        default: break;
        }
#undef CODE_LOOP
        return;
    }
    /* Normalise in double so +-1e30 and denormals land safely in [0,1]. */
    float *t = texels;
    const double slope = m->slope, inter = m->inter, mn = m->mn, mx = m->mx, inv = m->inv;
#define NORM_LOOP(T)                                                      \
    {                                                                     \
        const T *r = raw;                                                 \
        for (uint64_t i = 0; i < n; i++) {                                \
            double x = r[i] * slope + inter;                              \
            if (isnan(x)) x = mn;                                         \
            else if (x > mx) x = mx;                                      \
            else if (x < mn) x = mn;                                      \
            double s = (x - mn) * inv;                                    \
            t[i] = (float)(s < 0 ? 0 : s > 1 ? 1 : s);                    \
        }                                                                 \
    }
    RAW_TYPES(NORM_LOOP)
#undef NORM_LOOP
}

int vxl_volume_build(const void *raw, uint32_t dtype, const uint32_t dims[3], const double spacing[3],
                     const double *affine, double slope, double inter, const vxl_load_options *opt,
                     vxl_volume **out, vxl_err *e)
{
    if (!out) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (!raw) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "voxel data is NULL");
    if (!vxl_dtype_size(dtype)) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown data type %u", dtype);
    uint32_t bits = vxl_texture_bits_for(dtype);
    int rc = vxl_volume_check_limits(dims, bits / 8, opt, e);
    if (rc) return rc;
    if (!isfinite(slope) || !isfinite(inter))
        return vxl_fail(e, VXL_ERR_FORMAT, "scl_slope/scl_inter are not finite (%g, %g)", slope, inter);
    if (slope == 0.0) { slope = 1.0; inter = 0.0; } /* NIfTI: slope 0 means unscaled */

    uint64_t n = (uint64_t)dims[0] * dims[1] * dims[2];
    vxl_volume *v = calloc(1, sizeof *v);
    if (!v) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the volume header");
    v->texels = malloc((size_t)(n * (bits / 8)));
    if (!v->texels) {
        free(v);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for %llu voxels", (unsigned long long)n);
    }
    vxl_volume_set_geometry(v, dims, dtype, spacing, affine);

    /* Pass 1: finite range of the scaled values, NaN/Inf counts; pass 2: texels. */
    double mn = INFINITY, mx = -INFINITY;
    vxl_raw_range(dtype, raw, n, slope, inter, &mn, &mx, &v->nan_count, &v->inf_count);
    vxl_texel_map m;
    vxl_texel_map_init(&m, dtype, slope, inter, mn, mx);
    vxl_volume_set_values(v, &m);
    vxl_texels_from_raw(&m, raw, n, v->texels);
    *out = v;
    return VXL_OK;
}

void vxl_volume_set_geometry(vxl_volume *v, const uint32_t dims[3], uint32_t dtype, const double spacing[3],
                             const double *affine)
{
    memcpy(v->dims, dims, sizeof v->dims);
    v->src_dtype = dtype;
    v->texture_bits = vxl_texture_bits_for(dtype);
    v->storage_bytes = (uint64_t)dims[0] * dims[1] * dims[2] * (v->texture_bits / 8);
    for (int a = 0; a < 3; a++)
        v->spacing[a] = (spacing && isfinite(spacing[a]) && spacing[a] > 0) ? spacing[a] : 1.0;
    memset(v->affine, 0, sizeof v->affine);
    if (affine) {
        memcpy(v->affine, affine, sizeof v->affine);
    } else {
        for (int a = 0; a < 3; a++) v->affine[a * 4 + a] = v->spacing[a];
        v->affine[15] = 1.0;
    }
}

void vxl_volume_set_values(vxl_volume *v, const vxl_texel_map *m)
{
    v->value_min = m->mn;
    v->value_max = m->mx;
    v->tex_lo = m->tex_lo;
    v->tex_hi = m->tex_hi;
}

int vxl_volume_create(const vxl_volume_desc *d, const vxl_load_options *opt, vxl_volume **out)
{
    if (!d) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "volume description is NULL");
    uint32_t components = 1, channels = 1, interleaved = 0;
    if (d->struct_size == 0 || d->struct_size >= offsetof(vxl_volume_desc, reserved) + sizeof d->reserved) {
        if (d->reserved) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "desc.reserved is %u: it must be 0", d->reserved);
        components = d->components ? d->components : 1;
    }
    if (d->struct_size == 0 ||
        d->struct_size >= offsetof(vxl_volume_desc, channels_interleaved) + sizeof d->channels_interleaved) {
        channels = d->channels ? d->channels : 1;
        interleaved = d->channels_interleaved;
    }
    if (channels != 1) {
        if (out) *out = NULL;
        if (components != 1)
            return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT,
                            "desc.channels %u with desc.components %u: a volume is colour or multi-channel, not both",
                            channels, components);
        if (interleaved > 1)
            return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "desc.channels_interleaved is %u: 0 (planar) or 1",
                            interleaved);
        return vxl_volume_build_channels(d->data, d->dtype, channels, (int)interleaved, d->dims, d->spacing,
                                         d->has_affine ? d->affine : NULL, d->scl_slope, d->scl_inter, opt, NULL, out,
                                         NULL);
    }
    if (components != 1) {
        if (out) *out = NULL;
        if (components != 3 && components != 4)
            return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "desc.components is %u: 1 (grey), 3 (RGB) or 4 (RGBA)",
                            components);
        return vxl_volume_build_colour(d->data, d->dtype, components, 0, d->dims, d->spacing,
                                       d->has_affine ? d->affine : NULL, d->scl_slope, d->scl_inter, opt,
                                       components == 3 ? "RGB" : "RGBA", out, NULL);
    }
    return vxl_volume_build(d->data, d->dtype, d->dims, d->spacing, d->has_affine ? d->affine : NULL,
                            d->scl_slope, d->scl_inter, opt, out, NULL);
}

_Static_assert(VXL_NOTES_MAX == VXL_VOLUME_NOTES_MAX, "vxl_volume_info.notes holds vxl_volume.notes whole");

int vxl_volume_get_info(const vxl_volume *v, vxl_volume_info *out)
{
    if (!v || !out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "volume or info is NULL");
    /* Filled locally and copied up to the caller's struct_size, so a caller
     * built against an older, shorter struct is not overrun. */
    const size_t v1 = offsetof(vxl_volume_info, frame_count), s = out->struct_size;
    size_t have = s >= v1 && s < sizeof *out ? s : sizeof *out;
    /* a struct that ends inside notes would get an unterminated piece */
    const size_t notes_at = offsetof(vxl_volume_info, notes), notes_end = notes_at + sizeof out->notes;
    if (have > notes_at && have < notes_end) have = notes_at;
    /* and one inside the channel names, unterminated names */
    const size_t names_at = offsetof(vxl_volume_info, channel_names), names_end = names_at + sizeof out->channel_names;
    if (have > names_at && have < names_end) have = names_at;
    vxl_volume_info info, *o = &info;
    memset(o, 0, sizeof *o);
    o->struct_size = (uint32_t)have;
    o->dtype = v->src_dtype;
    memcpy(o->dims, v->dims, sizeof o->dims);
    o->nifti_version = v->nifti_version;
    memcpy(o->spacing, v->spacing, sizeof o->spacing);
    memcpy(o->affine, v->affine, sizeof o->affine);
    o->value_min = v->value_min;
    o->value_max = v->value_max;
    o->nan_count = v->nan_count;
    o->inf_count = v->inf_count;
    o->storage_bytes = v->storage_bytes;
    o->texture_bits = v->texture_bits;
    o->affine_source = v->affine_source;
    o->frame_count = v->frame_count ? v->frame_count : 1;
    o->frame = v->frame;
    if (v->source) {
        o->streamed = 1;
        o->level_count = v->source->n_levels;
        o->resident_bytes = v->source->resident_bytes;
        o->bytes_read = __atomic_load_n(&v->source->bytes_read, __ATOMIC_RELAXED);
    } else {
        o->level_count = 1;
        o->resident_bytes = v->storage_bytes;
    }
    memcpy(o->notes, v->notes, sizeof o->notes);
    o->components = v->components ? v->components : 1;
    if (v->colour) {
        o->opacity_source = v->opacity_source;
        o->color_bytes = vxl_volume_colour_bytes(v);
    }
    if (v->channels) {
        o->channel_count = v->channel_count;
        o->scalar_channel = v->scalar_channel;
        for (uint32_t c = 0; c < v->channel_count; c++) {
            o->channel_min[c] = v->ch_min[c];
            o->channel_max[c] = v->ch_max[c];
        }
        o->channel_bytes = vxl_volume_channel_bytes(v);
        for (uint32_t c = 0; c < v->channel_count; c++) {
            const vxl_channel_meta *m = &v->ch_meta[c];
            memcpy(o->channel_names[c], m->name, sizeof o->channel_names[c]);
            memcpy(o->channel_colors[c], m->color_srgb, sizeof o->channel_colors[c]);
            o->channel_color_known[c] = m->has_color;
            o->channel_window_low[c] = m->window[0];
            o->channel_window_high[c] = m->window[1];
            o->channel_window_known[c] = m->has_window;
            o->channel_active[c] = !m->hidden;
        }
    }
    memcpy(out, o, have);
    return VXL_OK;
}

double vxl_volume_texel(const vxl_volume *v, size_t i)
{
    if (v->texture_bits == 8) return ((const uint8_t *)v->texels)[i] / 255.0;
    if (v->texture_bits == 16) return ((const uint16_t *)v->texels)[i] / 65535.0;
    return ((const float *)v->texels)[i];
}

/* Bins n texels of bits (the stored t in [0,1] maps to tex_lo + t * span). */
static void bin_texels(const vxl_volume *v, uint32_t bits, const void *texels, size_t n, uint32_t bins, double lo,
                       double scale, uint64_t *counts)
{
    const double span = v->tex_hi - v->tex_lo;
    for (size_t i = 0; i < n; i++) {
        double t = bits == 8 ? ((const uint8_t *)texels)[i] / 255.0
                   : bits == 16 ? ((const uint16_t *)texels)[i] / 65535.0
                                : ((const float *)texels)[i];
        double b = (v->tex_lo + t * span - lo) * scale;
        if (b >= 0 && b <= bins) counts[b >= bins ? bins - 1 : (uint32_t)b]++;
    }
}

/* A streamed volume's texels, read through its source a z slab at a time
 * (about 16 MiB, at least one slice), so the histogram never holds the volume. */
static int bin_streamed(const vxl_volume *v, uint32_t bins, double lo, double scale, uint64_t *counts)
{
    vxl_brick_source *s = v->source;
    const size_t slice = (size_t)v->dims[0] * v->dims[1] * (s->texture_bits / 8);
    uint32_t depth = (uint32_t)((16u << 20) / slice);
    depth = depth < 1 ? 1 : depth > v->dims[2] ? v->dims[2] : depth;
    void *buf = malloc(slice * depth);
    if (!buf) return vxl_fail(NULL, VXL_ERR_NO_MEMORY, "out of memory for a histogram slab of %u slices", depth);
    vxl_err e = {0};
    int rc = VXL_OK;
    for (uint32_t z = 0; z < v->dims[2] && !rc; z += depth) {
        const uint32_t lo3[3] = {0, 0, z}, size[3] = {v->dims[0], v->dims[1], depth < v->dims[2] - z ? depth : v->dims[2] - z};
        rc = s->ops->read(s, 0, lo3, size, buf, &e);
        if (rc) rc = vxl_fail(NULL, rc, "histogram: %s", e.msg);
        else bin_texels(v, s->texture_bits, buf, (size_t)size[0] * size[1] * size[2], bins, lo, scale, counts);
    }
    free(buf);
    return rc;
}

/* The arguments both histograms take, checked; counts zeroed. */
static int histogram_args(const vxl_volume *v, uint32_t bins, double lo, double hi, uint64_t *counts)
{
    if (!v || !counts || bins == 0)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "histogram needs a volume, counts and bins >= 1");
    if (bins > (1u << 24)) return vxl_fail(NULL, VXL_ERR_LIMIT, "histogram of %u bins exceeds 2^24", bins);
    if (!isfinite(lo) || !isfinite(hi) || !(hi > lo))
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "histogram range [%g, %g] is empty or not finite", lo, hi);
    memset(counts, 0, bins * sizeof *counts);
    return VXL_OK;
}

int vxl_volume_histogram(const vxl_volume *v, uint32_t bins, double lo, double hi, uint64_t *counts)
{
    int rc = histogram_args(v, bins, lo, hi, counts);
    if (rc) return rc;
    /* Stored t in [0,1] maps to tex_lo + t*(tex_hi - tex_lo): bin by t directly. */
    const double scale = bins / (hi - lo);
    if (v->source) {
        int rc = bin_streamed(v, bins, lo, scale, counts);
        if (rc) return rc;
    } else {
        bin_texels(v, v->texture_bits, v->texels, (size_t)v->dims[0] * v->dims[1] * v->dims[2], bins, lo, scale,
                   counts);
    }
    if (v->nan_count) { /* NaN voxels were stored as value_min: take them back out */
        double b = (v->value_min - lo) * scale;
        if (b >= 0 && b <= bins) {
            uint64_t *c = &counts[b >= bins ? bins - 1 : (uint32_t)b];
            *c -= *c < v->nan_count ? *c : v->nan_count;
        }
    }
    return VXL_OK;
}

int vxl_volume_channel_histogram(const vxl_volume *v, uint32_t channel, uint32_t bins, double lo, double hi,
                                 uint64_t *counts)
{
    int rc = histogram_args(v, bins, lo, hi, counts);
    if (rc) return rc;
    if (!v->channels)
        return vxl_fail(NULL, VXL_ERR_STATE, "histogram of channel %u: the volume is not multi-channel", channel);
    if (channel >= v->channel_count)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "histogram of channel %u: the volume has channels 0..%u",
                        channel, v->channel_count - 1);
    /* From the channel's own 16-bit texels, the values the channel march
     * samples. A channel keeps no NaN count of its own, so its NaN voxels
     * are counted where they were stored (its minimum). */
    const uint64_t n = (uint64_t)v->dims[0] * v->dims[1] * v->dims[2];
    const double tex_lo = v->ch_tex_lo[channel], span = v->ch_tex_hi[channel] - tex_lo, scale = bins / (hi - lo);
    for (uint64_t i = 0; i < n; i++) {
        double b = (tex_lo + vxl_channel_texel(v, channel, i) * span - lo) * scale;
        if (b >= 0 && b <= bins) counts[b >= bins ? bins - 1 : (uint32_t)b]++;
    }
    return VXL_OK;
}

void vxl_volume_destroy(vxl_volume *v)
{
    if (!v) return;
    vxl_brick_source_free(v->source);
    free(v->colour);
    free(v->channels);
    free(v->texels);
    free(v);
}

void vxl_volume_note(vxl_volume *v, const char *fmt, ...)
{
    if (!v || !fmt) return;
    char line[VXL_VOLUME_NOTES_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    /* one line of text: the notes reach a terminal and Blender's UI, and the
     * helpers' receiver refuses control characters */
    for (char *c = line; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f) *c = ' ';
    const size_t cap = sizeof v->notes, used = strlen(v->notes);
    if (used + 4 >= cap) { /* full: this note is lost, so the notes end in "..." (may already) */
        memcpy(v->notes + used - 3, "...", 4);
        return;
    }
    int n = snprintf(v->notes + used, cap - used, "%s%s", used ? "; " : "", line);
    if (n < 0 || (size_t)n >= cap - used) memcpy(v->notes + cap - 4, "...", 4);
}

int vxl_volume_add_note(vxl_volume *v, const char *note)
{
    if (!v || !note) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "volume or note is NULL");
    vxl_volume_note(v, "%s", note);
    return VXL_OK;
}
