/* context.h - an offscreen OpenGL 4.5 core context from a backend opened
 * at run time (OSMesa or surfaceless EGL, platform/dynlib.h). All calls here must
 * happen on the renderer's GL thread. */
#ifndef VXL_CONTEXT_H
#define VXL_CONTEXT_H

#include "threads.h"
#include <stdint.h>

#include "dynlib.h"
#include "error.h"

typedef void (*vxl_ctx_proc)(void);

typedef struct vxl_context {
    uint32_t backend;          /* VXL_BACKEND_OSMESA or VXL_BACKEND_EGL */
    char name[32];             /* "osmesa", "egl-device", "egl-surfaceless" */
    vxl_dynlib *lib;           /* the backend's library, kept loaded */
    vxl_ctx_proc (*get_proc)(struct vxl_context *c, const char *name);
    void (*close)(struct vxl_context *c);
    /* backend-private */
    void *handle_a, *handle_b; /* osmesa: context; egl: display, context */
    unsigned char osmesa_pixels[16]; /* OSMesa needs a colour buffer; we render to FBOs */
} vxl_context;

/* Opens and makes current the requested backend (VXL_BACKEND_AUTO tries EGL on
 * a GPU, then OSMesa, then EGL on Mesa). The environment variable
 * VOXLIGHT_BACKEND (auto|osmesa|egl) overrides AUTO only. */
int vxl_context_open(vxl_context *c, uint32_t backend, vxl_err *e);
void vxl_context_close(vxl_context *c);

/* Mesa's llvmpipe (22.3, Debian 12) has every context of one screen look
 * into the others' queued scenes without their owners' synchronisation:
 * mapping a buffer or texture (glBufferData, glTexSubImage3D, glReadPixels...)
 * walks the resource lists of every context's scenes, while each context's
 * own thread frees and refills them. Two renderers rendering at once then
 * read freed memory and crash in lp_scene_is_resource_referenced
 * (tests/upstream/llvmpipe_shared_screen_race.c reproduces it without
 * Voxlight). All OSMesa contexts of a process share one screen, and so do all
 * surfaceless EGL contexts (one EGLDisplay), so each backend's llvmpipe
 * contexts take turns: the lock returned here is held around every job of a
 * renderer's GL thread. The lock is process-wide because the screen it
 * guards is. Which screen kind a context is on: 0 none (a GPU driver: no
 * lock), else a small number naming the shared lock. */
int vxl_context_screen_kind(const char *backend_name, const char *gl_renderer);
/* The lock for that kind, NULL for 0. */
vxl_mutex *vxl_context_screen_lock(int kind);

/* Backend entry points, in backend_osmesa.c and backend_egl.c. egl_mode: 0
 * hardware device only, 1 Mesa surfaceless only, 2 device then surfaceless. */
/* Opens backend b (not AUTO's environment override: context.c applies it)
 * from this OS's list (backends_posix.c, backends_win32.c). */
int vxl_context_open_backend(vxl_context *c, uint32_t b, vxl_err *e);

int vxl_osmesa_open(vxl_context *c, vxl_err *e);
int vxl_egl_open(vxl_context *c, int egl_mode, vxl_err *e);
int vxl_wgl_open(vxl_context *c, vxl_err *e);

#endif
