/* environment_image.c - vxl_environment_image_load: a World map file. A
 * Radiance .hdr is read whole under a size cap and decoded by our own reader
 * (hdr_read.c); an OpenEXR .exr goes to the OpenImageIO helper process
 * (loaders.h, environment_exr.cpp), whose codecs stay out of the library. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "error.h"
#include "files.h"
#include "hdr_read.h"
#include "loaders.h"
#include "voxlight.h"

/* As vxl_environment's limit: 2^26 pixels, 4 bytes each flat, plus the header. */
#define MAX_PIXELS (1ull << 26)
#define MAX_FILE (MAX_PIXELS * 4 + 65536 + 64)

static int has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), k = strlen(ext);
    return n >= k && !strcasecmp(path + n - k, ext);
}

static int read_whole(const char *path, uint8_t **data, size_t *size, vxl_err *e)
{
    FILE *f = vxl_fopen(path, "rb");
    if (!f) return vxl_fail(e, VXL_ERR_IO, "cannot open %s", path);
    size_t cap = 1 << 16, n = 0;
    uint8_t *buf = malloc(cap);
    int rc = buf ? VXL_OK : vxl_fail(e, VXL_ERR_NO_MEMORY, "no memory to read %s", path);
    while (!rc) {
        if (n == cap) {
            if (cap >= MAX_FILE) {
                rc = vxl_fail(e, VXL_ERR_LIMIT, "%s is larger than an environment map may be (%llu bytes)", path,
                              (unsigned long long)MAX_FILE);
                break;
            }
            cap = cap * 2 > MAX_FILE ? MAX_FILE : cap * 2;
            uint8_t *b = realloc(buf, cap);
            if (!b) {
                rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "no memory to read %s", path);
                break;
            }
            buf = b;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) {
            if (ferror(f)) rc = vxl_fail(e, VXL_ERR_IO, "cannot read %s", path);
            break;
        }
    }
    fclose(f);
    if (rc) {
        free(buf);
        return rc;
    }
    *data = buf;
    *size = n;
    return VXL_OK;
}

/* The helper sends the whole image; a caller asking for its size only
 * (rgb NULL) gets it from the same read. */
static int exr_load(const char *path, float *rgb, uint64_t max_pixels, uint32_t *width, uint32_t *height)
{
    vxl_err e = {0};
    float *px = NULL;
    uint32_t w = 0, h = 0;
    int rc = vxl_environment_exr_load(path, MAX_PIXELS, &px, &w, &h, &e);
    if (!rc && rgb && (uint64_t)w * h > max_pixels)
        rc = vxl_fail(&e, VXL_ERR_LIMIT, "%s: %ux%u pixels, more than the %llu given room for", path, w, h,
                      (unsigned long long)max_pixels);
    if (!rc && rgb) memcpy(rgb, px, (size_t)w * h * 3 * sizeof(float));
    free(px);
    if (rc) return vxl_fail(NULL, rc, "%s", e.msg);
    *width = w;
    *height = h;
    return VXL_OK;
}

VXL_API int vxl_environment_image_load(const char *path, float *rgb, uint64_t max_pixels, uint32_t *width,
                                       uint32_t *height)
{
    vxl_err e = {0};
    if (!path || !*path || !width || !height)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "path, width or height is missing");
    *width = *height = 0;
    if (has_ext(path, ".exr")) return exr_load(path, rgb, max_pixels, width, height);
    uint8_t *data = NULL;
    size_t size = 0;
    int rc = read_whole(path, &data, &size, &e);
    if (rc) return rc;
    uint32_t w = 0, h = 0;
    rc = vxl_hdr_decode(data, size, MAX_PIXELS, NULL, &w, &h, &e);
    if (!rc && rgb && (uint64_t)w * h > max_pixels)
        rc = vxl_fail(&e, VXL_ERR_LIMIT, "%ux%u pixels, more than the %llu given room for", w, h,
                      (unsigned long long)max_pixels);
    if (!rc && rgb) rc = vxl_hdr_decode(data, size, max_pixels, rgb, &w, &h, &e);
    free(data);
    if (rc) return vxl_fail(NULL, rc, "%s: %s", path, e.msg);
    *width = w;
    *height = h;
    return VXL_OK;
}
