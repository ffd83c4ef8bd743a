/* process.h - a child program whose output we read: the library's one seam
 * to the OS's processes and pipes (process_posix.c), used to run the reader
 * helpers. Failures return -1 or NULL with errno set. */
#ifndef VXL_PROCESS_H
#define VXL_PROCESS_H

#include <stddef.h>
#include <stdint.h>

typedef struct vxl_child vxl_child;

enum { VXL_CHILD_OUT = 0, VXL_CHILD_ERR = 1 }; /* its standard output and error */

/* How a child ended. reaped 0: the host reaps children itself (POSIX:
 * SIGCHLD ignored), so nothing is known. */
typedef struct vxl_child_end {
    int reaped;
    int exited, code;     /* ended by itself, with this exit code */
    int signaled, signal; /* ended by a signal (a crash, or killed) */
} vxl_child_end;

/* Starts program with argv (argv[0] first, NULL last): its standard input
 * empty, its output and error each to a pipe of ours, no other descriptor
 * of the host, default signal handling. */
vxl_child *vxl_child_start(const char *program, char *const argv[]);

/* Waits up to timeout_ms for a stream still open to have something to
 * read (or its end): *ready has bit (1 << VXL_CHILD_OUT / ERR) set for
 * each; 0 on a timeout with *ready 0, -1 on failure. */
int vxl_child_wait(vxl_child *c, int timeout_ms, int *ready);

/* Up to n bytes of a stream: the count, 0 at its end (the stream is then
 * closed), or -1 (errno EAGAIN or EINTR: nothing now). */
int64_t vxl_child_read(vxl_child *c, int stream, void *buf, size_t n);

/* Whether a stream has not reached its end. */
int vxl_child_open(const vxl_child *c, int stream);

void vxl_child_kill(vxl_child *c);

/* Waits for the child to end, closes what is left and frees c. */
void vxl_child_finish(vxl_child *c, vxl_child_end *end);

/* Whether path is a program this process may start. */
int vxl_is_program(const char *path);

/* What ends a program's file name on this OS: "" or ".exe". */
const char *vxl_program_suffix(void);

/* The short name ("SEGV") of a signal a child may end by, or NULL. */
const char *vxl_signal_name(int sig);

#endif
