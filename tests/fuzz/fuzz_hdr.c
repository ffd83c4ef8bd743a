/* fuzz_hdr.c - libFuzzer target: arbitrary bytes as a Radiance .hdr World
 * map through the in-process RGBE decoder (csrc/io/hdr_read.c), header
 * first and then the pixels, under ASan+UBSan (see Makefile 'fuzz',
 * tests/fuzz/run.sh). Checks the decoder's promises: an error has a
 * message; a decoded map has the size the header gave, within the limit,
 * and every value finite and >= 0. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "hdr_read.h"
#include "voxlight.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define MAX_PIXELS (1u << 20) /* 12 MiB of floats: room for the fuzzer's largest maps */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint32_t w = 0, h = 0;
    vxl_err e = {0};
    int rc = vxl_hdr_decode(data, size, MAX_PIXELS, NULL, &w, &h, &e);
    if (rc != VXL_OK) {
        if (!e.msg[0]) abort();
        return 0;
    }
    if (!w || !h || (uint64_t)w * h > MAX_PIXELS) abort();
    float *rgb = malloc((size_t)w * h * 3 * sizeof *rgb);
    if (!rgb) return 0;
    uint32_t w2 = 0, h2 = 0;
    vxl_err e2 = {0};
    rc = vxl_hdr_decode(data, size, MAX_PIXELS, rgb, &w2, &h2, &e2);
    if (rc != VXL_OK && !e2.msg[0]) abort();
    if (rc == VXL_OK) {
        if (w2 != w || h2 != h) abort();
        for (size_t i = 0; i < (size_t)w * h * 3; i++)
            if (!(rgb[i] >= 0 && isfinite(rgb[i]))) abort();
    }
    free(rgb);
    return 0;
}
