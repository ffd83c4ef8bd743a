/* dicom_rle.h - DICOM's RLE Lossless transfer syntax (1.2.840.10008.1.2.5,
 * PS3.5 Annex G) decoded in our own C: it is small and fully specified, and
 * so runs wherever the core does. One frame: a 64-byte header (the number of
 * segments, then each segment's offset), then one PackBits segment per byte
 * of each sample, most significant byte first. */
#ifndef VXL_DICOM_RLE_H
#define VXL_DICOM_RLE_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "voxlight.h"

/* Decodes one frame of rows x cols single-sample pixels of bytes_per_pixel
 * (1, 2 or 4) from the frame's fragments joined (frame[0..n)) into dst, native
 * byte order. VXL_OK, or a vxl_fail with the reason (VXL_ERR_FORMAT: the
 * frame is corrupt or cut short; every offset and run is checked against n
 * and the frame's size). */
int vxl_dicom_rle_decode(const uint8_t *frame, size_t n, uint32_t rows, uint32_t cols, uint32_t bytes_per_pixel,
                         void *dst, vxl_err *e);

/* The same for `samples` (1 or 3) samples per pixel: one segment per byte of
 * each sample, sample by sample, so dst receives the samples as planes
 * (all of sample 0, then sample 1, ...: planar configuration 1, which is how
 * RLE stores colour whatever the header says). */
int vxl_dicom_rle_decode_samples(const uint8_t *frame, size_t n, uint32_t rows, uint32_t cols,
                                 uint32_t bytes_per_sample, uint32_t samples, void *dst, vxl_err *e);

#endif
