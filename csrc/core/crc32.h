/* crc32.h - CRC-32 as zlib, PNG and gzip compute it, without zlib: the
 * brick cache's checksums and PNG chunks need it on paths that do not
 * otherwise decompress anything. */
#ifndef VXL_CRC32_H
#define VXL_CRC32_H

#include <stddef.h>
#include <stdint.h>

/* The CRC of n more bytes after a running value crc (0 to start). */
uint32_t vxl_crc32(uint32_t crc, const void *p, size_t n);

#endif
