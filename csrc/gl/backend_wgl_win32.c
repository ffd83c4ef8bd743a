/* backend_wgl_win32.c - WGL on Windows: a message-only window (it receives
 * no broadcasts, so a renderer thread that pumps no messages never holds
 * up the system), a legacy context only to find wglCreateContextAttribsARB,
 * then an OpenGL 4.5 core context, made current on the renderer's GL
 * thread. opengl32.dll is opened at run time (platform/dynlib.h), as the
 * other backends open theirs; functions of OpenGL 1.1 come from it, newer
 * ones from wglGetProcAddress. */
#include <string.h>
#include <windows.h>

#include "context.h"
#include "voxlight.h"

#define WGL_CONTEXT_MAJOR_VERSION_ARB 0x2091
#define WGL_CONTEXT_MINOR_VERSION_ARB 0x2092
#define WGL_CONTEXT_PROFILE_MASK_ARB 0x9126
#define WGL_CONTEXT_CORE_PROFILE_BIT_ARB 0x00000001

typedef HGLRC(WINAPI *create_fn)(HDC);
typedef BOOL(WINAPI *make_current_fn)(HDC, HGLRC);
typedef BOOL(WINAPI *delete_fn)(HGLRC);
typedef PROC(WINAPI *get_proc_fn)(LPCSTR);
typedef HGLRC(WINAPI *create_attribs_fn)(HDC, HGLRC, const int *);

typedef struct wgl_api {
    create_fn CreateContext;
    make_current_fn MakeCurrent;
    delete_fn DeleteContext;
    get_proc_fn GetProcAddress;
} wgl_api;

static const char *const wgl_names[] = {"wglCreateContext", "wglMakeCurrent", "wglDeleteContext",
                                        "wglGetProcAddress"};
static const wchar_t window_class[] = L"VoxlightGL";

static int load_api(vxl_dynlib *lib, wgl_api *a)
{
    _Static_assert(sizeof(wgl_api) == sizeof wgl_names / sizeof wgl_names[0] * sizeof(vxl_dynlib_fn), "one each");
    return vxl_dynlib_symbols(lib, wgl_names, sizeof wgl_names / sizeof wgl_names[0], (vxl_dynlib_fn *)a, NULL, 0) == 0;
}

static vxl_ctx_proc wgl_get_proc(vxl_context *c, const char *name)
{
    wgl_api a;
    if (!load_api(c->lib, &a)) return NULL;
    PROC p = a.GetProcAddress(name);
    const intptr_t v = (intptr_t)p;
    if (v == 0 || v == 1 || v == 2 || v == 3 || v == -1) /* 1.1 functions, and what some drivers return instead */
        return vxl_dynlib_symbol(c->lib, name);
    vxl_ctx_proc f;
    memcpy(&f, &p, sizeof f);
    return f;
}

static void wgl_close(vxl_context *c)
{
    wgl_api a;
    HDC dc = c->handle_b;
    HWND w = dc ? WindowFromDC(dc) : NULL;
    if (load_api(c->lib, &a) && c->handle_a) {
        a.MakeCurrent(NULL, NULL);
        a.DeleteContext((HGLRC)c->handle_a);
    }
    if (dc) ReleaseDC(w, dc);
    if (w) DestroyWindow(w);
    /* opengl32.dll stays loaded: its driver keeps threads, as llvmpipe does */
}

int vxl_wgl_open(vxl_context *c, vxl_err *e)
{
    char why[256];
    c->lib = vxl_dynlib_open("opengl32.dll", why, sizeof why);
    if (!c->lib) return vxl_fail(e, VXL_ERR_BACKEND, "wgl: %s", why);
    wgl_api a;
    if (!load_api(c->lib, &a)) return vxl_fail(e, VXL_ERR_BACKEND, "wgl: opengl32.dll lacks the wgl functions");
    HINSTANCE inst = GetModuleHandleW(NULL);
    WNDCLASSW wc;
    memset(&wc, 0, sizeof wc);
    wc.style = CS_OWNDC;
    wc.lpfnWndProc = DefWindowProcW;
    wc.hInstance = inst;
    wc.lpszClassName = window_class;
    if (!RegisterClassW(&wc) && GetLastError() != ERROR_CLASS_ALREADY_EXISTS)
        return vxl_fail(e, VXL_ERR_BACKEND, "wgl: cannot register a window class (error %lu)", GetLastError());
    HWND w = CreateWindowExW(0, window_class, L"Voxlight", 0, 0, 0, 16, 16, HWND_MESSAGE, NULL, inst, NULL);
    if (!w) return vxl_fail(e, VXL_ERR_BACKEND, "wgl: cannot create a window (error %lu)", GetLastError());
    HDC dc = GetDC(w);
    PIXELFORMATDESCRIPTOR pfd;
    memset(&pfd, 0, sizeof pfd);
    pfd.nSize = sizeof pfd;
    pfd.nVersion = 1;
    pfd.dwFlags = PFD_DRAW_TO_WINDOW | PFD_SUPPORT_OPENGL;
    pfd.iPixelType = PFD_TYPE_RGBA;
    pfd.cColorBits = 32;
    const int pf = dc ? ChoosePixelFormat(dc, &pfd) : 0;
    if (!pf || !SetPixelFormat(dc, pf, &pfd)) {
        if (dc) ReleaseDC(w, dc);
        DestroyWindow(w);
        return vxl_fail(e, VXL_ERR_BACKEND, "wgl: no OpenGL pixel format (error %lu)", GetLastError());
    }
    c->handle_b = dc;
    c->get_proc = wgl_get_proc;
    c->close = wgl_close;
    c->backend = VXL_BACKEND_WGL;
    strcpy(c->name, "wgl");
    HGLRC legacy = a.CreateContext(dc);
    create_attribs_fn create = NULL;
    if (legacy && a.MakeCurrent(dc, legacy)) {
        PROC p = a.GetProcAddress("wglCreateContextAttribsARB");
        memcpy(&create, &p, sizeof create);
    }
    static const int attribs[] = {WGL_CONTEXT_MAJOR_VERSION_ARB, 4, WGL_CONTEXT_MINOR_VERSION_ARB, 5,
                                  WGL_CONTEXT_PROFILE_MASK_ARB, WGL_CONTEXT_CORE_PROFILE_BIT_ARB, 0};
    HGLRC ctx = create ? create(dc, NULL, attribs) : NULL;
    if (legacy) {
        a.MakeCurrent(NULL, NULL);
        a.DeleteContext(legacy);
    }
    if (!ctx || !a.MakeCurrent(dc, ctx)) {
        if (ctx) a.DeleteContext(ctx);
        wgl_close(c);
        return vxl_fail(e, VXL_ERR_BACKEND, "wgl: the driver gives no OpenGL 4.5 core context");
    }
    c->handle_a = ctx;
    return VXL_OK;
}
