/* context.c - backend selection. */
#include "context.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "voxlight.h"

static uint32_t backend_from_env(uint32_t requested)
{
    if (requested != VXL_BACKEND_AUTO) return requested;
    const char *env = getenv("VOXLIGHT_BACKEND");
    if (!env || !*env || !strcasecmp(env, "auto")) return VXL_BACKEND_AUTO;
    if (!strcasecmp(env, "osmesa")) return VXL_BACKEND_OSMESA;
    if (!strcasecmp(env, "egl")) return VXL_BACKEND_EGL;
    return 0xFFFFFFFFu;
}

int vxl_context_open(vxl_context *c, uint32_t backend, vxl_err *e)
{
    memset(c, 0, sizeof *c);
    uint32_t b = backend_from_env(backend);
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
                        "unknown backend (VOXLIGHT_BACKEND must be auto, osmesa or egl)");
    }
}

int vxl_context_screen_kind(const char *backend_name, const char *gl_renderer)
{
    if (!backend_name || !gl_renderer || !strstr(gl_renderer, "llvmpipe")) return 0;
    if (!strcmp(backend_name, "osmesa")) return 1;
    if (!strcmp(backend_name, "egl-surfaceless")) return 2;
    if (!strcmp(backend_name, "egl-device")) return 3; /* Mesa's software device, when it lists one */
    return 4; /* an unknown llvmpipe backend: one lock of its own, never none */
}

vxl_mutex *vxl_context_screen_lock(int kind)
{
    /* One mutex per llvmpipe screen a process can have through us: the
     * screens are process-wide inside Mesa, so their locks are too. They
     * hold no data and need no set-up. */
    static vxl_mutex locks[4] = {VXL_MUTEX_INIT, VXL_MUTEX_INIT,
                                       VXL_MUTEX_INIT, VXL_MUTEX_INIT};
    return kind >= 1 && kind <= 4 ? &locks[kind - 1] : NULL;
}

void vxl_context_close(vxl_context *c)
{
    if (c && c->close) c->close(c);
    if (c) memset(c, 0, sizeof *c);
}
