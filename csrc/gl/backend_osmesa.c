/* backend_osmesa.c - Mesa's OSMesa (llvmpipe), loaded with dlopen so that the
 * library works where OSMesa is absent and never drags a GL into the host. */
#include <GL/glcorearb.h>
#include <string.h>

#include "context.h"
#include "voxlight.h"

/* The few declarations of Mesa's GL/osmesa.h this file uses, written out so
 * that the build needs no OSMesa headers: Mesa 25.1 removed OSMesa and
 * releases built on it (Debian 13 may be one) ship no libosmesa6-dev. The
 * values are OSMesa's stable ABI (osmesa.h, unchanged since Mesa 11.2). */
typedef struct osmesa_context *OSMesaContext;
typedef void (*OSMESAproc)(void);
#define OSMESA_RGBA GL_RGBA
#define OSMESA_FORMAT 0x22
#define OSMESA_DEPTH_BITS 0x30
#define OSMESA_STENCIL_BITS 0x31
#define OSMESA_ACCUM_BITS 0x32
#define OSMESA_PROFILE 0x33
#define OSMESA_CORE_PROFILE 0x34
#define OSMESA_CONTEXT_MAJOR_VERSION 0x36
#define OSMESA_CONTEXT_MINOR_VERSION 0x37

typedef OSMesaContext (*create_fn)(const int *, OSMesaContext);
typedef GLboolean (*make_current_fn)(OSMesaContext, void *, GLenum, GLsizei, GLsizei);
typedef void (*destroy_fn)(OSMesaContext);
typedef OSMESAproc (*get_proc_fn)(const char *);

static vxl_ctx_proc osmesa_get_proc(vxl_context *c, const char *name)
{
    get_proc_fn gp = (get_proc_fn)vxl_dynlib_symbol(c->lib, "OSMesaGetProcAddress");
    return gp ? (vxl_ctx_proc)gp(name) : NULL;
}

static void osmesa_close(vxl_context *c)
{
    if (c->handle_a) {
        make_current_fn mc = (make_current_fn)vxl_dynlib_symbol(c->lib, "OSMesaMakeCurrent");
        destroy_fn d = (destroy_fn)vxl_dynlib_symbol(c->lib, "OSMesaDestroyContext");
        if (mc) mc(NULL, NULL, 0, 0, 0);
        if (d) d((OSMesaContext)c->handle_a);
    }
    /* The library stays loaded: llvmpipe keeps threads and atexit handlers,
     * and unloading it under a live process is not safe. */
}

int vxl_osmesa_open(vxl_context *c, vxl_err *e)
{
    c->lib = vxl_dynlib_open("libOSMesa.so.8", NULL, 0);
    if (!c->lib) c->lib = vxl_dynlib_open("libOSMesa.so", NULL, 0);
    if (!c->lib) return vxl_fail(e, VXL_ERR_BACKEND, "osmesa: cannot load libOSMesa.so.8 (install libosmesa6)");
    create_fn create = (create_fn)vxl_dynlib_symbol(c->lib, "OSMesaCreateContextAttribs");
    make_current_fn mc = (make_current_fn)vxl_dynlib_symbol(c->lib, "OSMesaMakeCurrent");
    if (!create || !mc) return vxl_fail(e, VXL_ERR_BACKEND, "osmesa: libOSMesa lacks OSMesaCreateContextAttribs");
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                           OSMESA_ACCUM_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 4, OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
    OSMesaContext ctx = create(attribs, NULL);
    if (!ctx) return vxl_fail(e, VXL_ERR_BACKEND, "osmesa: cannot create an OpenGL 4.5 core context");
    c->handle_a = ctx;
    c->get_proc = osmesa_get_proc;
    c->close = osmesa_close;
    c->backend = VXL_BACKEND_OSMESA;
    strcpy(c->name, "osmesa");
    if (!mc(ctx, c->osmesa_pixels, GL_UNSIGNED_BYTE, 2, 2)) {
        osmesa_close(c);
        return vxl_fail(e, VXL_ERR_BACKEND, "osmesa: OSMesaMakeCurrent failed");
    }
    return VXL_OK;
}
