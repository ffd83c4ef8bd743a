/* fuzz_dicom_rle.c - libFuzzer target: arbitrary bytes as one RLE Lossless
 * frame of a shape the input's prefix picks (dicom_rle_input.h) through
 * io/dicom_rle.c, under ASan+UBSan: every offset and run is checked, so a
 * read or write out of bounds, or a refusal without a reason, is a crash. */
#include <stdlib.h>
#include <string.h>

#include "dicom_rle.h"
#include "dicom_rle_input.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < RLE_PREFIX) return 0;
    uint32_t rows, cols, bytes;
    rle_input_shape(data, &rows, &cols, &bytes);
    void *px = malloc((size_t)rows * cols * bytes);
    if (!px) abort();
    char why[256] = "";
    /* the frame is copied to its own allocation so ASan sees its exact end */
    const size_t n = size - RLE_PREFIX;
    uint8_t *frame = malloc(n ? n : 1);
    if (!frame) abort();
    memcpy(frame, data + RLE_PREFIX, n);
    const int rc = vxl_dicom_rle_decode(frame, n, rows, cols, bytes, px, why, sizeof why);
    if (rc != 0 && (rc != -1 || !why[0])) abort();
    free(frame);
    free(px);
    return 0;
}
