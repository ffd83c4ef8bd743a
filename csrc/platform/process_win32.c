/* process_win32.c - process.h on Windows: CreateProcessW with the child's
 * standard handles on two anonymous pipes (and NUL for input), only those
 * three handles inherited (PROC_THREAD_ATTRIBUTE_HANDLE_LIST), and the
 * pipes polled with PeekNamedPipe, as anonymous pipes cannot be waited on.
 * Arguments are quoted by the rules CommandLineToArgvW and the C runtime
 * read them back with, so any UTF-8 argument arrives unchanged. */
#include "process.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <windows.h>

#include "utf16_win32.h"

#define POLL_MS 5 /* how often the pipes are looked at while waiting */

struct vxl_child {
    HANDLE process;
    HANDLE pipe[2]; /* read ends of stdout and stderr; NULL once at their end */
};

/* Appends s to the command line at *at (size n), quoted when it needs to
 * be: backslashes before a quote and at the end are doubled. 0, or -1 when
 * it does not fit. */
static int append_argument(char *line, size_t n, size_t *at, const char *s)
{
    const int quote = !*s || strpbrk(s, " \t\n\v\"") != NULL;
    size_t k = *at;
#define PUT(c)                      \
    do {                            \
        if (k + 1 >= n) return -1;  \
        line[k++] = (c);            \
    } while (0)
    if (k) PUT(' ');
    if (quote) PUT('"');
    for (const char *p = s;; p++) {
        size_t slashes = 0;
        while (*p == '\\') {
            p++;
            slashes++;
        }
        if (!*p) {
            for (size_t i = 0; i < (quote ? 2 * slashes : slashes); i++) PUT('\\');
            break;
        }
        if (*p == '"') {
            for (size_t i = 0; i < 2 * slashes + 1; i++) PUT('\\');
        } else {
            for (size_t i = 0; i < slashes; i++) PUT('\\');
        }
        PUT(*p);
    }
    if (quote) PUT('"');
#undef PUT
    line[k] = 0;
    *at = k;
    return 0;
}

static int pipe_pair(HANDLE *read_end, HANDLE *write_end)
{
    SECURITY_ATTRIBUTES sa = {sizeof sa, NULL, TRUE};
    if (!CreatePipe(read_end, write_end, &sa, 1 << 20)) return -1;
    SetHandleInformation(*read_end, HANDLE_FLAG_INHERIT, 0); /* ours alone */
    return 0;
}

vxl_child *vxl_child_start(const char *program, char *const argv[])
{
    char *line = malloc(VXL_WPATH);
    wchar_t *wline = malloc(VXL_WPATH * sizeof *wline), *wprog = malloc(VXL_WPATH * sizeof *wprog);
    vxl_child *c = calloc(1, sizeof *c);
    HANDLE out_w = NULL, err_w = NULL, nul = INVALID_HANDLE_VALUE;
    LPPROC_THREAD_ATTRIBUTE_LIST attrs = NULL;
    int ok = line && wline && wprog && c;
    size_t at = 0;
    for (int i = 0; ok && argv[i]; i++) ok = append_argument(line, VXL_WPATH, &at, argv[i]) == 0;
    ok = ok && vxl_utf8_to_utf16(line, wline, VXL_WPATH) && vxl_utf8_to_utf16(program, wprog, VXL_WPATH);
    if (!ok) errno = c && line ? EINVAL : ENOMEM;
    if (ok && (pipe_pair(&c->pipe[0], &out_w) || pipe_pair(&c->pipe[1], &err_w))) {
        ok = 0;
        errno = EMFILE;
    }
    if (ok) {
        SECURITY_ATTRIBUTES sa = {sizeof sa, NULL, TRUE};
        nul = CreateFileW(L"NUL", GENERIC_READ, FILE_SHARE_READ | FILE_SHARE_WRITE, &sa, OPEN_EXISTING, 0, NULL);
        ok = nul != INVALID_HANDLE_VALUE;
    }
    HANDLE inherit[3] = {nul, out_w, err_w};
    SIZE_T attr_size = 0;
    if (ok) {
        InitializeProcThreadAttributeList(NULL, 1, 0, &attr_size);
        attrs = malloc(attr_size);
        ok = attrs && InitializeProcThreadAttributeList(attrs, 1, 0, &attr_size) &&
             UpdateProcThreadAttribute(attrs, 0, PROC_THREAD_ATTRIBUTE_HANDLE_LIST, inherit, sizeof inherit, NULL,
                                       NULL);
    }
    if (ok) {
        STARTUPINFOEXW si;
        memset(&si, 0, sizeof si);
        si.StartupInfo.cb = sizeof si;
        si.StartupInfo.dwFlags = STARTF_USESTDHANDLES;
        si.StartupInfo.hStdInput = nul;
        si.StartupInfo.hStdOutput = out_w;
        si.StartupInfo.hStdError = err_w;
        si.lpAttributeList = attrs;
        PROCESS_INFORMATION pi;
        ok = CreateProcessW(wprog, wline, NULL, NULL, TRUE, CREATE_NO_WINDOW | EXTENDED_STARTUPINFO_PRESENT, NULL,
                            NULL, &si.StartupInfo, &pi);
        if (ok) {
            CloseHandle(pi.hThread);
            c->process = pi.hProcess;
        } else {
            errno = GetLastError() == ERROR_FILE_NOT_FOUND || GetLastError() == ERROR_PATH_NOT_FOUND ? ENOENT
                                                                                                        : EACCES;
        }
    }
    if (attrs) {
        DeleteProcThreadAttributeList(attrs);
        free(attrs);
    }
    if (out_w) CloseHandle(out_w);
    if (err_w) CloseHandle(err_w);
    if (nul != INVALID_HANDLE_VALUE) CloseHandle(nul);
    free(line);
    free(wline);
    free(wprog);
    if (!ok && c) {
        for (int s = 0; s < 2; s++)
            if (c->pipe[s]) CloseHandle(c->pipe[s]);
        free(c);
        c = NULL;
    }
    return c;
}

