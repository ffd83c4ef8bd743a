/* dicom_rle_input.h - how the DICOM RLE fuzz target reads its input: a
 * 4-byte prefix (rows - 1, cols - 1, bytes per pixel (1 + low bit), spare),
 * then one frame as it sits in a file's fragments. make_seeds writes its
 * seeds the same way. */
#ifndef VXL_FUZZ_DICOM_RLE_INPUT_H
#define VXL_FUZZ_DICOM_RLE_INPUT_H

#include <stdint.h>

#define RLE_PREFIX 4

static inline void rle_input_shape(const uint8_t *in, uint32_t *rows, uint32_t *cols, uint32_t *bytes)
{
    *rows = (uint32_t)in[0] + 1;
    *cols = (uint32_t)in[1] + 1;
    *bytes = 1 + (in[2] & 1u);
}

#endif
