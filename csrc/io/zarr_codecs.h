/* zarr_codecs.h - the functions of libzstd and libblosc that Zarr chunks
 * need, looked up with dlopen/dlsym on first use (zarr_codecs.c); the
 * decoders in zarr_chunk.c call them through these tables. */
#ifndef VXL_ZARR_CODECS_H
#define VXL_ZARR_CODECS_H

#include <blosc.h>
#include <zstd.h>
#include <zstd_errors.h>

#include "zarr.h"

#define VXL_ZSTD_SO "libzstd.so.1"
#define VXL_BLOSC_SO "libblosc.so.1"

typedef struct vxl_zstd_api {
    __typeof__(&ZSTD_getFrameContentSize) getFrameContentSize;
    __typeof__(&ZSTD_decompress) decompress;
    __typeof__(&ZSTD_isError) isError;
    __typeof__(&ZSTD_getErrorCode) getErrorCode;
    __typeof__(&ZSTD_getErrorName) getErrorName;
} vxl_zstd_api;

typedef struct vxl_blosc_api {
    __typeof__(&blosc_cbuffer_validate) cbuffer_validate;
    __typeof__(&blosc_cbuffer_sizes) cbuffer_sizes;
    __typeof__(&blosc_decompress_ctx) decompress_ctx;
} vxl_blosc_api;

/* The table in *api, opening the library on the first call; otherwise a
 * vxl_fail naming the library, the codec and chunk (the file decoded). */
int vxl_zarr_zstd(vxl_zarr_codecs *c, const char *chunk, const vxl_zstd_api **api, vxl_err *e);
int vxl_zarr_blosc(vxl_zarr_codecs *c, const char *chunk, const vxl_blosc_api **api, vxl_err *e);

#endif
