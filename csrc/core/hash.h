/* hash.h - FNV-1a over bytes, for the cache keys of derived volumes (the
 * classification key in frame.c, the illumination keys): equal inputs give
 * equal keys, so a cache is rebuilt only when what it depends on changed. */
#ifndef VXL_HASH_H
#define VXL_HASH_H

#include <stddef.h>
#include <stdint.h>

static inline uint64_t vxl_fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    for (size_t i = 0; i < n; i++) h = (h ^ c[i]) * 1099511628211ull;
    return h;
}

#endif
