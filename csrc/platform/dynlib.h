/* dynlib.h - opening a shared library at run time and finding its
 * functions: the one seam through which the library reaches code it does
 * not link (zlib, libzstd, libblosc, the GL drivers). One implementation
 * per OS (dynlib_posix.c); nothing else includes <dlfcn.h>. */
#ifndef VXL_DYNLIB_H
#define VXL_DYNLIB_H

#include <stddef.h>

typedef struct vxl_dynlib vxl_dynlib;
typedef void (*vxl_dynlib_fn)(void);

/* Opens `name` (a file name the OS's loader searches for, or a path),
 * keeping its symbols to itself (nothing joins the process' global
 * namespace, so a copy of the same library inside Blender is never
 * bound by mistake). NULL on failure, with the loader's reason in why. */
vxl_dynlib *vxl_dynlib_open(const char *name, char *why, size_t why_size);

/* The function `name` of lib, or NULL. */
vxl_dynlib_fn vxl_dynlib_symbol(vxl_dynlib *lib, const char *name);

/* Looks up count functions into table[i] (names[i]); 0, or -1 with the
 * first missing name in why. */
int vxl_dynlib_symbols(vxl_dynlib *lib, const char *const *names, size_t count, vxl_dynlib_fn *table, char *why,
                       size_t why_size);

/* A library opened for a table of its functions: the file the variable
 * `env` names when it is set (tests point it at a missing library), else
 * `name`; then the count functions names[i] into table[i]. The library, or
 * NULL with why ("it lacks inflate", the loader's reason). */
vxl_dynlib *vxl_dynlib_open_table(const char *env, const char *name, const char *const *names, size_t count,
                                  vxl_dynlib_fn *table, char *why, size_t why_size);

void vxl_dynlib_close(vxl_dynlib *lib);

/* The file of the loaded module (library or program) holding `address`,
 * copied into out; 0, or -1 when the loader cannot tell or it is too long. */
int vxl_dynlib_path_of(const void *address, char *out, size_t size);

#endif
