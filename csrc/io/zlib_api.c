/* zlib_api.c - zlib_api.h: the system's zlib opened once per process.
 *
 * The table is process-wide and written exactly once (vxl_once_run), then
 * only read: zlib's functions are the same for every caller, and a table
 * per volume or renderer would have to be threaded through every reader
 * that may meet a compressed file. The library handle is kept for the
 * process' life: a table's functions may be running on another thread. */
#include <stdio.h>
#include <stdlib.h>

#include "dynlib.h"
#include "os.h"
#include "threads.h"
#include "zlib_api.h"

/* In the order of vxl_zlib's members. */
static const char *const names[] = {"zlibVersion", "inflateInit2_", "inflate",   "inflateReset", "inflateEnd",
                                    "uncompress",  "deflateInit_",  "deflate",   "deflateEnd",   "compress2",
                                    "compressBound"};

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
    vxl_dynlib *lib = vxl_dynlib_open_table("VOXLIGHT_LIBZ", vxl_os_zlib_name(), names, sizeof names / sizeof names[0],
                                            (vxl_dynlib_fn *)&state.api, state.why, sizeof state.why);
    if (!lib) return;
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
    vxl_fail(e, VXL_ERR_IO, "compressed data needs zlib (%s), which cannot be loaded: %s", vxl_os_zlib_name(),
             state.why);
    return NULL;
}
