/* helper_self.h - what a reader helper process (csrc/io/helper_main.c)
 * does to itself before it reads: close what the host left open, take its
 * standard output for the reply stream, cap its own memory, and write the
 * reply. One implementation per OS (helper_self_posix.c,
 * helper_self_win32.c). Helpers only: nothing here is in the library. */
#ifndef VXL_HELPER_SELF_H
#define VXL_HELPER_SELF_H

#include <stddef.h>
#include <stdint.h>

/* Closes every descriptor above 0, 1 and 2 that the host let the helper
 * inherit (POSIX; on Windows only the handles the library passes are
 * inherited, so nothing is left to close). */
void vxl_self_close_inherited(void);

/* A descriptor for the reply stream, in binary mode, which was standard
 * output; standard output then goes to standard error, so whatever the
 * libraries print cannot land in the voxels. -1 with errno on failure. */
int vxl_self_take_stdout(void);

/* Up to n bytes to fd: how many were written, or -1 with errno (EINTR:
 * nothing yet, try again). */
int64_t vxl_self_write(int fd, const void *buf, size_t n);

/* Best effort: allocations past bytes in all fail from now on (POSIX:
 * RLIMIT_AS; Windows: a job's process memory limit). */
void vxl_self_cap_memory(uint64_t bytes);

#endif
