/* dicom_j2k.h - DICOM's JPEG 2000 transfer syntaxes (1.2.840.10008.1.2.4.90
 * lossless, .91 lossy, and HTJ2K .201, .202, .203): each frame is a J2K
 * codestream (or now and then a JP2 file), decoded by the system's OpenJPEG,
 * opened on the first frame (dicom_j2k.c; os.h names the file) and never
 * linked: wavelets, tiers 1 and 2 and the HT block coder are a large codec
 * that a well-kept library does better than we would, and a system without
 * it still reads every other syntax. */
#ifndef VXL_DICOM_J2K_H
#define VXL_DICOM_J2K_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "voxlight.h"

/* Decodes one frame (its fragments joined: a J2K codestream, FF 4F FF 51,
 * or a JP2 file) of rows x cols pixels of `samples` components into dst:
 * rows * cols * samples values, the samples of a pixel interleaved, each
 * bytes_per_sample (1 or 2) in native byte order; a signed component is
 * sign-extended into its 8- or 16-bit container. VXL_OK, or a vxl_fail with
 * one line: VXL_ERR_IO when OpenJPEG cannot be loaded (naming the package),
 * VXL_ERR_FORMAT for a frame that is corrupt or cut short (OpenJPEG's own
 * reason), of another size, component count or subsampling, or deeper than
 * bytes_per_sample holds. The size is checked from the header before any
 * tile is decoded, so a frame never allocates more than its declared size.
 * Thread-safe. */
int vxl_j2k_decode(const uint8_t *data, size_t n, uint32_t rows, uint32_t cols, uint32_t bytes_per_sample,
                   uint32_t samples, void *dst, vxl_err *e);

#endif
