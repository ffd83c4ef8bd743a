/* stream_load.c - the loaders' streaming route (stream_load.h). */
#include "stream_load.h"
#include "files.h"

#include "brick_cache.h"
#include "loader_util.h"
#include "raw_source.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

uint32_t vxl_load_streaming(const vxl_load_options *opt)
{
    const size_t need = offsetof(vxl_load_options, streaming) + sizeof opt->streaming;
    if (!opt || (opt->struct_size && opt->struct_size < need) || opt->streaming >= VXL_STREAMING_COUNT)
        return VXL_STREAMING_AUTO;
    return opt->streaming;
}

/* What streaming checks instead of the budget: the per-axis limit, and sizes
 * that cannot overflow a file offset. */
static int stream_limits(const char *path, const uint32_t dims[3], uint32_t es, const vxl_load_options *opt,
                         uint64_t *nbytes, vxl_err *e)
{
    const uint32_t max_dim = opt && opt->max_dim ? opt->max_dim : VXL_DEFAULT_MAX_DIM;
    uint64_t n;
    for (int a = 0; a < 3; a++) {
        if (!dims[a])
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': bad dimensions %ux%ux%u: every axis needs at least 1 voxel",
                            path, dims[0], dims[1], dims[2]);
        if (dims[a] > max_dim)
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s': dimensions %ux%ux%u exceed the per-axis limit of %u", path,
                            dims[0], dims[1], dims[2], max_dim);
    }
    if (__builtin_mul_overflow((uint64_t)dims[0] * dims[1], (uint64_t)dims[2], &n) ||
        __builtin_mul_overflow(n, (uint64_t)es, nbytes) || *nbytes > (uint64_t)INT64_MAX)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': %ux%ux%u voxels overflow any file size", path, dims[0], dims[1],
                        dims[2]);
    return VXL_OK;
}

int vxl_stream_plan(const char *path, const uint32_t dims[3], uint32_t dtype, const vxl_load_options *opt,
                    const char *not_streamable, int *stream, uint64_t *nbytes, vxl_err *e)
{
    const uint32_t mode = vxl_load_streaming(opt);
    const uint64_t budget = vxl_load_budget(opt);
    const uint32_t es = vxl_dtype_size(dtype), bpv = vxl_texture_bits_for(dtype) / 8;
    *stream = 0;
    if (mode == VXL_STREAMING_ON) *stream = 1;
    else if (mode == VXL_STREAMING_AUTO) /* in double: a hostile header's product may overflow 64 bits */
        *stream = (double)dims[0] * dims[1] * dims[2] * bpv > budget / 2.0;
    if (*stream && !not_streamable) {
        int rc = stream_limits(path, dims, es, opt, nbytes, e);
        /* AUTO streams only to get under the budget: a header that cannot
         * stream gets the whole read's answer, which names the budget */
        if (rc == VXL_OK || mode == VXL_STREAMING_ON) return rc;
    }
    *stream = 0;
    vxl_err inner = {0};
    int rc = vxl_plan_voxels(path, dims, dtype, opt, nbytes, &inner);
    if (rc == VXL_ERR_LIMIT && not_streamable && mode != VXL_STREAMING_OFF)
        return vxl_fail_not_streamable(e, rc, inner.msg, not_streamable);
    if (rc) return vxl_fail(e, rc, "%s", inner.msg);
    return VXL_OK;
}

int vxl_fail_not_streamable(vxl_err *e, int rc, const char *msg, const char *what)
{
    return vxl_fail(e, rc, "%s (streaming is not available for %s)", msg, what); /* vxl_fail formats before it writes e */
}

int vxl_stream_file_holds(const char *path, uint64_t offset, int compressed, uint64_t nbytes,
                          const vxl_load_options *opt)
{
    if (vxl_load_streaming(opt) == VXL_STREAMING_ON) return 1;
    vxl_path_info st;
    if (vxl_path_stat(path, &st) != 0) return 0;
    const uint64_t size = st.size, have = size > offset ? size - offset : 0;
    if (!compressed) return have >= nbytes;
    /* deflate expands at most 1032:1 (the bound vxl_read_payload applies) */
    return size >= (UINT64_MAX - 4096) / 1032 || size * 1032 + 4096 >= nbytes + offset;
}

int vxl_layout_init(vxl_raw_layout *l, const char *path, uint64_t offset, const uint32_t dims[3], uint32_t dtype,
                    const double spacing[3], const double affine[16], vxl_err *e)
{
    memset(l, 0, sizeof *l);
    const size_t n = strlen(path);
    if (n >= sizeof l->path) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': path too long", path);
    memcpy(l->path, path, n + 1);
    l->offset = offset;
    memcpy(l->dims, dims, sizeof l->dims);
    l->dtype = dtype;
    l->slope = 1.0;
    memcpy(l->spacing, spacing, sizeof l->spacing);
    memcpy(l->affine, affine, sizeof l->affine);
    l->frame_count = 1;
    vxl_path_info st;
    if (vxl_path_stat(l->path, &st) != 0) return vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", l->path, strerror(errno));
    l->file_size = st.size;
    l->mtime_ns = st.mtime_ns;
    return VXL_OK;
}

int vxl_file_is_gzip(const char *path)
{
    unsigned char m[2] = {0, 0};
    FILE *f = vxl_fopen(path, "rb");
    if (!f) return 0;
    size_t n = fread(m, 1, 2, f);
    fclose(f);
    return n == 2 && m[0] == 0x1f && m[1] == 0x8b;
}

int vxl_stream_load(const vxl_raw_layout *l, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    *out = NULL;
    vxl_brick_source *s = NULL;
    int rc = l->compressed ? vxl_brick_cache_open(l, opt, &s, e) : vxl_raw_source_open(l, opt, &s, e);
    if (rc) return rc;
    vxl_volume *v = calloc(1, sizeof *v);
    if (!v) {
        vxl_brick_source_free(s);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for a volume header", l->path);
    }
    vxl_volume_set_geometry(v, l->dims, l->dtype, l->spacing, l->affine);
    rc = l->compressed ? vxl_brick_cache_describe(s, v, e) : vxl_raw_source_describe(s, v, e);
    if (rc) {
        vxl_brick_source_free(s);
        free(v);
        return rc;
    }
    v->affine_source = l->affine_source;
    v->nifti_version = l->nifti_version;
    v->frame_count = l->frame_count ? l->frame_count : 1;
    v->frame = l->frame;
    v->source = s;
    *out = v;
    return VXL_OK;
}
