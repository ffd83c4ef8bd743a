/* fuzz_dicom_codecs.c - libFuzzer target: arbitrary bytes as one frame of
 * the DICOM codecs written in our own C (io/dicom_rle.c,
 * io/dicom_jpeg_lossless.c), of a shape and codec the input's prefix picks
 * (dicom_codec_input.h), under ASan+UBSan: every offset, table, code and run
 * is checked, so a read or write out of bounds, or a refusal without a
 * reason, is a crash. */
#include <stdlib.h>
#include <string.h>

#include "dicom_codec_input.h"
#include "dicom_jpeg_lossless.h"
#include "dicom_rle.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < CODEC_PREFIX) return 0;
    uint32_t rows, cols, bytes;
    int jpeg;
    codec_input_shape(data, &rows, &cols, &bytes, &jpeg);
    void *px = malloc((size_t)rows * cols * bytes);
    if (!px) abort();
    vxl_err e = {0};
    /* the frame is copied to its own allocation so ASan sees its exact end */
    const size_t n = size - CODEC_PREFIX;
    uint8_t *frame = malloc(n ? n : 1);
    if (!frame) abort();
    memcpy(frame, data + CODEC_PREFIX, n);
    const int rc = jpeg ? vxl_jpeg_lossless_decode(frame, n, rows, cols, bytes, px, &e)
                        : vxl_dicom_rle_decode(frame, n, rows, cols, bytes, px, &e);
    if (rc != VXL_OK && (rc != e.code || !e.msg[0])) abort();
    free(frame);
    free(px);
    return 0;
}
