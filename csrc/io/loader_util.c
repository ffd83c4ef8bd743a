/* loader_util.c - see loader_util.h. */
#include "loader_util.h"
#include "channel_volume.h"
#include "colour_volume.h"
#include "files.h"

#include <errno.h>
#include <stddef.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "zlib_api.h"

#define IO_CHUNK (256u * 1024u)

int vxl_fail_in(vxl_err *e, const char *path, const vxl_err *inner)
{
    return vxl_fail(e, inner->code, "'%s': %s", path, inner->msg);
}

int64_t vxl_pread_full(int fd, void *buf, size_t n, uint64_t off)
{
    size_t got = 0;
    while (got < n) {
        int64_t r = vxl_file_pread(fd, (uint8_t *)buf + got, n - got, off + got);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return -1;
        if (r == 0) break;
        got += (size_t)r;
    }
    return (int64_t)got;
}

int vxl_regular_file(const char *path, uint64_t *size, vxl_err *e)
{
    vxl_path_info st;
    if (vxl_path_stat(path, &st) != 0) return vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    if (st.kind != VXL_PATH_FILE)
        return vxl_fail(e, VXL_ERR_IO, "'%s' is not a regular file", path);
    if (size) *size = st.size;
    return VXL_OK;
}

int vxl_read_head(const char *path, char **text, size_t *len, uint64_t *file_size, vxl_err *e)
{
    *text = NULL;
    *len = 0;
    uint64_t size = 0;
    int rc = vxl_regular_file(path, &size, e);
    if (rc) return rc;
    if (file_size) *file_size = size;
    FILE *f = vxl_fopen(path, "rb");
    if (!f) return vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    size_t want = size < VXL_HEADER_MAX ? (size_t)size : VXL_HEADER_MAX;
    char *buf = malloc(want + 1);
    if (!buf) {
        fclose(f);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for the header", path);
    }
    size_t got = fread(buf, 1, want, f);
    int err = ferror(f);
    fclose(f);
    if (err) {
        free(buf);
        return vxl_fail(e, VXL_ERR_IO, "read error in '%s'", path);
    }
    buf[got] = '\0';
    *text = buf;
    *len = got;
    return VXL_OK;
}

char *vxl_next_line(char *text, size_t len, size_t *pos, int *had_newline)
{
    if (*pos >= len) return NULL;
    char *s = text + *pos;
    char *nl = memchr(s, '\n', len - *pos);
    size_t n = nl ? (size_t)(nl - s) : len - *pos;
    *had_newline = nl != NULL;
    *pos += n + (nl ? 1 : 0);
    s[n] = '\0'; /* the newline itself, or the buffer's terminating NUL */
    if (n > 0 && s[n - 1] == '\r') s[n - 1] = '\0';
    return s;
}

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

char *vxl_trim(char *s)
{
    while (is_space(*s)) s++;
    size_t n = strlen(s);
    while (n > 0 && is_space(s[n - 1])) s[--n] = '\0';
    return s;
}

int vxl_parse_doubles(const char *s, double *out, int n)
{
    int count = 0;
    while (*s) {
        while (is_space(*s)) s++;
        if (!*s) break;
        char *end = NULL;
        errno = 0;
        double v = strtod(s, &end);
        if (end == s || (*end && !is_space(*end)) || !isfinite(v)) return -1;
        if (count < n) out[count] = v;
        count++;
        if (count > 64) return -1;
        s = end;
    }
    return count;
}

int vxl_parse_u64s(const char *s, uint64_t *out, int n, uint64_t max)
{
    int count = 0;
    while (*s) {
        while (is_space(*s)) s++;
        if (!*s) break;
        if (*s < '0' || *s > '9') return -1;
        uint64_t v = 0;
        while (*s >= '0' && *s <= '9') {
            unsigned d = (unsigned)(*s - '0');
            if (v > (max - d) / 10) return -1;
            v = v * 10 + d;
            s++;
        }
        if (*s && !is_space(*s)) return -1;
        if (count < n) out[count] = v;
        count++;
        if (count > 64) return -1;
    }
    return count;
}

char *vxl_sibling_path(const char *base_path, const char *name)
{
    size_t dn = 0;
    if (!vxl_path_is_absolute(name)) {
        const char *slash = vxl_path_last_separator(base_path);
        dn = slash ? (size_t)(slash - base_path) + 1 : 0;
    }
    size_t nn = strlen(name);
    char *p = malloc(dn + nn + 1);
    if (!p) return NULL;
    memcpy(p, base_path, dn);
    memcpy(p + dn, name, nn + 1);
    return p;
}

