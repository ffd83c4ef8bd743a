/* backends_win32.c - the OpenGL backend of Windows (context.h): WGL. */
#include "context.h"
#include "voxlight.h"

int vxl_context_open_backend(vxl_context *c, uint32_t b, vxl_err *e)
{
    if (b == VXL_BACKEND_AUTO || b == VXL_BACKEND_WGL) return vxl_wgl_open(c, e);
    /* as on Linux: a backend this system does not have is a bad argument */
    return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "backend %u is not one of Windows' (VOXLIGHT_BACKEND must be auto or wgl)",
                    b);
}
