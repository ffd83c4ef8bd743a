/* zarr_codecs.c - libzstd and libblosc opened on demand (zarr.h).
 *
 * libvoxlight.so links only the C runtime (it loads inside Blender), so the
 * two decoders Zarr chunks may need are opened by SONAME with dlopen the
 * first time a chunk compressed with them is met, and their few functions
 * are looked up on that handle (platform/dynlib.h: nothing of theirs joins
 * the process' global namespace, so a lookup binds to that very library,
 * not to another copy Blender may carry). A missing library fails
 * that chunk with a message naming the library, the codec and the Debian
 * package; stores with gzip/zlib or raw chunks never open either library.
 * The function types come from the libraries' own headers (__typeof__), so
 * a signature slip is a compile error, yet nothing of them is linked.
 * VOXLIGHT_ZARR_LIBZSTD / VOXLIGHT_ZARR_LIBBLOSC name other files to open
 * (the tests name a missing one to see the message). */
#include "threads.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dynlib.h"
#include "os.h"
#include "zarr_codecs.h"

struct vxl_zarr_codecs {
    vxl_mutex lock; /* the first use of a library, from any reader thread */
    vxl_dynlib *zstd, *blosc; /* NULL until needed */
    vxl_zstd_api zstd_api;
    vxl_blosc_api blosc_api;
};

vxl_zarr_codecs *vxl_zarr_codecs_new(void)
{
    vxl_zarr_codecs *c = calloc(1, sizeof *c);
    if (c && vxl_mutex_init(&c->lock)) {
        free(c);
        return NULL;
    }
    return c;
}

void vxl_zarr_codecs_free(vxl_zarr_codecs *c)
{
    if (!c) return;
    vxl_dynlib_close(c->zstd);
    vxl_dynlib_close(c->blosc);
    vxl_mutex_destroy(&c->lock);
    free(c);
}

static const char *library(const char *soname, const char *env)
{
    const char *o = getenv(env);
    return o && *o ? o : soname;
}

/* One library: its SONAME, the variable that overrides it, what it
 * decodes, its package, and the functions to look up into its table. */
typedef struct codec_library {
    const char *soname, *env, *codec, *package;
    const char *const *symbols;
    size_t count;
} codec_library;

static const char *const zstd_symbols[] = {"ZSTD_getFrameContentSize", "ZSTD_decompress", "ZSTD_isError",
                                           "ZSTD_getErrorCode", "ZSTD_getErrorName"};
static const char *const blosc_symbols[] = {"blosc_cbuffer_validate", "blosc_cbuffer_sizes", "blosc_decompress_ctx"};
static const codec_library zstd_library = {VXL_ZSTD_SO, "VOXLIGHT_ZARR_LIBZSTD", "zstd", "libzstd1", zstd_symbols,
                                           sizeof zstd_symbols / sizeof zstd_symbols[0]};
static const codec_library blosc_library = {VXL_BLOSC_SO, "VOXLIGHT_ZARR_LIBBLOSC", "blosc", "libblosc1",
                                            blosc_symbols, sizeof blosc_symbols / sizeof blosc_symbols[0]};

/* Opens lib into *handle and fills table (lib->count function pointers, in
 * the order of lib->symbols) on the first call; under c->lock. */
static int open_library(vxl_zarr_codecs *c, const codec_library *lib, vxl_dynlib **handle, vxl_dynlib_fn *table,
                        const char *chunk, vxl_err *e)
{
    vxl_mutex_lock(&c->lock);
    if (*handle) {
        vxl_mutex_unlock(&c->lock);
        return VXL_OK;
    }
    const char *so = library(lib->soname, lib->env);
    char why[256];
    vxl_dynlib *h = vxl_dynlib_open(so, why, sizeof why);
    if (h && vxl_dynlib_symbols(h, lib->symbols, lib->count, table, why, sizeof why)) {
        vxl_dynlib_close(h);
        h = NULL;
    }
    *handle = h;
    vxl_mutex_unlock(&c->lock);
    /* Debian's packages have no Windows build: there the codec is refused by name */
    if (!h && !vxl_os_has_debian_libraries())
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %s-compressed chunks are not read on Windows yet (stores with gzip, "
                        "zlib or no compression are)", chunk, lib->codec);
    if (!h)
        return vxl_fail(e, VXL_ERR_IO, "'%s': a %s-compressed chunk needs %s, which cannot be loaded (%s): apt-get "
                        "install %s", chunk, lib->codec, so, why, lib->package);
    return VXL_OK;
}

int vxl_zarr_zstd(vxl_zarr_codecs *c, const char *chunk, const vxl_zstd_api **api, vxl_err *e)
{
    _Static_assert(sizeof(vxl_zstd_api) == sizeof zstd_symbols / sizeof zstd_symbols[0] * sizeof(vxl_dynlib_fn),
                   "one pointer per symbol");
    int rc = open_library(c, &zstd_library, &c->zstd, (vxl_dynlib_fn *)&c->zstd_api, chunk, e);
    *api = &c->zstd_api;
    return rc;
}

int vxl_zarr_blosc(vxl_zarr_codecs *c, const char *chunk, const vxl_blosc_api **api, vxl_err *e)
{
    _Static_assert(sizeof(vxl_blosc_api) == sizeof blosc_symbols / sizeof blosc_symbols[0] * sizeof(vxl_dynlib_fn),
                   "one pointer per symbol");
    int rc = open_library(c, &blosc_library, &c->blosc, (vxl_dynlib_fn *)&c->blosc_api, chunk, e);
    *api = &c->blosc_api;
    return rc;
}
