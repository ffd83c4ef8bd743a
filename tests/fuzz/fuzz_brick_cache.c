/* fuzz_brick_cache.c - libFuzzer target for the bricked cache reader of
 * gzip-compressed volumes (csrc/io/brick_cache_read.c, _format.c): the
 * input is a cache file, opened without a source to match (so header, index
 * and table checks all run on what the fuzzer writes), then every level is
 * read whole and in a corner box, decoding every brick (CRC, zlib,
 * constant, raw). Axes up to 64 voxels keep a level within 1 MiB. The
 * contract: success gives a source, failure NULL and a message; a read
 * fails with a message or fills the box. Seeds: build/tests/test_brick_cache
 * --write-seeds DIR (tests/fuzz/run.sh). */
#include "brick_cache.h"
#include "fuzz_common.h"

#define FUZZ_MAX_DIM 64u

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = vxl_fuzz_write(data, size, "vxlcache");
    vxl_brick_source *s = NULL;
    vxl_err e = {0};
    int rc = vxl_brick_cache_read_open(path, NULL, FUZZ_MAX_DIM, &s, &e);
    if ((rc == VXL_OK) != (s != NULL) || (rc && !e.msg[0])) abort();
    if (!s) return 0;
    static uint8_t buf[FUZZ_MAX_DIM * FUZZ_MAX_DIM * FUZZ_MAX_DIM * 4];
    for (uint32_t L = 0; L < s->n_levels; L++) {
        const uint32_t *d = s->level_dims[L];
        if (d[0] > FUZZ_MAX_DIM || d[1] > FUZZ_MAX_DIM || d[2] > FUZZ_MAX_DIM) abort();
        const uint32_t lo[3] = {0, 0, 0}, corner[3] = {d[0] - 1, d[1] - 1, d[2] - 1}, one[3] = {1, 1, 1};
        vxl_err re = {0};
        if (s->ops->read(s, L, lo, d, buf, &re) != VXL_OK && !re.msg[0]) abort();
        re.msg[0] = 0;
        if (s->ops->read(s, L, corner, one, buf, &re) != VXL_OK && !re.msg[0]) abort();
    }
    vxl_brick_source_free(s);
    return 0;
}
