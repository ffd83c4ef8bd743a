/* vdb_spawn.c - vxl_vdb_load: reads a .vdb in a helper process.
 *
 * Debian's libopenvdb is built with assertions and aborts on some malformed
 * files inside OpenImageIO's open(), before any check of ours can run
 * (tests/fuzz/upstream/README.md). Inside Blender that would end the user's
 * session, so the read happens in voxlight-vdb-read (vdb_helper_main.c),
 * found next to libvoxlight.so and started with posix_spawn (never a bare
 * fork in a multi-threaded host). It streams a header and the voxels over a
 * pipe (vdb_stream.h); here the header is checked and the size passes the
 * memory budget before anything is allocated, a short stream is an error,
 * a crash becomes a message naming the signal, a hung helper is killed
 * after a time limit scaled with the file size, and the child is always
 * reaped. Nothing is ever written to the child, so SIGPIPE cannot reach
 * this process, and every descriptor here is O_CLOEXEC. There is no
 * in-process fallback: without the helper a .vdb is refused. */
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "loader_util.h"
#include "vdb_stream.h"

extern char **environ;

#define STDERR_KEEP 400 /* the tail of the helper's stderr quoted in errors */

static int helper_path(const char *path, char *out, size_t n, vxl_err *e)
{
    const char *env = getenv(VXL_VDB_HELPER_ENV);
    if (env && *env) {
        if (snprintf(out, n, "%s", env) >= (int)n)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "%s is too long", VXL_VDB_HELPER_ENV);
    } else {
        Dl_info info;
        if (!dladdr((void *)&vxl_vdb_load, &info) || !info.dli_fname)
            return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': cannot locate libvoxlight to find %s", path,
                            VXL_VDB_HELPER_NAME);
        const char *slash = strrchr(info.dli_fname, '/');
        int dir_len = slash ? (int)(slash - info.dli_fname) : 1;
        if (snprintf(out, n, "%.*s/%s", dir_len, slash ? info.dli_fname : ".", VXL_VDB_HELPER_NAME) >= (int)n)
            return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': the path of %s is too long", path, VXL_VDB_HELPER_NAME);
    }
    if (access(out, F_OK))
        return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': the OpenVDB reader helper %s is missing (it belongs next "
                        "to libvoxlight.so; .vdb files are read in a separate process so a corrupt file cannot "
                        "crash this one)", path, out);
    if (access(out, X_OK))
        return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': the OpenVDB reader helper %s is not executable "
                        "(chmod +x it)", path, out);
    return VXL_OK;
}

/* Seconds the helper may take: generous (OpenVDB decompresses every grid),
 * one minute plus a second per 4 MiB of file. */