int vxl_host_big_endian(void)
{
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 0;
}

void vxl_swap_elements(void *p, uint64_t count, size_t elem)
{
    if (elem < 2) return;
    unsigned char *b = p;
    for (uint64_t i = 0; i < count; i++) {
        unsigned char *x = b + i * elem;
        for (size_t k = 0; k < elem / 2; k++) {
            unsigned char t = x[k];
            x[k] = x[elem - 1 - k];
            x[elem - 1 - k] = t;
        }
    }
}

uint64_t vxl_load_budget(const vxl_load_options *opt)
{
    return opt && opt->memory_budget_bytes ? opt->memory_budget_bytes : VXL_DEFAULT_BUDGET;
}

int vxl_plan_voxels(const char *path, const uint32_t dims[3], uint32_t dtype, const vxl_load_options *opt,
                    uint64_t *nbytes, vxl_err *e)
{
    vxl_err inner = {0};
    if (vxl_volume_check_limits(dims, vxl_texture_bits_for(dtype) / 8, opt, &inner))
        return vxl_fail_in(e, path, &inner);
    uint64_t n = (uint64_t)dims[0] * dims[1] * dims[2];
    uint64_t size = vxl_dtype_size(dtype);
    if (n > (uint64_t)SIZE_MAX / size)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': volume too large for this address space", path);
    *nbytes = n * size;
    return VXL_OK;
}

int vxl_plan_colour_voxels(const char *path, const uint32_t dims[3], uint32_t dtype, uint32_t components,
                           const vxl_load_options *opt, uint64_t *nbytes, vxl_err *e)
{
    const uint32_t raw = vxl_dtype_size(dtype) * components,
                   texture = vxl_texture_bits_for(dtype) / 8 + VXL_COLOUR_BYTES_PER_VOXEL;
    vxl_err inner = {0};
    if (vxl_volume_check_limits(dims, raw > texture ? raw : texture, opt, &inner)) {
        if (inner.code == VXL_ERR_LIMIT)
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s': %s (colour volumes are read whole: streaming is not available for them)",
                            path, inner.msg);
        return vxl_fail_in(e, path, &inner);
    }
    *nbytes = (uint64_t)dims[0] * dims[1] * dims[2] * raw;
    return VXL_OK;
}

int vxl_plan_channel_voxels(const char *path, const uint32_t dims[3], uint32_t dtype, uint32_t channels,
                            const vxl_load_options *opt, uint64_t *nbytes, vxl_err *e)
{
    const uint32_t raw = vxl_dtype_size(dtype) * channels,
                   texture = vxl_texture_bits_for(dtype) / 8 + VXL_CHANNEL_BYTES * channels;
    vxl_err inner = {0};
    if (vxl_volume_check_limits(dims, raw > texture ? raw : texture, opt, &inner)) {
        if (inner.code == VXL_ERR_LIMIT)
            return vxl_fail(e, VXL_ERR_LIMIT,
                            "'%s': %s (multi-channel volumes are read whole: streaming is not available for them)", path,
                            inner.msg);
        return vxl_fail_in(e, path, &inner);
    }
    *nbytes = (uint64_t)dims[0] * dims[1] * dims[2] * vxl_dtype_size(dtype); /* one channel */
    return VXL_OK;
}

int vxl_build_interleaved(const char *path, const void *raw, uint32_t dtype, uint32_t channels, uint32_t components,
                          const uint32_t dims[3], const double sp[3], const double A[16], const vxl_load_options *opt,
                          const char *format, const char *channel_axis, int streaming_on, vxl_volume **out,
                          vxl_err *e)
{
    char what[96];
    vxl_err inner = {0};
    int rc;
    if (channels) {
        snprintf(what, sizeof what, "%s %s", format, channel_axis);
        rc = vxl_volume_build_channels(raw, dtype, channels, 1, dims, sp, A, 0.0, 0.0, opt, what, out, &inner);
    } else if (components > 1) {
        snprintf(what, sizeof what, "%s %s", format, components == 3 ? "RGB" : "RGBA");
        rc = vxl_volume_build_colour(raw, dtype, components, 0, dims, sp, A, 0.0, 0.0, opt, what, out, &inner);
    } else {
        rc = vxl_volume_build(raw, dtype, dims, sp, A, 0.0, 0.0, opt, out, &inner);
    }
    if (rc) return vxl_fail_in(e, path, &inner);
    if (streaming_on && (channels || components > 1))
        vxl_volume_note(*out, "read whole: a %s volume does not stream", channels ? "multi-channel" : "colour");
    return VXL_OK;
}

