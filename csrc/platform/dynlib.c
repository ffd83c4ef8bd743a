/* dynlib.c - what dynlib.h does the same on every OS. */
#include <stdio.h>
#include <stdlib.h>

#include "dynlib.h"

int vxl_dynlib_symbols(vxl_dynlib *lib, const char *const *names, size_t count, vxl_dynlib_fn *table, char *why,
                       size_t why_size)
{
    for (size_t i = 0; i < count; i++) {
        table[i] = vxl_dynlib_symbol(lib, names[i]);
        if (!table[i]) {
            if (why_size) snprintf(why, why_size, "it lacks %s", names[i]);
            return -1;
        }
    }
    return 0;
}

vxl_dynlib *vxl_dynlib_open_table(const char *env, const char *name, const char *const *names, size_t count,
                                  vxl_dynlib_fn *table, char *why, size_t why_size)
{
    const char *so = env ? getenv(env) : NULL;
    if (!so || !*so) so = name;
    vxl_dynlib *lib = vxl_dynlib_open(so, why, why_size);
    if (lib && vxl_dynlib_symbols(lib, names, count, table, why, why_size)) {
        vxl_dynlib_close(lib);
        return NULL;
    }
    return lib;
}
