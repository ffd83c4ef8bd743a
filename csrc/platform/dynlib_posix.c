/* dynlib_posix.c - dynlib.h on POSIX systems: dlopen with RTLD_LOCAL. */
#include <dlfcn.h>
#include <stdio.h>
#include <string.h>

#include "dynlib.h"

vxl_dynlib *vxl_dynlib_open(const char *name, char *why, size_t why_size)
{
    void *h = dlopen(name, RTLD_NOW | RTLD_LOCAL);
    if (!h && why_size) {
        const char *msg = dlerror();
        snprintf(why, why_size, "%s", msg ? msg : "cannot be loaded");
    }
    return (vxl_dynlib *)h;
}

/* The cast of dlsym's void * to a function pointer is what POSIX
 * guarantees; memcpy keeps ISO C's pedantic warnings quiet. */
vxl_dynlib_fn vxl_dynlib_symbol(vxl_dynlib *lib, const char *name)
{
    void *p = lib ? dlsym((void *)lib, name) : NULL;
    vxl_dynlib_fn f = NULL;
    if (p) memcpy(&f, &p, sizeof f);
    return f;
}

void vxl_dynlib_close(vxl_dynlib *lib)
{
    if (lib) dlclose((void *)lib);
}

int vxl_dynlib_path_of(const void *address, char *out, size_t size)
{
    Dl_info info;
    /* dladdr takes a data pointer; a function's address converts on POSIX */
    if (!dladdr(address, &info) || !info.dli_fname) return -1;
    return snprintf(out, size, "%s", info.dli_fname) < (int)size ? 0 : -1;
}
