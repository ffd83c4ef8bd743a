/* volume.c - turns raw voxels from any source (file loaders, memory) into the
 * normalised storage the GL side uploads. One place for value scaling, NaN
 * handling and size limits, so every loader gets them the same way. */
#include "volume.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

static double raw_value(const void *raw, uint32_t dtype, uint64_t i)
{
    switch (dtype) {
    case VXL_DTYPE_U8: return ((const uint8_t *)raw)[i];
    case VXL_DTYPE_I8: return ((const int8_t *)raw)[i];
    case VXL_DTYPE_U16: return ((const uint16_t *)raw)[i];
    case VXL_DTYPE_I16: return ((const int16_t *)raw)[i];
    case VXL_DTYPE_U32: return ((const uint32_t *)raw)[i];
    case VXL_DTYPE_I32: return ((const int32_t *)raw)[i];
    case VXL_DTYPE_F32: return ((const float *)raw)[i];
    case VXL_DTYPE_F64: return ((const double *)raw)[i];
    default: return 0.0;
    }
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
    memcpy(v->dims, dims, sizeof v->dims);
    v->src_dtype = dtype;
    v->texture_bits = bits;
    v->storage_bytes = n * (bits / 8);
    for (int a = 0; a < 3; a++)
        v->spacing[a] = (spacing && isfinite(spacing[a]) && spacing[a] > 0) ? spacing[a] : 1.0;
    memset(v->affine, 0, sizeof v->affine);
    if (affine) {
        memcpy(v->affine, affine, sizeof v->affine);
    } else {
        for (int a = 0; a < 3; a++) v->affine[a * 4 + a] = v->spacing[a];
        v->affine[15] = 1.0;
    }

    /* Pass 1: finite range of the scaled values, NaN/Inf counts. */
    double mn = INFINITY, mx = -INFINITY;
    for (uint64_t i = 0; i < n; i++) {
        double x = raw_value(raw, dtype, i) * slope + inter;
        if (isnan(x)) v->nan_count++;
        else if (isinf(x)) v->inf_count++;
        else {
            if (x < mn) mn = x;
            if (x > mx) mx = x;
        }
    }
    if (!(mn <= mx)) mn = mx = 0.0; /* nothing finite at all */
    v->value_min = mn;
    v->value_max = mx;

    if (bits < 32) {
        double tlo, tspan;
        int_type_range(dtype, &tlo, &tspan);
        /* integer data is never NaN; scaled endpoints of the type range */
        v->tex_lo = tlo * slope + inter;
        v->tex_hi = (tlo + tspan) * slope + inter;
        for (uint64_t i = 0; i < n; i++) {
            double t = raw_value(raw, dtype, i) - tlo;
            if (bits == 8) ((uint8_t *)v->texels)[i] = (uint8_t)t;
            else ((uint16_t *)v->texels)[i] = (uint16_t)t;
        }
    } else {
        /* Normalise in double so +-1e30 and denormals land safely in [0,1]. */
        double span = mx - mn;
        v->tex_lo = mn;
        v->tex_hi = span > 0 ? mx : mn + 1.0;
        double inv = span > 0 ? 1.0 / span : 0.0;
        float *t = v->texels;
        for (uint64_t i = 0; i < n; i++) {
            double x = raw_value(raw, dtype, i) * slope + inter;
            if (isnan(x)) x = mn;
            else if (x > mx) x = mx;
            else if (x < mn) x = mn;
            double s = (x - mn) * inv;
            t[i] = (float)(s < 0 ? 0 : s > 1 ? 1 : s);
        }
    }
    *out = v;
    return VXL_OK;
}

int vxl_volume_create(const vxl_volume_desc *d, const vxl_load_options *opt, vxl_volume **out)
{
    if (!d) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "volume description is NULL");
    return vxl_volume_build(d->data, d->dtype, d->dims, d->spacing, d->has_affine ? d->affine : NULL,
                            d->scl_slope, d->scl_inter, opt, out, NULL);
}

int vxl_volume_get_info(const vxl_volume *v, vxl_volume_info *out)
{
    if (!v || !out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "volume or info is NULL");
    /* Filled locally and copied up to the caller's struct_size, so a caller
     * built against an older, shorter struct is not overrun. */
    const size_t v1 = offsetof(vxl_volume_info, frame_count), s = out->struct_size;
    size_t have = s >= v1 && s < sizeof *out ? s : sizeof *out;
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
    memcpy(out, o, have);
    return VXL_OK;
}

double vxl_volume_texel(const vxl_volume *v, size_t i)
{
    if (v->texture_bits == 8) return ((const uint8_t *)v->texels)[i] / 255.0;
    if (v->texture_bits == 16) return ((const uint16_t *)v->texels)[i] / 65535.0;
    return ((const float *)v->texels)[i];
}

int vxl_volume_histogram(const vxl_volume *v, uint32_t bins, double lo, double hi, uint64_t *counts)
{
    if (!v || !counts || bins == 0)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "histogram needs a volume, counts and bins >= 1");
    if (bins > (1u << 24)) return vxl_fail(NULL, VXL_ERR_LIMIT, "histogram of %u bins exceeds 2^24", bins);
    if (!isfinite(lo) || !isfinite(hi) || !(hi > lo))
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "histogram range [%g, %g] is empty or not finite", lo, hi);
    memset(counts, 0, bins * sizeof *counts);
    /* Stored t in [0,1] maps to tex_lo + t*(tex_hi - tex_lo): bin by t directly. */
    const double span = v->tex_hi - v->tex_lo, scale = bins / (hi - lo);
    const uint64_t n = (uint64_t)v->dims[0] * v->dims[1] * v->dims[2];
    for (uint64_t i = 0; i < n; i++) {
        double t = vxl_volume_texel(v, (size_t)i);
        double b = (v->tex_lo + t * span - lo) * scale;
        if (b >= 0 && b <= bins) counts[b >= bins ? bins - 1 : (uint32_t)b]++;
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

void vxl_volume_destroy(vxl_volume *v)
{
    if (!v) return;
    vxl_brick_source_free(v->source);
    free(v->texels);
    free(v);
}
