/* error.c - error recording. The thread-local buffer is the only state that
 * outlives a call, and it is per thread, so the library has no global mutable
 * state shared between callers. */
#include "error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "voxlight.h"

static _Thread_local char tls_last_error[VXL_MSG_MAX];

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
    memcpy(tls_last_error, buf, sizeof buf);
    return code;
}

void vxl_publish_error(const vxl_err *e)
{
    if (e && e->code != VXL_OK) memcpy(tls_last_error, e->msg, sizeof tls_last_error);
}

void vxl_clear_error(vxl_err *e)
{
    if (e) {
        e->code = VXL_OK;
        e->msg[0] = '\0';
    }
}

const char *vxl_last_error(void) { return tls_last_error; }

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
    default: return "unknown error";
    }
}

uint32_t vxl_abi_version(void) { return VXL_ABI_VERSION; }