int vxl_affine_from(const double dir[3][3], const double origin[3], double A[16])
{
    memset(A, 0, 16 * sizeof *A);
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++) A[c * 4 + r] = dir[c][r];
    for (int r = 0; r < 3; r++) A[12 + r] = origin[r];
    A[15] = 1.0;
    for (int i = 0; i < 16; i++)
        if (!isfinite(A[i])) return 0;
    double det = A[0] * (A[5] * A[10] - A[9] * A[6]) - A[4] * (A[1] * A[10] - A[9] * A[2]) +
                 A[8] * (A[1] * A[6] - A[5] * A[2]);
    return isfinite(det) && det != 0.0;
}

/* Inflates from f (positioned at the stream) until nbytes land in buf after
 * skip_after bytes were discarded. Concatenated members are followed. */
static int inflate_into(FILE *f, const char *path, uint64_t skip_after, unsigned char *buf, uint64_t nbytes,
                        vxl_err *e)
{
    const vxl_zlib *zl = vxl_zlib_api(e);
    if (!zl) return VXL_ERR_IO;
    unsigned char *in = malloc(IO_CHUNK), *scratch = NULL;
    if (!in) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for decompression", path);
    z_stream z;
    memset(&z, 0, sizeof z);
    if (VXL_INFLATE_INIT2(zl, &z, 15 + 32) != Z_OK) { /* zlib or gzip, auto-detected */
        free(in);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': cannot start zlib", path);
    }
    int rc = VXL_OK;
    uint64_t produced = 0; /* counts skipped bytes too */
    uint64_t total = skip_after + nbytes;
    int ended = 0;
    while (produced < total) {
        if (z.avail_in == 0) {
            size_t r = fread(in, 1, IO_CHUNK, f);
            if (r == 0) {
                if (ferror(f)) rc = vxl_fail(e, VXL_ERR_IO, "read error in '%s'", path);
                break;
            }
            z.next_in = in;
            z.avail_in = (uInt)r;
        }
        if (ended) { /* another gzip member follows */
            if (zl->inflateReset(&z) != Z_OK) break;
            ended = 0;
        }
        unsigned char *dst;
        uint64_t room;
        if (produced < skip_after) {
            if (!scratch && !(scratch = malloc(IO_CHUNK))) {
                rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for decompression", path);
                break;
            }
            dst = scratch;
            room = skip_after - produced;
            if (room > IO_CHUNK) room = IO_CHUNK;
        } else {
            dst = buf + (produced - skip_after);
            room = total - produced;
            if (room > (1u << 30)) room = 1u << 30;
        }
        z.next_out = dst;
        z.avail_out = (uInt)room;
        int zr = zl->inflate(&z, Z_NO_FLUSH);
        produced += room - z.avail_out;
        if (zr == Z_STREAM_END) {
            ended = 1;
        } else if (zr == Z_BUF_ERROR) {
            if (z.avail_in == 0) continue; /* needs more input */
            rc = vxl_fail(e, VXL_ERR_FORMAT, "corrupt compressed data in '%s'", path);
            break;
        } else if (zr != Z_OK) {
            rc = vxl_fail(e, VXL_ERR_FORMAT, "corrupt compressed data in '%s': %s", path,
                          z.msg ? z.msg : "zlib error");
            break;
        }
    }
    if (!rc && produced < total)
        rc = vxl_fail(e, VXL_ERR_FORMAT,
                      "'%s': truncated compressed data: expected %llu bytes of voxel data, got %llu", path,
                      (unsigned long long)nbytes,
                      (unsigned long long)(produced > skip_after ? produced - skip_after : 0));
    zl->inflateEnd(&z);
    free(scratch);
    free(in);
    return rc;
}

