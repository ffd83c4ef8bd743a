/* helper_self_win32.c - helper_self.h on Windows. */
#include <fcntl.h>
#include <io.h>
#include <windows.h>

#include "helper_self.h"

/* process_win32.c passes the child only its three standard handles
 * (PROC_THREAD_ATTRIBUTE_HANDLE_LIST): nothing else was inherited. */
void vxl_self_close_inherited(void) {}

int vxl_self_take_stdout(void)
{
    int out = _dup(1);
    if (out < 0) return -1;
    /* the voxels are bytes: no newline translation */
    if (_setmode(out, _O_BINARY) < 0 || _dup2(2, 1) < 0) {
        _close(out);
        return -1;
    }
    return out;
}

int64_t vxl_self_write(int fd, const void *buf, size_t n)
{
    return _write(fd, buf, n > (1u << 30) ? (1u << 30) : (unsigned)n); /* _write counts in an unsigned */
}

/* The process joins a job of its own whose memory limit fails allocations
 * past bytes; the job handle is left open for the process' life (closing it
 * would end the limit). */
void vxl_self_cap_memory(uint64_t bytes)
{
    HANDLE job = CreateJobObjectW(NULL, NULL);
    if (!job) return;
    JOBOBJECT_EXTENDED_LIMIT_INFORMATION lim;
    ZeroMemory(&lim, sizeof lim);
    lim.BasicLimitInformation.LimitFlags = JOB_OBJECT_LIMIT_PROCESS_MEMORY;
    lim.ProcessMemoryLimit = (SIZE_T)bytes;
    if (!SetInformationJobObject(job, JobObjectExtendedLimitInformation, &lim, sizeof lim) ||
        !AssignProcessToJobObject(job, GetCurrentProcess()))
        CloseHandle(job); /* best effort, as on POSIX */
}
