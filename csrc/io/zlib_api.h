/* zlib_api.h - zlib's functions, looked up in the system's zlib on first
 * use (zlib_api.c; libz.so.1, or zlib1.dll beside voxlight.dll: os.h), so
 * libvoxlight links only the C runtime and loads in any Blender (official
 * builds carry their own zlib, linked in and not exported). Files are read
 * through gz_reader.h, not zlib's gz functions. Call sites use the table: z->inflate(...). CRC-32
 * is crc32.h's, which needs no zlib. The types
 * come from zlib.h (__typeof__), so a signature slip is a compile error,
 * yet nothing of zlib is linked. */
#ifndef VXL_ZLIB_API_H
#define VXL_ZLIB_API_H

#include <stddef.h>
#include <stdint.h>
#include <zlib.h>

#include "error.h"
#include "voxlight.h"

typedef struct vxl_zlib {
    __typeof__(&zlibVersion) zlibVersion;
    __typeof__(&inflateInit2_) inflateInit2_;
    __typeof__(&inflate) inflate;
    __typeof__(&inflateReset) inflateReset;
    __typeof__(&inflateEnd) inflateEnd;
    __typeof__(&uncompress) uncompress;
    __typeof__(&deflateInit_) deflateInit_;
    __typeof__(&deflate) deflate;
    __typeof__(&deflateEnd) deflateEnd;
    __typeof__(&compress2) compress2;
    __typeof__(&compressBound) compressBound;
} vxl_zlib;

/* The table, loading zlib on the first call from any thread; NULL with a
 * vxl_fail naming the library when it cannot be loaded. The table lives
 * for the process and never changes once filled. */
const vxl_zlib *vxl_zlib_api(vxl_err *e);

/* inflateInit2 (a macro in zlib.h) through the table. */
#define VXL_INFLATE_INIT2(z, strm, bits) ((z)->inflateInit2_((strm), (bits), ZLIB_VERSION, (int)sizeof(z_stream)))

#endif
