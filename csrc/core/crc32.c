/* crc32.c - crc32.h, slicing by 8: eight bytes per step through eight
 * tables (crc32_tables.h), several times faster than a byte at a time on
 * the megabytes of a brick. */
#include "crc32.h"

#include <string.h>

#include "crc32_tables.h"

uint32_t vxl_crc32(uint32_t crc, const void *p, size_t n)
{
    const unsigned char *b = p;
    const uint32_t(*t)[256] = vxl_crc32_table;
    crc = ~crc;
    for (; n && ((uintptr_t)b & 7u); n--) crc = t[0][(crc ^ *b++) & 0xffu] ^ (crc >> 8);
    for (; n >= 8; n -= 8, b += 8) {
        uint32_t lo, hi;
        memcpy(&lo, b, 4); /* little-endian hosts: every target the library builds for */
        memcpy(&hi, b + 4, 4);
        lo ^= crc;
        crc = t[7][lo & 0xffu] ^ t[6][(lo >> 8) & 0xffu] ^ t[5][(lo >> 16) & 0xffu] ^ t[4][lo >> 24] ^
              t[3][hi & 0xffu] ^ t[2][(hi >> 8) & 0xffu] ^ t[1][(hi >> 16) & 0xffu] ^ t[0][hi >> 24];
    }
    for (; n; n--) crc = t[0][(crc ^ *b++) & 0xffu] ^ (crc >> 8);
    return ~crc;
}
