/* gl_funcs.c - loads the GL entry point table through a backend's loader. */
#include "gl_funcs.h"

#include <string.h>

const char *vxl_gl_load(vxl_gl *gl, vxl_get_proc_fn get, void *user)
{
    memset(gl, 0, sizeof *gl);
    /* ISO C forbids converting between function pointer types via void*,
     * but function-pointer to function-pointer casts are fine. */
#define VXL_GL_LOAD(type, name)                          \
    gl->name = (type)get(user, "gl" #name);              \
    if (!gl->name) return "gl" #name;
    VXL_GL_FUNC_LIST(VXL_GL_LOAD)
#undef VXL_GL_LOAD
    return NULL;
}
