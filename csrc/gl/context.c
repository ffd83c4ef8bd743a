/* context.c - the backend asked for (the environment may override AUTO);
 * which backends each OS has is backends_posix.c's or backends_win32.c's. */
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
    if (!strcasecmp(env, "wgl")) return VXL_BACKEND_WGL;
    return 0xFFFFFFFFu;
}

int vxl_context_open(vxl_context *c, uint32_t backend, vxl_err *e)
{
    memset(c, 0, sizeof *c);
    return vxl_context_open_backend(c, backend_from_env(backend), e);
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
