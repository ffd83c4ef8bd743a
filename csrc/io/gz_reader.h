/* gz_reader.h - a file read as gzip or as plain bytes, whichever it is
 * (the gzip magic decides), through the platform's files (UTF-8 paths on
 * every OS) and zlib's inflate (zlib_api.h). zlib's own gz functions are not
 * used: on Windows they open files by the ANSI code page and the C runtime
 * of whichever zlib DLL is found, so a path like C:\Users\José fails. */
#ifndef VXL_GZ_READER_H
#define VXL_GZ_READER_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"

typedef struct vxl_gz vxl_gz;

/* NULL with a vxl_fail on failure (the OS's reason, or zlib missing when the
 * file is compressed). buffer_bytes: how much compressed input one read of
 * the file fetches (0: 64 KiB). */
vxl_gz *vxl_gz_open(const char *path, size_t buffer_bytes, vxl_err *e);

/* Up to n bytes of the uncompressed stream, *got of them (short only at its
 * end): VXL_OK, or a vxl_fail naming the file: VXL_ERR_IO for a read error,
 * VXL_ERR_FORMAT for corrupt or cut-off compressed data. A multi-member
 * gzip file reads as the members one after another. */
int vxl_gz_read(vxl_gz *f, void *buf, size_t n, size_t *got, vxl_err *e);

/* Moves to offset in the uncompressed stream: compressed data is inflated
 * and discarded on the way (from the start again when going back). VXL_OK,
 * or vxl_read's failures; a position past the end shows up as a short read. */
int vxl_gz_seek(vxl_gz *f, uint64_t offset, vxl_err *e);

/* 1 when the file is plain (not gzip): its size on disk is its stream's. */
int vxl_gz_direct(const vxl_gz *f);

void vxl_gz_close(vxl_gz *f);

#endif
