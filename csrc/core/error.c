/* error.c - error recording. The last message is kept per thread, so the
 * library has no global mutable state shared between callers.
 *
 * The per-thread buffer hangs off a thread key (vxl_tls) rather than a _Thread_local
 * array: TLS in a shared object compiles to calls of __tls_get_addr, which
 * lives in the dynamic loader and would make ld-linux a NEEDED entry of the
 * core (the core links only the C runtime). The key is written once
 * (vxl_once_run) and only read after; a thread's buffer is made at its first
 * failure and freed when the thread ends. */
#include "error.h"

#include "threads.h"
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "voxlight.h"

static vxl_once last_error_once = VXL_ONCE_INIT;
static vxl_tls last_error_key;
static int last_error_key_ok;

static void make_last_error_key(void) { last_error_key_ok = vxl_tls_create(&last_error_key, free) == 0; }

/* The library may be unloaded (Blender disabling the add-on) while threads
 * that hold buffers live on: without the key their destructor would call
 * into unmapped code. Those buffers then leak, as vxl_tls_delete says. */
__attribute__((destructor)) static void delete_last_error_key(void)
{
    if (last_error_key_ok) vxl_tls_delete(last_error_key);
}

/* This thread's buffer, made when create is set; NULL when there is none
 * (or no memory: the message is then lost, the error code is not). */
static char *last_error_buffer(int create)
{
    vxl_once_run(&last_error_once, make_last_error_key);
    if (!last_error_key_ok) return NULL;
    char *buf = vxl_tls_get(last_error_key);
    if (!buf && create) {
        buf = calloc(1, VXL_MSG_MAX);
        if (buf && vxl_tls_set(last_error_key, buf)) {
            free(buf);
            buf = NULL;
        }
    }
    return buf;
}

static void set_last_error(const char *msg)
{
    char *buf = last_error_buffer(1);
    if (buf) memcpy(buf, msg, VXL_MSG_MAX);
}

int vxl_fail(vxl_err *e, int code, const char *fmt, ...)
{
    char buf[VXL_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (e) {
        e->code = code;
        memcpy(e->msg, buf, sizeof buf);
    }
    set_last_error(buf);
    return code;
}

void vxl_publish_error(const vxl_err *e)
{
    if (e && e->code != VXL_OK) set_last_error(e->msg);
}

void vxl_clear_error(vxl_err *e)
{
    if (e) {
        e->code = VXL_OK;
        e->msg[0] = '\0';
    }
}

const char *vxl_last_error(void)
{
    const char *buf = last_error_buffer(0);
    return buf ? buf : "";
}

const char *vxl_error_name(int code)
{
    switch (code) {
    case VXL_OK: return "ok";
    case VXL_ERR_INVALID_ARGUMENT: return "invalid argument";
    case VXL_ERR_IO: return "i/o error";
    case VXL_ERR_FORMAT: return "bad file format";
    case VXL_ERR_LIMIT: return "over a limit";
    case VXL_ERR_NO_MEMORY: return "out of memory";
    case VXL_ERR_BACKEND: return "no OpenGL backend";
    case VXL_ERR_GL: return "OpenGL error";
    case VXL_ERR_SHADER: return "shader error";
    case VXL_ERR_STATE: return "wrong state";
    case VXL_ERR_CANCELLED: return "cancelled";
    default: return "unknown error";
    }
}

uint32_t vxl_abi_version(void) { return VXL_ABI_VERSION; }
