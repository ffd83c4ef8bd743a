/* dicom_jpeg_lossless.h - lossless JPEG (ITU T.81 process 14, Annex H):
 * DICOM's JPEG Lossless transfer syntaxes (1.2.840.10008.1.2.4.57 and .70,
 * "SV1", the usual PACS export of CT and MR) decoded in our own C: Huffman
 * coded differences from one of seven predictors, small and fully
 * specified, so it runs wherever the core does. */
#ifndef VXL_DICOM_JPEG_LOSSLESS_H
#define VXL_DICOM_JPEG_LOSSLESS_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "voxlight.h"

/* Decodes one frame (the fragments of a frame joined: SOI ... EOI) of rows
 * x cols grey samples into dst, bytes_per_pixel (1 or 2) each in native
 * byte order. VXL_OK, or a vxl_fail with the reason (VXL_ERR_FORMAT): a
 * frame of another size or more than one component, an unsupported process,
 * or corrupt or cut-short data (every length, table and code is checked
 * against the input). */
int vxl_jpeg_lossless_decode(const uint8_t *data, size_t n, uint32_t rows, uint32_t cols, uint32_t bytes_per_pixel,
                             void *dst, vxl_err *e);

#endif
