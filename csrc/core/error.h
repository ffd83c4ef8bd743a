/* error.h - how the library reports failures: a code plus a message, kept
 * per handle and mirrored into a thread-local "last error". Never printed. */
#ifndef VXL_ERROR_H
#define VXL_ERROR_H

#include <stddef.h>

#define VXL_MSG_MAX 512

typedef struct vxl_err {
    int code;
    char msg[VXL_MSG_MAX];
} vxl_err;

/* Records code+message into *e (may be NULL) and into the calling thread's
 * last error. Returns code so callers can `return vxl_fail(...)`. */
int vxl_fail(vxl_err *e, int code, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Copies an error (e.g. from the GL thread) into the caller's thread-local. */
void vxl_publish_error(const vxl_err *e);
void vxl_clear_error(vxl_err *e);

#endif