static double time_limit(uint64_t file_size)
{
    const char *env = getenv(VXL_VDB_TIMEOUT_ENV);
    if (env && *env) {
        char *end;
        double s = strtod(env, &end);
        if (!*end && isfinite(s) && s > 0) return s;
    }
    return 60.0 + (double)(file_size >> 22);
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

/* What came back over the two pipes. */
typedef struct reply {
    vxl_vdb_header h;
    size_t h_got;
    char *body;            /* the message or the voxels, once the header passed */
    uint64_t body_len, body_got;
    int extra;             /* bytes after the announced end */
    char err_tail[STDERR_KEEP + 1];
    size_t err_len;
} reply;

static void keep_stderr(reply *r, const char *buf, size_t n)
{
    if (n >= STDERR_KEEP) {
        memcpy(r->err_tail, buf + n - STDERR_KEEP, STDERR_KEEP);
        r->err_len = STDERR_KEEP;
    } else {
        size_t drop = r->err_len + n > STDERR_KEEP ? r->err_len + n - STDERR_KEEP : 0;
        memmove(r->err_tail, r->err_tail + drop, r->err_len - drop);
        memcpy(r->err_tail + r->err_len - drop, buf, n);
        r->err_len += n - drop;
    }
    r->err_tail[r->err_len] = '\0';
}

/* Checks a complete header and makes room for what follows it. */
static int accept_header(const char *path, reply *r, const vxl_load_options *opt, vxl_err *e)
{
    const vxl_vdb_header *h = &r->h;
    if (memcmp(h->magic, VXL_VDB_MAGIC, sizeof VXL_VDB_MAGIC))
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the OpenVDB reader helper sent no valid header", path);
    if (h->status != VXL_OK) {
        if (h->msg_len == 0 || h->msg_len > VXL_VDB_MSG_MAX)
            return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the OpenVDB reader helper failed (code %u) with "
                            "a bad message length %u", path, h->status, h->msg_len);
        r->body_len = h->msg_len;
    } else {
        if (h->dtype != VXL_DTYPE_F32)
            return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the OpenVDB reader helper sent data type %u", path,
                            h->dtype);
        uint64_t nbytes = 0;
        int rc = vxl_plan_voxels(path, h->dims, VXL_DTYPE_F32, opt, &nbytes, e);
        if (rc) return rc;
        if (h->nbytes != nbytes)
            return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the OpenVDB reader helper announced %llu bytes "
                            "for %ux%ux%u float voxels", path, (unsigned long long)h->nbytes, h->dims[0],
                            h->dims[1], h->dims[2]);
        for (int i = 0; i < 16; i++)
            if (!isfinite(h->affine[i]))
                return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the grid transform is not finite", path);
        r->body_len = nbytes;
    }
    r->body = malloc(r->body_len ? r->body_len : 1);
    if (!r->body)
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "cannot read '%s': out of memory for %llu bytes", path,
                        (unsigned long long)r->body_len);
    return VXL_OK;
}

/* Reads what is readable on the data pipe; sets *eof at its end. */
static int read_data(const char *path, int fd, reply *r, const vxl_load_options *opt, int *eof, vxl_err *e)
{
    char scratch[256];
    void *dst;
    size_t want;
    if (r->h_got < sizeof r->h) {
        dst = (char *)&r->h + r->h_got;
        want = sizeof r->h - r->h_got;
    } else if (r->body_got < r->body_len) {
        dst = r->body + r->body_got;
        uint64_t left = r->body_len - r->body_got;
        want = left > (1u << 24) ? (1u << 24) : (size_t)left;
    } else {
        dst = scratch;
        want = sizeof scratch;
    }
    ssize_t n = read(fd, dst, want);
    if (n < 0) {
        if (errno == EINTR || errno == EAGAIN) return VXL_OK;
        return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': reading from the OpenVDB reader helper: %s", path,
                        strerror(errno));
    }
    if (n == 0) {
        *eof = 1;
        return VXL_OK;
    }
    if (dst == scratch) r->extra = 1;
    else if (r->h_got < sizeof r->h) {
        r->h_got += (size_t)n;
        if (r->h_got == sizeof r->h) return accept_header(path, r, opt, e);
    } else r->body_got += (uint64_t)n;
    return VXL_OK;
}

/* Moves a descriptor above 0..2, so that a host running with a standard
 * stream closed cannot make the helper's dup2s below overwrite each other. */
static int above_stdio(int fd)
{
    if (fd > 2) return fd;
    int moved = fcntl(fd, F_DUPFD_CLOEXEC, 3);
    close(fd);
    return moved;
}

/* Opens a pipe, both ends O_CLOEXEC and above 0..2. */
static int pipe_above_stdio(int p[2])
{
    if (pipe2(p, O_CLOEXEC)) return -1;
    p[0] = above_stdio(p[0]);
    p[1] = above_stdio(p[1]);
    if (p[0] >= 0 && p[1] >= 0) return 0;
    int saved = errno;
    if (p[0] >= 0) close(p[0]);
    if (p[1] >= 0) close(p[1]);
    errno = saved;
    return -1;
}

/* Starts the helper with stdout on data_w, stderr on err_w, stdin on
 * /dev/null, no other descriptor of ours, default signal handling. */
