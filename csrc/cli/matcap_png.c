/* matcap_png.c - the CLI's PNG reader for --matcap (matcap_png.h). The
 * library reads colour images only through its OpenImageIO helper, which
 * reduces them to grey volumes, and the CLI links no image library: a
 * MatCap is one small RGB picture, decoded here with the system's zlib,
 * opened at run time as the library opens it (os.h names it per OS), so
 * the tool needs no zlib to start. Image rows are stored top first;
 * vxl_matcap wants row 0 = bottom. The texels are the stored values over 255 (65535), as they are:
 * the CLI writes its PNGs the same way (image_write.c, no transfer curve),
 * so a MatCap shades a white surface to the picture's own colours. */
#include "matcap_png.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zlib.h>

#include "dynlib.h"
#include "files.h"
#include "os.h"

#define MAX_SIDE 4096 /* vxl_matcap's limit */

static int fail(char *err, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, n, fmt, ap);
    va_end(ap);
    return 1;
}

static uint32_t be32(const unsigned char *p) { return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]; }

static int paeth(int a, int b, int c)
{
    int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

/* Undoes the PNG row filters in place: raw holds h rows of 1 + stride bytes. */
static int unfilter(unsigned char *raw, uint32_t h, size_t stride, int bpp)
{
    unsigned char *prev = NULL;
    for (uint32_t y = 0; y < h; y++) {
        unsigned char *row = raw + y * (stride + 1), f = row[0], *cur = row + 1;
        if (f > 4) return 1;
        for (size_t x = 0; x < stride; x++) {
            int a = x >= (size_t)bpp ? cur[x - bpp] : 0, b = prev ? prev[x] : 0,
                c = prev && x >= (size_t)bpp ? prev[x - bpp] : 0;
            int add = f == 1 ? a : f == 2 ? b : f == 3 ? (a + b) / 2 : f == 4 ? paeth(a, b, c) : 0;
            cur[x] = (unsigned char)(cur[x] + add);
        }
        prev = cur;
    }
    return 0;
}

int vxl_cli_read_matcap_png(const char *path, float **rgba, uint32_t *w, uint32_t *h, char *err, size_t err_size)
{
    *rgba = NULL;
    FILE *fp = vxl_fopen(path, "rb");
    if (!fp) return fail(err, err_size, "cannot open the MatCap '%s'", path);
    unsigned char *file = NULL, *idat = NULL, *raw = NULL;
    vxl_dynlib *zlib = NULL;
    long size = fseek(fp, 0, SEEK_END) == 0 ? ftell(fp) : -1;
    int rc = 1;
    if (size < 8 || size > (1L << 30) || fseek(fp, 0, SEEK_SET) != 0 || !(file = malloc((size_t)size)) ||
        fread(file, 1, (size_t)size, fp) != (size_t)size) {
        fail(err, err_size, "cannot read the MatCap '%s'", path);
        goto done;
    }
    static const unsigned char sig[8] = {137, 'P', 'N', 'G', 13, 10, 26, 10};
    if (memcmp(file, sig, 8)) {
        fail(err, err_size, "the MatCap '%s' is not a PNG file", path);
        goto done;
    }
    uint32_t depth = 0, colour = 99, interlace = 0;
    size_t n_idat = 0;
    *w = *h = 0;
    for (long pos = 8; pos + 12 <= size;) {
        uint32_t len = be32(file + pos);
        const unsigned char *type = file + pos + 4, *data = file + pos + 8;
        if (len > (uint32_t)(size - pos - 12)) break;
        if (!memcmp(type, "IHDR", 4) && len >= 13) {
            *w = be32(data);
            *h = be32(data + 4);
            depth = data[8];
            colour = data[9];
            interlace = data[12];
        } else if (!memcmp(type, "IDAT", 4)) {
            unsigned char *grown = realloc(idat, n_idat + len);
            if (!grown) {
                fail(err, err_size, "out of memory reading the MatCap '%s'", path);
                goto done;
            }
            idat = grown;
            memcpy(idat + n_idat, data, len);
            n_idat += len;
        }
        pos += 12 + (long)len;
    }
    int channels = colour == 0 ? 1 : colour == 2 ? 3 : colour == 4 ? 2 : colour == 6 ? 4 : 0;
    if (*w < 1 || *h < 1 || *w > MAX_SIDE || *h > MAX_SIDE) {
        fail(err, err_size, "the MatCap '%s' is %ux%u: each side must be 1..%d", path, *w, *h, MAX_SIDE);
        goto done;
    }
    if (!channels || (depth != 8 && depth != 16) || interlace || !n_idat) {
        fail(err, err_size,
             "the MatCap '%s' is an unsupported PNG (colour type %u, %u bits, %s): use 8- or 16-bit grey or RGB(A)",
             path, colour, depth, interlace ? "interlaced" : "not interlaced");
        goto done;
    }
    int bpp = channels * (int)depth / 8;
    size_t stride = (size_t)*w * (size_t)bpp;
    uLongf raw_size = (uLongf)((stride + 1) * *h);
    char why[256] = "";
    zlib = vxl_dynlib_open(vxl_os_zlib_name(), why, sizeof why);
    __typeof__(&uncompress) inflate_all = NULL;
    vxl_dynlib_fn fn = zlib ? vxl_dynlib_symbol(zlib, "uncompress") : NULL;
    if (fn) memcpy(&inflate_all, &fn, sizeof fn);
    if (!inflate_all) {
        fail(err, err_size, "the MatCap '%s' cannot be decoded without zlib: %s", path, zlib ? "it lacks uncompress" : why);
        goto done;
    }
    if (!(raw = malloc(raw_size)) || inflate_all(raw, &raw_size, idat, (uLong)n_idat) != Z_OK ||
        raw_size != (stride + 1) * *h || unfilter(raw, *h, stride, bpp)) {
        fail(err, err_size, "the MatCap '%s' has corrupt image data", path);
        goto done;
    }
    if (!(*rgba = malloc((size_t)*w * *h * 4 * sizeof **rgba))) {
        fail(err, err_size, "out of memory for the MatCap '%s'", path);
        goto done;
    }
    const double top = depth == 8 ? 255.0 : 65535.0;
    for (uint32_t y = 0; y < *h; y++)
        for (uint32_t x = 0; x < *w; x++) {
            const unsigned char *s = raw + (size_t)y * (stride + 1) + 1 + (size_t)x * bpp;
            double c[4];
            for (int k = 0; k < channels; k++) c[k] = (depth == 8 ? s[k] : (s[2 * k] << 8 | s[2 * k + 1])) / top;
            float *d = *rgba + 4 * ((size_t)(*h - 1 - y) * *w + x);
            for (int k = 0; k < 3; k++) d[k] = (float)(channels >= 3 ? c[k] : c[0]);
            d[3] = 1;
        }
    rc = 0;
done:
    fclose(fp);
    free(file);
    free(idat);
    free(raw);
    vxl_dynlib_close(zlib);
    if (rc) {
        free(*rgba);
        *rgba = NULL;
    }
    return rc;
}
