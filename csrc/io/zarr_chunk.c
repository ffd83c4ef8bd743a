/* zarr_chunk.c - one Zarr chunk: its key (file name), reading the stored
 * bytes and decoding them (raw, gzip/zlib with zlib, zstd with libzstd,
 * blosc with libblosc) into exactly the chunk's decoded size. A chunk that
 * decodes to more or fewer bytes than the metadata says, or whose file is
 * larger than any encoding of that size could be, is an error naming the
 * file; nothing is allocated from a stored size. libzstd and libblosc are
 * reached through the dlopen'd tables of zarr_codecs.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "loader_util.h"
#include "zarr.h"
#include "zarr_codecs.h"
#include "zlib_api.h"

static int decode_zlib(const void *src, size_t n, void *out, uint64_t nbytes, const char *name, vxl_err *e)
{
    const vxl_zlib *zl = vxl_zlib_api(e);
    if (!zl) return VXL_ERR_IO;
    z_stream z;
    memset(&z, 0, sizeof z);
    if (VXL_INFLATE_INIT2(zl, &z, 15 + 32) != Z_OK) /* 15 + 32: zlib or gzip header, detected */
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': cannot start zlib", name);
    z.next_in = (Bytef *)src;
    z.avail_in = (uInt)n; /* the caller bounds n below 4 GiB */
    z.next_out = out;
    z.avail_out = (uInt)nbytes;
    int r = zl->inflate(&z, Z_FINISH);
    uint64_t got = z.total_out;
    unsigned char extra;
    if (r == Z_BUF_ERROR && z.avail_out == 0) {
        /* the output is full: is there more? */
        z.next_out = &extra;
        z.avail_out = 1;
        r = zl->inflate(&z, Z_FINISH);
        if (z.avail_out == 0) r = Z_BUF_ERROR - 100; /* it had more */
    }
    zl->inflateEnd(&z);
    if (r == Z_BUF_ERROR - 100)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the chunk decompresses to more than the %llu bytes its array "
                        "metadata says", name, (unsigned long long)nbytes);
    if (r != Z_STREAM_END)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': corrupt or truncated gzip/zlib chunk", name);
    if (got != nbytes)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the chunk decompresses to %llu bytes, not the %llu its array "
                        "metadata says", name, (unsigned long long)got, (unsigned long long)nbytes);
    return VXL_OK;
}

static int decode_zstd(vxl_zarr_codecs *codecs, const void *src, size_t n, void *out, uint64_t nbytes,
                       const char *name, vxl_err *e)
{
    const vxl_zstd_api *z = NULL;
    int rc = vxl_zarr_zstd(codecs, name, &z, e);
    if (rc) return rc;
    unsigned long long claimed = z->getFrameContentSize(src, n);
    if (claimed == ZSTD_CONTENTSIZE_ERROR) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': not a zstd chunk", name);
    if (claimed != ZSTD_CONTENTSIZE_UNKNOWN && claimed > nbytes)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the chunk decompresses to %llu bytes, more than the %llu its array "
                        "metadata says", name, claimed, (unsigned long long)nbytes);
    /* the output capacity bounds the work whatever the frames claim */
    size_t got = z->decompress(out, (size_t)nbytes, src, n);
    if (z->isError(got)) {
        if (z->getErrorCode(got) == ZSTD_error_dstSize_tooSmall)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the chunk decompresses to more than the %llu bytes its array "
                            "metadata says", name, (unsigned long long)nbytes);
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': corrupt zstd chunk (%s)", name, z->getErrorName(got));
    }
    if (got != nbytes)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the chunk decompresses to %zu bytes, not the %llu its array "
                        "metadata says", name, got, (unsigned long long)nbytes);
    return VXL_OK;
}

static int decode_blosc(vxl_zarr_codecs *codecs, const void *src, size_t n, void *out, uint64_t nbytes,
                        const char *name, vxl_err *e)
{
    const vxl_blosc_api *b = NULL;
    int rc = vxl_zarr_blosc(codecs, name, &b, e);
    if (rc) return rc;
    size_t claimed = 0, cbytes = 0, blocksize = 0;
    /* blosc's header is 16 bytes; validate checks its sizes against n
     * before anything is decompressed */
    if (n < BLOSC_MIN_HEADER_LENGTH || b->cbuffer_validate(src, n, &claimed) < 0)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': not a valid blosc chunk", name);
    b->cbuffer_sizes(src, &claimed, &cbytes, &blocksize);
    if (claimed != nbytes)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the blosc chunk holds %zu bytes, not the %llu its array metadata "
                        "says", name, claimed, (unsigned long long)nbytes);
    if (cbytes != n)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the blosc chunk says %zu bytes compressed, the file has %zu",
                        name, cbytes, n);
    int got = b->decompress_ctx(src, out, (size_t)nbytes, 1); /* no global state, one thread */
    if (got < 0 || (uint64_t)got != nbytes)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': corrupt blosc chunk", name);
    return VXL_OK;
}

