/* zlib_api.h - zlib's functions, looked up in the system's libz.so.1 on
 * first use (zlib_api.c), so libvoxlight links only the C runtime and
 * loads in any Blender (official builds carry their own zlib, linked in
 * and not exported). Call sites use the table: z->inflate(...). CRC-32
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

#define VXL_ZLIB_SO "libz.so.1"

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
    __typeof__(&gzopen) gzopen;
    __typeof__(&gzbuffer) gzbuffer;
    __typeof__(&gzread) gzread;
    __typeof__(&gzseek) gzseek;
    __typeof__(&gzdirect) gzdirect;
    __typeof__(&gzerror) gzerror;
    __typeof__(&gzclose) gzclose;
} vxl_zlib;

/* The table, loading zlib on the first call from any thread; NULL with a
 * vxl_fail naming the library when it cannot be loaded. The table lives
 * for the process and never changes once filled. */
const vxl_zlib *vxl_zlib_api(vxl_err *e);

/* inflateInit2 (a macro in zlib.h) through the table. */
#define VXL_INFLATE_INIT2(z, strm, bits) ((z)->inflateInit2_((strm), (bits), ZLIB_VERSION, (int)sizeof(z_stream)))

/* A file read through zlib's gz functions (gzip or plain, detected), for
 * readers that take a path: the table travels with the file. */
typedef struct vxl_gz vxl_gz;

/* NULL with a vxl_fail on failure (zlib missing, or the OS's reason). */
vxl_gz *vxl_gz_open(const char *path, unsigned buffer_bytes, vxl_err *e);
int vxl_gz_read(vxl_gz *f, void *buf, unsigned n);
const char *vxl_gz_error(vxl_gz *f, int *zerr);
z_off_t vxl_gz_seek(vxl_gz *f, z_off_t offset, int whence);
int vxl_gz_direct(vxl_gz *f);
void vxl_gz_close(vxl_gz *f);

#endif
