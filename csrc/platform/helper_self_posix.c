/* helper_self_posix.c - helper_self.h on POSIX systems. */
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "helper_self.h"

/* The library starts helpers with plain posix_spawn, which on glibc 2.28
 * (the oldest the library supports) has no way to close the host's
 * descriptors itself. Linux's close_range where the kernel has it, else
 * every descriptor up to the limit. */
void vxl_self_close_inherited(void)
{
#ifdef SYS_close_range
    if (syscall(SYS_close_range, 3u, ~0u, 0u) == 0) return;
#endif
    long max = sysconf(_SC_OPEN_MAX);
    if (max < 0 || max > 65536) max = 65536;
    for (int fd = 3; fd < max; fd++) close(fd);
}

int vxl_self_take_stdout(void)
{
    int out = fcntl(1, F_DUPFD_CLOEXEC, 3);
    if (out < 0 || dup2(2, 1) < 0) return -1;
    return out;
}

int64_t vxl_self_write(int fd, const void *buf, size_t n) { return write(fd, buf, n); }

void vxl_self_cap_memory(uint64_t bytes)
{
    struct rlimit lim;
    if (getrlimit(RLIMIT_AS, &lim) == 0 && (lim.rlim_max == RLIM_INFINITY || bytes < lim.rlim_max)) {
        lim.rlim_cur = (rlim_t)bytes;
        setrlimit(RLIMIT_AS, &lim); /* best effort: a failure leaves the process as it was */
    }
}
