/* matcap_png.h - --matcap FILE.png for the CLI: a PNG read into
 * the linear RGBA floats vxl_matcap takes. */
#ifndef VXL_MATCAP_PNG_H
#define VXL_MATCAP_PNG_H

#include <stddef.h>
#include <stdint.h>

/* Reads an 8- or 16-bit, non-interlaced PNG (grey, grey+alpha, RGB, RGBA;
 * palette images are refused) into *rgba (w*h*4 floats, row 0 = bottom,
 * values as stored, alpha 1; free() it). 0 on success; otherwise
 * nonzero with a message in err. */
int vxl_cli_read_matcap_png(const char *path, float **rgba, uint32_t *w, uint32_t *h, char *err, size_t err_size);

#endif