int vxl_read_payload(const char *path, uint64_t offset, int from_end, int compressed, uint64_t skip_after,
                     uint64_t nbytes, void **out, vxl_err *e)
{
    *out = NULL;
    uint64_t size = 0;
    int rc = vxl_regular_file(path, &size, e);
    if (rc) return rc;
    if (!compressed) {
        if (from_end) {
            if (size < nbytes)
                return vxl_fail(e, VXL_ERR_FORMAT,
                                "'%s': truncated file: expected %llu bytes of voxel data, the file has %llu",
                                path, (unsigned long long)nbytes, (unsigned long long)size);
            offset = size - nbytes;
        }
        uint64_t have = size > offset ? size - offset : 0;
        if (have < nbytes)
            return vxl_fail(e, VXL_ERR_FORMAT,
                            "'%s': truncated file: expected %llu bytes of voxel data at offset %llu, got %llu",
                            path, (unsigned long long)nbytes, (unsigned long long)offset,
                            (unsigned long long)have);
    } else {
        if (offset >= size)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': truncated file: no compressed data after the header",
                            path);
        /* deflate cannot expand more than 1032:1: refuse a stream that is
         * too short for what the header claims before allocating for it. */
        uint64_t have = size - offset;
        if (have < (UINT64_MAX - 4096) / 1032 && have * 1032 + 4096 < nbytes + skip_after)
            return vxl_fail(e, VXL_ERR_FORMAT,
                            "'%s': truncated file: %llu bytes of compressed data cannot hold the %llu bytes of "
                            "voxel data the header claims", path, (unsigned long long)have,
                            (unsigned long long)nbytes);
    }
    FILE *f = vxl_fopen(path, "rb");
    if (!f) return vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    if (vxl_fseek(f, offset) != 0) {
        fclose(f);
        return vxl_fail(e, VXL_ERR_IO, "'%s': cannot seek to offset %llu", path, (unsigned long long)offset);
    }
    unsigned char *buf = malloc(nbytes ? (size_t)nbytes : 1);
    if (!buf) {
        fclose(f);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for %llu bytes of voxel data", path,
                        (unsigned long long)nbytes);
    }
    if (compressed) {
        rc = inflate_into(f, path, skip_after, buf, nbytes, e);
    } else {
        uint64_t got = 0;
        while (got < nbytes) {
            size_t want = nbytes - got > (1u << 30) ? (1u << 30) : (size_t)(nbytes - got);
            size_t r = fread(buf + got, 1, want, f);
            if (r == 0) break;
            got += r;
        }
        if (got < nbytes)
            rc = vxl_fail(e, ferror(f) ? VXL_ERR_IO : VXL_ERR_FORMAT,
                          "'%s': truncated file: expected %llu bytes of voxel data, got %llu", path,
                          (unsigned long long)nbytes, (unsigned long long)got);
    }
    fclose(f);
    if (rc) {
        free(buf);
        return rc;
    }
    *out = buf;
    return VXL_OK;
}

void vxl_load_voxel_size(const vxl_load_options *opt, double out[3])
{
    out[0] = out[1] = out[2] = 1.0;
    if (!opt) return;
    size_t need = offsetof(vxl_load_options, voxel_size) + sizeof opt->voxel_size;
    if (opt->struct_size != 0 && opt->struct_size < need) return;
    for (int a = 0; a < 3; a++) {
        double v = opt->voxel_size[a];
        if (isfinite(v) && v > 0) out[a] = v;
    }
}

/* The caller's struct reaches field end `need`: 0 means this header's size. */
static int options_cover(const vxl_load_options *opt, size_t need)
{
    return opt && (opt->struct_size == 0 || opt->struct_size >= need);
}

uint32_t vxl_load_frame(const vxl_load_options *opt)
{
    return options_cover(opt, offsetof(vxl_load_options, frame) + sizeof opt->frame) ? opt->frame : 0;
}

const char *vxl_load_series(const vxl_load_options *opt)
{
    return options_cover(opt, offsetof(vxl_load_options, series) + sizeof opt->series) ? opt->series : NULL;
}

char *vxl_one_line(char *s)
{
    char *w = s;
    int space = 0;
    for (const char *r = s; *r; r++) {
        if (*r == ' ' || *r == '\t' || *r == '\n' || *r == '\r' || *r == '\v' || *r == '\f') {
            space = w != s;
        } else {
            if (space) *w++ = ' ';
            space = 0;
            *w++ = *r;
        }
    }
    *w = '\0';
    return s;
}