static int spawn_helper(const char *helper, const char *path, const vxl_load_options *opt, int data_w, int err_w,
                        pid_t *pid, vxl_err *e)
{
    char max_dim[24], budget[24];
    snprintf(max_dim, sizeof max_dim, "%u", opt && opt->max_dim ? opt->max_dim : VXL_DEFAULT_MAX_DIM);
    snprintf(budget, sizeof budget, "%llu",
             (unsigned long long)(opt && opt->memory_budget_bytes ? opt->memory_budget_bytes : VXL_DEFAULT_BUDGET));
    char *const argv[] = {(char *)helper, (char *)path, max_dim, budget, NULL};
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t at;
    sigset_t none, all;
    sigemptyset(&none);
    sigfillset(&all);
    int rc = posix_spawn_file_actions_init(&fa);
    if (rc) return vxl_fail(e, VXL_ERR_NO_MEMORY, "cannot read '%s': %s", path, strerror(rc));
    rc = posix_spawnattr_init(&at);
    if (rc) {
        posix_spawn_file_actions_destroy(&fa);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "cannot read '%s': %s", path, strerror(rc));
    }
    if (!rc) rc = posix_spawn_file_actions_adddup2(&fa, data_w, 1);
    if (!rc) rc = posix_spawn_file_actions_adddup2(&fa, err_w, 2);
    if (!rc) rc = posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    /* the host's own descriptors without O_CLOEXEC stay out of the helper */
    if (!rc) rc = posix_spawn_file_actions_addclosefrom_np(&fa, 3);
    if (!rc) rc = posix_spawnattr_setflags(&at, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    if (!rc) rc = posix_spawnattr_setsigmask(&at, &none);
    if (!rc) rc = posix_spawnattr_setsigdefault(&at, &all);
    if (!rc) rc = posix_spawn(pid, helper, &fa, &at, argv, environ);
    posix_spawnattr_destroy(&at);
    posix_spawn_file_actions_destroy(&fa);
    if (rc) return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': cannot start the OpenVDB reader helper %s: %s", path,
                            helper, strerror(rc));
    return VXL_OK;
}

/* Collects the helper's output until both pipes close, the time limit
 * passes (*timed_out) or the stream is bad (an error: the caller kills). */
static int collect(const char *path, int data_r, int err_r, double limit, const vxl_load_options *opt, reply *r,
                   int *timed_out, vxl_err *e)
{
    const double deadline = now_s() + limit;
    int data_eof = 0, err_eof = 0;
    while (!data_eof || !err_eof) {
        double left = deadline - now_s();
        if (left <= 0) {
            *timed_out = 1;
            return VXL_OK;
        }
        struct pollfd p[2] = {{.fd = data_eof ? -1 : data_r, .events = POLLIN},
                              {.fd = err_eof ? -1 : err_r, .events = POLLIN}};
        int n = poll(p, 2, left > 1e6 ? 1000000000 : (int)(left * 1000.0) + 1);
        if (n < 0) {
            if (errno == EINTR) continue;
            return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': waiting for the OpenVDB reader helper: %s", path,
                            strerror(errno));
        }
        if (p[0].revents) {
            int rc = read_data(path, data_r, r, opt, &data_eof, e);
            if (rc) return rc;
        }
        if (p[1].revents) {
            char buf[4096];
            ssize_t k = read(err_r, buf, sizeof buf);
            if (k > 0) keep_stderr(r, buf, (size_t)k);
            else if (k == 0 || (errno != EINTR && errno != EAGAIN)) err_eof = 1;
        }
    }
    return VXL_OK;
}

/* The last non-empty line of the helper's stderr, for error messages. */
static const char *last_line(reply *r)
{
    char *s = r->err_tail;
    size_t n = strlen(s);
    while (n && (s[n - 1] == '\n' || s[n - 1] == '\r' || s[n - 1] == ' ')) s[--n] = '\0';
    char *nl = strrchr(s, '\n');
    return nl ? nl + 1 : s;
}

