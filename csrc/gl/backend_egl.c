/* backend_egl.c - EGL with no surface: EGL_EXT_platform_device on a GPU, or
 * EGL_MESA_platform_surfaceless on Mesa. Loaded with dlopen; every EGL entry
 * point comes from libEGL's own eglGetProcAddress/dlsym. */
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <string.h>

#include "context.h"
#include "voxlight.h"

typedef struct egl_api {
    PFNEGLGETPROCADDRESSPROC GetProcAddress;
    PFNEGLQUERYSTRINGPROC QueryString;
    PFNEGLINITIALIZEPROC Initialize;
    PFNEGLBINDAPIPROC BindAPI;
    PFNEGLCHOOSECONFIGPROC ChooseConfig;
    PFNEGLCREATECONTEXTPROC CreateContext;
    PFNEGLDESTROYCONTEXTPROC DestroyContext;
    PFNEGLMAKECURRENTPROC MakeCurrent;
    PFNEGLRELEASETHREADPROC ReleaseThread;
    PFNEGLQUERYDEVICESEXTPROC QueryDevicesEXT;
    PFNEGLQUERYDEVICESTRINGEXTPROC QueryDeviceStringEXT;
    PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT;
} egl_api;

static int load_api(vxl_dynlib *lib, egl_api *a)
{
    memset(a, 0, sizeof *a);
    a->GetProcAddress = (PFNEGLGETPROCADDRESSPROC)vxl_dynlib_symbol(lib, "eglGetProcAddress");
    if (!a->GetProcAddress) return 0;
#define EGL_GET(name) a->name = (__typeof__(a->name))a->GetProcAddress("egl" #name)
    EGL_GET(QueryString); EGL_GET(Initialize); EGL_GET(BindAPI); EGL_GET(ChooseConfig);
    EGL_GET(CreateContext); EGL_GET(DestroyContext); EGL_GET(MakeCurrent); EGL_GET(ReleaseThread);
    EGL_GET(QueryDevicesEXT); EGL_GET(QueryDeviceStringEXT); EGL_GET(GetPlatformDisplayEXT);
#undef EGL_GET
    return a->QueryString && a->Initialize && a->BindAPI && a->ChooseConfig && a->CreateContext &&
           a->MakeCurrent && a->GetPlatformDisplayEXT;
}

static int has_ext(const char *list, const char *ext)
{
    size_t n = strlen(ext);
    for (const char *p = list; p && (p = strstr(p, ext)); p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return 1;
    return 0;
}

/* Creates a 4.5 core context on dpy and makes it current without a surface. */
static int make_context(const egl_api *a, EGLDisplay dpy, EGLContext *out)
{
    EGLint major, minor;
    if (!a->Initialize(dpy, &major, &minor)) return 0;
    const char *ext = a->QueryString(dpy, EGL_EXTENSIONS);
    if (!has_ext(ext, "EGL_KHR_surfaceless_context")) return 0;
    if (!a->BindAPI(EGL_OPENGL_API)) return 0;
    EGLConfig cfg = (EGLConfig)0;
    EGLint n = 0;
    const EGLint cattr[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    if (!a->ChooseConfig(dpy, cattr, &cfg, 1, &n) || n < 1) {
        if (!has_ext(ext, "EGL_KHR_no_config_context")) return 0;
        cfg = (EGLConfig)0; /* EGL_NO_CONFIG_KHR */
    }
    const EGLint attr[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                           EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = a->CreateContext(dpy, cfg, EGL_NO_CONTEXT, attr);
    if (ctx == EGL_NO_CONTEXT) return 0;
    if (!a->MakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        a->DestroyContext(dpy, ctx);
        return 0;
    }
    *out = ctx;
    return 1;
}

/* The first non-software device that gives a context. */
static int open_gpu_device(const egl_api *a, EGLDisplay *dpy, EGLContext *ctx)
{
    if (!a->QueryDevicesEXT || !a->QueryDeviceStringEXT) return 0;
    EGLDeviceEXT devs[16];
    EGLint n = 0;
    if (!a->QueryDevicesEXT(16, devs, &n)) return 0;
    for (EGLint i = 0; i < n; i++) {
        const char *dext = a->QueryDeviceStringEXT(devs[i], EGL_EXTENSIONS);
        if (has_ext(dext, "EGL_MESA_device_software")) continue;
        EGLDisplay d = a->GetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devs[i], NULL);
        if (d != EGL_NO_DISPLAY && make_context(a, d, ctx)) {
            *dpy = d;
            return 1;
        }
    }
    return 0;
}

static vxl_ctx_proc egl_get_proc(vxl_context *c, const char *name)
{
    PFNEGLGETPROCADDRESSPROC gp = (PFNEGLGETPROCADDRESSPROC)vxl_dynlib_symbol(c->lib, "eglGetProcAddress");
    return gp ? (vxl_ctx_proc)gp(name) : NULL;
}

static void egl_close(vxl_context *c)
{
    egl_api a;
    if (!load_api(c->lib, &a) || !c->handle_b) return;
    a.MakeCurrent(c->handle_a, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    a.DestroyContext(c->handle_a, c->handle_b);
    if (a.ReleaseThread) a.ReleaseThread();
    /* No eglTerminate: EGL displays are shared process-wide and not
     * reference counted, so terminating would kill other renderers' contexts. */
}

int vxl_egl_open(vxl_context *c, int egl_mode, vxl_err *e)
{
    c->lib = vxl_dynlib_open("libEGL.so.1", NULL, 0);
    if (!c->lib) return vxl_fail(e, VXL_ERR_BACKEND, "egl: cannot load libEGL.so.1");
    egl_api a;
    if (!load_api(c->lib, &a))
        return vxl_fail(e, VXL_ERR_BACKEND, "egl: libEGL lacks eglGetPlatformDisplayEXT");
    const char *client = a.QueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    EGLDisplay dpy = EGL_NO_DISPLAY;
    EGLContext ctx = EGL_NO_CONTEXT;
    int ok = 0;
    if (egl_mode != 1 && has_ext(client, "EGL_EXT_platform_device") && open_gpu_device(&a, &dpy, &ctx)) {
        ok = 1;
        strcpy(c->name, "egl-device");
    }
    if (!ok && egl_mode != 0 && has_ext(client, "EGL_MESA_platform_surfaceless")) {
        dpy = a.GetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
        if (dpy != EGL_NO_DISPLAY && make_context(&a, dpy, &ctx)) {
            ok = 1;
            strcpy(c->name, "egl-surfaceless");
        }
    }
    if (!ok)
        return vxl_fail(e, VXL_ERR_BACKEND, "egl: no %s display gave an OpenGL 4.5 core context",
                        egl_mode == 0 ? "GPU device" : egl_mode == 1 ? "Mesa surfaceless" : "GPU or surfaceless");
    c->handle_a = dpy;
    c->handle_b = ctx;
    c->get_proc = egl_get_proc;
    c->close = egl_close;
    c->backend = VXL_BACKEND_EGL;
    return VXL_OK;
}
