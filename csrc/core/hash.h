/* hash.h - FNV-1a over bytes, for the cache keys of derived volumes (the
 * classification key in frame.c, the illumination keys): equal inputs give
 * equal keys, so a cache is rebuilt only when what it depends on changed. */
#ifndef VXL_HASH_H
#define VXL_HASH_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

static inline uint64_t vxl_fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    for (size_t i = 0; i < n; i++) h = (h ^ c[i]) * 1099511628211ull;
    return h;
}

/* The same step over 8-byte words (the tail byte by byte): several times
 * faster, for arrays of megabytes hashed every frame (the occluder
 * meshes when the caller gives no key). A different key from vxl_fnv's. */
static inline uint64_t vxl_fnv_words(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t w;
        memcpy(&w, c + i, sizeof w);
        h = (h ^ w) * 1099511628211ull;
    }
    return vxl_fnv(h, c + i, n - i);
}

#endif
