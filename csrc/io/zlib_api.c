/* zlib_api.c - zlib_api.h: libz.so.1 opened once per process.
 *
 * The table is process-wide and written exactly once (vxl_once_run), then
 * only read: zlib's functions are the same for every caller, and a table
 * per volume or renderer would have to be threaded through every reader
 * that may meet a compressed file. The library handle is kept for the
 * process' life: a table's functions may be running on another thread. */
#include <errno.h>
#include "threads.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dynlib.h"
#include "zlib_api.h"

/* In the order of vxl_zlib's members. */
static const char *const names[] = {"zlibVersion", "inflateInit2_", "inflate",   "inflateReset", "inflateEnd",
                                    "uncompress",  "deflateInit_",  "deflate",   "deflateEnd",   "compress2",
                                    "compressBound", "gzopen",      "gzbuffer",  "gzread",       "gzseek",
                                    "gzdirect",    "gzerror",       "gzclose"};

typedef struct zlib_state {
    vxl_zlib api;
    int ok;
    char why[256];
} zlib_state;

static zlib_state state;
static vxl_once once = VXL_ONCE_INIT;

static void load(void)
{
    _Static_assert(sizeof(vxl_zlib) == sizeof names / sizeof names[0] * sizeof(vxl_dynlib_fn), "one pointer per name");
    const char *so = getenv("VOXLIGHT_LIBZ");
    if (!so || !*so) so = VXL_ZLIB_SO;
    vxl_dynlib *lib = vxl_dynlib_open(so, state.why, sizeof state.why);
    if (!lib) return;
    if (vxl_dynlib_symbols(lib, names, sizeof names / sizeof names[0], (vxl_dynlib_fn *)&state.api, state.why,
                           sizeof state.why)) {
        vxl_dynlib_close(lib);
        return;
    }
    /* The major version must match the header the table's types come from. */
    if (state.api.zlibVersion()[0] != ZLIB_VERSION[0]) {
        snprintf(state.why, sizeof state.why, "it is zlib %s, not %c.x", state.api.zlibVersion(), ZLIB_VERSION[0]);
        vxl_dynlib_close(lib);
        return;
    }
    state.ok = 1;
}

const vxl_zlib *vxl_zlib_api(vxl_err *e)
{
    vxl_once_run(&once, load);
    if (state.ok) return &state.api;
    vxl_fail(e, VXL_ERR_IO, "compressed data needs zlib (%s), which cannot be loaded: %s", VXL_ZLIB_SO, state.why);
    return NULL;
}

struct vxl_gz {
    const vxl_zlib *z;
    gzFile f;
};

vxl_gz *vxl_gz_open(const char *path, unsigned buffer_bytes, vxl_err *e)
{
    const vxl_zlib *z = vxl_zlib_api(e);
    if (!z) return NULL;
    vxl_gz *g = calloc(1, sizeof *g);
    if (!g) {
        vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory opening '%s'", path);
        return NULL;
    }
    errno = 0;
    g->z = z;
    g->f = z->gzopen(path, "rb");
    if (!g->f) {
        vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", path, errno ? strerror(errno) : "out of memory");
        free(g);
        return NULL;
    }
    if (buffer_bytes) z->gzbuffer(g->f, buffer_bytes);
    return g;
}

int vxl_gz_read(vxl_gz *f, void *buf, unsigned n) { return f->z->gzread(f->f, buf, n); }
const char *vxl_gz_error(vxl_gz *f, int *zerr) { return f->z->gzerror(f->f, zerr); }
z_off_t vxl_gz_seek(vxl_gz *f, z_off_t offset, int whence) { return f->z->gzseek(f->f, offset, whence); }
int vxl_gz_direct(vxl_gz *f) { return f->z->gzdirect(f->f); }

void vxl_gz_close(vxl_gz *f)
{
    if (!f) return;
    f->z->gzclose(f->f);
    free(f);
}
