/* dicom_rle.c - dicom_rle.h. */
#include "dicom_rle.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HEADER_BYTES 64

static uint32_t le32(const uint8_t *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }

/* PackBits from seg[0..n) into out[0..want): 0 when exactly want bytes came
 * (an encoder may pad a segment to even length: what follows is ignored),
 * -1 when the segment ends first or a run overshoots. */
static int unpack_bits(const uint8_t *seg, size_t n, uint8_t *out, size_t want)
{
    size_t i = 0, o = 0;
    while (o < want) {
        if (i >= n) return -1;
        const int c = (int8_t)seg[i++];
        if (c >= 0) { /* c + 1 literal bytes */
            const size_t run = (size_t)c + 1;
            if (run > n - i || run > want - o) return -1;
            memcpy(out + o, seg + i, run);
            i += run;
            o += run;
        } else if (c != -128) { /* the next byte, 1 - c times */
            const size_t run = (size_t)(1 - c);
            if (i >= n || run > want - o) return -1;
            memset(out + o, seg[i++], run);
            o += run;
        } /* -128: no operation */
    }
    return 0;
}

int vxl_dicom_rle_decode(const uint8_t *frame, size_t n, uint32_t rows, uint32_t cols, uint32_t bytes_per_pixel,
                         void *dst, vxl_err *e)
{
    return vxl_dicom_rle_decode_samples(frame, n, rows, cols, bytes_per_pixel, 1, dst, e);
}

int vxl_dicom_rle_decode_samples(const uint8_t *frame, size_t n, uint32_t rows, uint32_t cols,
                                 uint32_t bytes_per_sample, uint32_t samples, void *dst, vxl_err *e)
{
    if (bytes_per_sample != 1 && bytes_per_sample != 2 && bytes_per_sample != 4)
        return vxl_fail(e, VXL_ERR_FORMAT, "RLE of %u-byte pixels is not supported", bytes_per_sample);
    if (samples != 1 && samples != 3)
        return vxl_fail(e, VXL_ERR_FORMAT, "RLE of %u samples per pixel is not supported", samples);
    if (n < HEADER_BYTES)
        return vxl_fail(e, VXL_ERR_FORMAT, "RLE frame of %zu bytes is shorter than its %d-byte header", n,
                        HEADER_BYTES);
    const uint32_t segments = le32(frame);
    if (segments != bytes_per_sample * samples)
        return vxl_fail(e, VXL_ERR_FORMAT, "RLE frame has %u segments, expected %u (%u sample(s) of %u byte(s))",
                        segments, bytes_per_sample * samples, samples, bytes_per_sample);
    const size_t pixels = (size_t)rows * cols;
    uint8_t *plane = malloc(pixels ? pixels : 1);
    if (!plane) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for a %ux%u RLE frame", cols, rows);
    int rc = VXL_OK;
    for (uint32_t s = 0; s < segments && !rc; s++) {
        const uint32_t start = le32(frame + 4 + 4 * s);
        const uint32_t end = s + 1 < segments ? le32(frame + 8 + 4 * s) : (uint32_t)(n > UINT32_MAX ? UINT32_MAX : n);
        if (start < HEADER_BYTES || start > end || end > n) {
            rc = vxl_fail(e, VXL_ERR_FORMAT, "RLE segment %u has offset %u outside its frame", s, start);
            break;
        }
        if (unpack_bits(frame + start, end - start, plane, pixels)) {
            rc = vxl_fail(e, VXL_ERR_FORMAT, "RLE segment %u does not decode to %zu bytes (corrupt or cut short)", s,
                          pixels);
            break;
        }
        /* sample by sample; within one, the most significant byte first */
        const uint32_t sample = s / bytes_per_sample, byte = s % bytes_per_sample;
        const unsigned shift = 8u * (bytes_per_sample - 1 - byte);
        if (bytes_per_sample == 1) {
            memcpy((uint8_t *)dst + sample * pixels, plane, pixels);
        } else if (bytes_per_sample == 2) {
            uint16_t *d = (uint16_t *)dst + sample * pixels;
            for (size_t i = 0; i < pixels; i++) d[i] = (uint16_t)((byte ? d[i] : 0u) | (unsigned)plane[i] << shift);
        } else {
            uint32_t *d = (uint32_t *)dst + sample * pixels;
            for (size_t i = 0; i < pixels; i++) d[i] = (byte ? d[i] : 0u) | (uint32_t)plane[i] << shift;
        }
    }
    free(plane);
    return rc;
}