/* Whether a stream has something to read, or has ended. */
static int readable(HANDLE h)
{
    DWORD avail = 0;
    if (!PeekNamedPipe(h, NULL, 0, NULL, &avail, NULL)) return 1; /* broken: the end, which a read reports */
    return avail > 0;
}

int vxl_child_wait(vxl_child *c, int timeout_ms, int *ready)
{
    const ULONGLONG until = GetTickCount64() + (ULONGLONG)(timeout_ms < 0 ? 0 : timeout_ms);
    for (;;) {
        *ready = 0;
        for (int s = 0; s < 2; s++)
            if (c->pipe[s] && readable(c->pipe[s])) *ready |= 1 << s;
        if (*ready || GetTickCount64() >= until) return 0;
        Sleep(POLL_MS);
    }
}

int64_t vxl_child_read(vxl_child *c, int stream, void *buf, size_t n)
{
    if (!c->pipe[stream]) return 0;
    DWORD got = 0;
    const DWORD want = n > (1u << 30) ? (1u << 30) : (DWORD)n;
    if (!ReadFile(c->pipe[stream], buf, want, &got, NULL)) {
        if (GetLastError() != ERROR_BROKEN_PIPE) {
            errno = EIO;
            return -1;
        }
        got = 0;
    }
    if (!got) {
        CloseHandle(c->pipe[stream]);
        c->pipe[stream] = NULL;
    }
    return (int64_t)got;
}

int vxl_child_open(const vxl_child *c, int stream) { return c->pipe[stream] != NULL; }

void vxl_child_kill(vxl_child *c) { TerminateProcess(c->process, 1); }

void vxl_child_finish(vxl_child *c, vxl_child_end *end)
{
    memset(end, 0, sizeof *end);
    for (int s = 0; s < 2; s++)
        if (c->pipe[s]) CloseHandle(c->pipe[s]);
    DWORD code = 0;
    end->reaped = WaitForSingleObject(c->process, INFINITE) == WAIT_OBJECT_0 && GetExitCodeProcess(c->process, &code);
    end->exited = end->reaped;
    end->code = (int)code;
    CloseHandle(c->process);
    free(c);
}

int vxl_is_program(const char *path)
{
    wchar_t *w = malloc(VXL_WPATH * sizeof *w);
    int ok = 0;
    if (w && vxl_utf8_to_utf16(path, w, VXL_WPATH)) {
        const DWORD a = GetFileAttributesW(w);
        const size_t n = strlen(path);
        ok = a != INVALID_FILE_ATTRIBUTES && !(a & FILE_ATTRIBUTE_DIRECTORY) && n > 4 &&
             !_stricmp(path + n - 4, ".exe");
    }
    free(w);
    return ok;
}

/* Windows ends a crashed program with an exception code, not a signal. */
const char *vxl_signal_name(int sig)
{
    (void)sig;
    return NULL;
}

const char *vxl_program_suffix(void) { return ".exe"; }