int vxl_zarr_decode(const vxl_zarr_array *a, vxl_zarr_codecs *codecs, const void *src, size_t n, void *out,
                    uint64_t nbytes, const char *name, vxl_err *e)
{
    if (nbytes > VXL_ZARR_MAX_CHUNK_BYTES || n > (size_t)2 * VXL_ZARR_MAX_CHUNK_BYTES)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': chunk too large", name);
    int rc;
    switch (a->codec) {
    case VXL_ZARR_RAW:
        if (n != nbytes)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': an uncompressed chunk of %zu bytes, not the %llu its array "
                            "metadata says", name, n, (unsigned long long)nbytes);
        memcpy(out, src, n);
        rc = VXL_OK;
        break;
    case VXL_ZARR_ZLIB: rc = decode_zlib(src, n, out, nbytes, name, e); break;
    case VXL_ZARR_ZSTD: rc = decode_zstd(codecs, src, n, out, nbytes, name, e); break;
    case VXL_ZARR_BLOSC: rc = decode_blosc(codecs, src, n, out, nbytes, name, e); break;
    default: return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unknown codec", name);
    }
    if (rc) return rc;
    size_t elem = vxl_dtype_size(a->dtype);
    if (elem > 1 && a->big_endian != vxl_host_big_endian()) vxl_swap_elements(out, nbytes / elem, elem);
    return VXL_OK;
}

/* The chunk's file: v2 "i.j.k" (or "i/j/k"), v3 "c/i/j/k" (or "c.i.j.k"). */
static int chunk_path(const vxl_zarr_array *a, const uint64_t *idx, char *p, size_t size)
{
    int n = snprintf(p, size, "%s/%s", a->path, a->key_prefix ? "c" : "");
    for (int i = 0; i < a->ndim && n > 0 && (size_t)n < size; i++) {
        int first = i == 0 && !a->key_prefix;
        n += snprintf(p + n, size - (size_t)n, "%s%llu", first ? "" : (char[]){a->separator, 0},
                      (unsigned long long)idx[i]);
    }
    return n > 0 && (size_t)n < size;
}

/* The chunk's value a->fill in the chunk's native type. */
static void fill_chunk(const vxl_zarr_array *a, void *out, uint64_t nbytes)
{
    const size_t elem = vxl_dtype_size(a->dtype);
    const uint64_t count = nbytes / elem;
    double f = a->fill;
    if (a->dtype != VXL_DTYPE_F32 && a->dtype != VXL_DTYPE_F64 && !isfinite(f)) f = 0;
    if (f == 0 && !signbit(f)) {
        memset(out, 0, nbytes);
        return;
    }
    unsigned char v[8];
    switch (a->dtype) {
    case VXL_DTYPE_U8: { uint8_t x = (uint8_t)fmin(fmax(f, 0), 255); memcpy(v, &x, 1); break; }
    case VXL_DTYPE_I8: { int8_t x = (int8_t)fmin(fmax(f, -128), 127); memcpy(v, &x, 1); break; }
    case VXL_DTYPE_U16: { uint16_t x = (uint16_t)fmin(fmax(f, 0), 65535); memcpy(v, &x, 2); break; }
    case VXL_DTYPE_I16: { int16_t x = (int16_t)fmin(fmax(f, -32768), 32767); memcpy(v, &x, 2); break; }
    case VXL_DTYPE_U32: { uint32_t x = (uint32_t)fmin(fmax(f, 0), 4294967295.0); memcpy(v, &x, 4); break; }
    case VXL_DTYPE_I32: { int32_t x = (int32_t)fmin(fmax(f, -2147483648.0), 2147483647.0); memcpy(v, &x, 4); break; }
    case VXL_DTYPE_F32: { float x = (float)f; memcpy(v, &x, 4); break; }
    default: memcpy(v, &f, 8); break;
    }
    unsigned char *o = out;
    for (uint64_t i = 0; i < count; i++) memcpy(o + i * elem, v, elem);
}

int vxl_zarr_read_chunk(const vxl_zarr_array *a, const uint64_t *idx, vxl_zarr_codecs *codecs, void *out,
                        vxl_err *e)
{
    return vxl_zarr_read_chunk_counted(a, idx, codecs, out, NULL, e);
}

int vxl_zarr_read_chunk_counted(const vxl_zarr_array *a, const uint64_t *idx, vxl_zarr_codecs *codecs, void *out,
                                uint64_t *bytes_read, vxl_err *e)
{
    const uint64_t nbytes = vxl_zarr_chunk_bytes(a);
    if (!nbytes) return vxl_fail(e, VXL_ERR_LIMIT, "'%s': chunk too large", a->path);
    for (int i = 0; i < a->ndim; i++)
        if (idx[i] >= (a->shape[i] + a->chunks[i] - 1) / a->chunks[i])
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': chunk index outside the grid", a->path);
    char p[4096 + 128];
    if (!chunk_path(a, idx, p, sizeof p)) return vxl_fail(e, VXL_ERR_IO, "'%s': path too long", a->path);
    /* No codec here grows data by more than a small fraction (zstd's and
     * blosc's worst case is the raw bytes plus headers): a larger file is
     * not this chunk, and is refused before it is read into memory. */
    const uint64_t most = nbytes + nbytes / 8 + 65536;
    char *buf = NULL;
    size_t n = 0;
    uint64_t size = 0;
    int rc = vxl_zarr_read_file(p, most, &buf, &n, &size, e);
    if (rc == VXL_ZARR_FILE_MISSING) {
        fill_chunk(a, out, nbytes); /* Zarr leaves chunks of only fill_value unwritten */
        return VXL_OK;
    }
    if (rc == VXL_ZARR_FILE_TOO_LARGE)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %llu bytes, more than any encoding of the chunk's %llu bytes",
                        p, (unsigned long long)size, (unsigned long long)nbytes);
    if (rc) return rc;
    if (bytes_read) __atomic_fetch_add(bytes_read, (uint64_t)n, __ATOMIC_RELAXED);
    rc = vxl_zarr_decode(a, codecs, buf, n, out, nbytes, p, e);
    free(buf);
    return rc;
}