/* Turns how the helper ended and what it sent into our result. */
static int verdict(const char *path, const char *helper, int status, int reaped, int timed_out, double limit,
                   reply *r, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    const char *said = last_line(r);
    if (timed_out)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the OpenVDB reader took longer than %.0f s and was "
                        "stopped", path, limit);
    if (reaped && WIFSIGNALED(status)) {
        int sig = WTERMSIG(status);
        const char *abbrev = sigabbrev_np(sig);
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the OpenVDB reader crashed (signal %d: SIG%s) - the "
                        "file is corrupt or unsupported%s%s%s", path, sig, abbrev ? abbrev : "?",
                        *said ? " (" : "", said, *said ? ")" : "");
    }
    const int complete = r->h_got == sizeof r->h && r->body && r->body_got == r->body_len;
    if (complete && r->h.status != VXL_OK) {
        int code = r->h.status >= VXL_ERR_INVALID_ARGUMENT && r->h.status <= VXL_ERR_STATE ? (int)r->h.status
                                                                                           : VXL_ERR_FORMAT;
        return vxl_fail(e, code, "%.*s", (int)r->body_len, r->body);
    }
    if (reaped && WIFEXITED(status) && WEXITSTATUS(status) != 0)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the OpenVDB reader helper %s failed (exit %d)%s%s", path,
                        helper, WEXITSTATUS(status), *said ? ": " : "", said);
    if (!complete)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the OpenVDB reader's output was cut short (%llu of "
                        "%llu bytes)", path, (unsigned long long)(r->h_got + r->body_got),
                        (unsigned long long)(sizeof r->h + r->body_len));
    if (r->extra)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the OpenVDB reader sent more than it announced", path);
    vxl_err inner = {0};
    int rc = vxl_volume_build(r->body, VXL_DTYPE_F32, r->h.dims, r->h.spacing, r->h.affine, 0.0, 0.0, opt, out,
                              &inner);
    if (rc) return vxl_fail_in(e, path, &inner);
    (*out)->affine_source = 2; /* a full affine from the file, as an sform */
    return VXL_OK;
}

int vxl_vdb_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    if (!out) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (!path || !*path) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path is empty");
    uint64_t fsize = 0;
    int rc = vxl_regular_file(path, &fsize, e);
    if (rc) return rc;
    char helper[4096];
    rc = helper_path(path, helper, sizeof helper, e);
    if (rc) return rc;
    int data[2], err[2];
    if (pipe_above_stdio(data))
        return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': pipe: %s", path, strerror(errno));
    if (pipe_above_stdio(err)) {
        int saved = errno;
        close(data[0]);
        close(data[1]);
        return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': pipe: %s", path, strerror(saved));
    }
    /* a larger pipe: fewer wake-ups for the voxels (best effort; 64 KiB
     * otherwise) */
    (void)fcntl(data[1], F_SETPIPE_SZ, 1 << 20);
    pid_t pid = -1;
    rc = spawn_helper(helper, path, opt, data[1], err[1], &pid, e);
    close(data[1]);
    close(err[1]);
    reply r;
    memset(&r, 0, sizeof r);
    int timed_out = 0, status = 0, reaped = 0;
    const double limit = time_limit(fsize);
    if (!rc) {
        rc = collect(path, data[0], err[0], limit, opt, &r, &timed_out, e);
        if (rc || timed_out) kill(pid, SIGKILL);
        pid_t w;
        while ((w = waitpid(pid, &status, 0)) < 0 && errno == EINTR) {}
        /* ECHILD: the host reaps children itself (SIGCHLD ignored); the
         * stream alone then decides */
        reaped = w == pid;
        if (!rc) rc = verdict(path, helper, status, reaped, timed_out, limit, &r, opt, out, e);
    }
    close(data[0]);
    close(err[0]);
    free(r.body);
    return rc;
}
