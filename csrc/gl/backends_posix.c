/* backends_posix.c - the OpenGL backends of Linux (context.h): EGL on a
 * GPU, OSMesa and Mesa's surfaceless EGL. */
#include <string.h>

#include "context.h"
#include "voxlight.h"

int vxl_context_open_backend(vxl_context *c, uint32_t b, vxl_err *e)
{
    switch (b) {
    case VXL_BACKEND_OSMESA: return vxl_osmesa_open(c, e);
    case VXL_BACKEND_EGL: return vxl_egl_open(c, 2, e);
    case VXL_BACKEND_AUTO: {
        /* A real GPU first; then OSMesa (the tested software path); then
         * Mesa's surfaceless EGL, which outlives OSMesa (removed in Mesa 25.1). */
        char why[3][VXL_MSG_MAX];
        vxl_err sub;
        if (vxl_egl_open(c, 0, &sub) == VXL_OK) return VXL_OK;
        memcpy(why[0], sub.msg, VXL_MSG_MAX);
        memset(c, 0, sizeof *c);
        if (vxl_osmesa_open(c, &sub) == VXL_OK) return VXL_OK;
        memcpy(why[1], sub.msg, VXL_MSG_MAX);
        memset(c, 0, sizeof *c);
        if (vxl_egl_open(c, 1, &sub) == VXL_OK) return VXL_OK;
        memcpy(why[2], sub.msg, VXL_MSG_MAX);
        memset(c, 0, sizeof *c);
        return vxl_fail(e, VXL_ERR_BACKEND, "no OpenGL 4.5 backend: egl gpu: %.150s; osmesa: %.150s; egl mesa: %.150s",
                        why[0], why[1], why[2]);
    }
    default:
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "backend %u is not one of this system's (VOXLIGHT_BACKEND must be auto, osmesa or egl)", b);
    }
}
