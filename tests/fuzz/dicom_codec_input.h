/* dicom_codec_input.h - how the DICOM codec fuzz target reads its input: a
 * 4-byte prefix (rows - 1, cols - 1, bytes per pixel (1 + low bit), codec
 * (low bit: 0 RLE Lossless, 1 JPEG Lossless)), then one frame as it sits in
 * a file's fragments. make_seeds and jpeg_seeds.py write seeds the same way. */
#ifndef VXL_FUZZ_DICOM_CODEC_INPUT_H
#define VXL_FUZZ_DICOM_CODEC_INPUT_H

#include <stdint.h>

#define CODEC_PREFIX 4

static inline void codec_input_shape(const uint8_t *in, uint32_t *rows, uint32_t *cols, uint32_t *bytes, int *jpeg)
{
    *rows = (uint32_t)in[0] + 1;
    *cols = (uint32_t)in[1] + 1;
    *bytes = 1 + (in[2] & 1u);
    *jpeg = in[3] & 1;
}

#endif
