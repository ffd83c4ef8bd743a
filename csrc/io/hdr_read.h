/* hdr_read.h - Radiance RGBE images (.hdr, .pic) decoded from memory into
 * linear RGB floats, row 0 at the bottom: the World's map for
 * vxl_environment (environment_image.c reads the file). Bounded and
 * fuzz-safe: every length is checked against the bytes left, and a corrupt
 * or truncated file is VXL_ERR_FORMAT with what was wrong. */
#ifndef VXL_HDR_READ_H
#define VXL_HDR_READ_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"

/* Decodes data (size bytes). *width and *height receive the image's size;
 * more than max_pixels pixels is VXL_ERR_LIMIT. rgb NULL: the header only;
 * else rgb holds width*height*3 floats, every one finite and >= 0. */
int vxl_hdr_decode(const uint8_t *data, size_t size, uint64_t max_pixels, float *rgb, uint32_t *width,
                   uint32_t *height, vxl_err *e);

#endif
