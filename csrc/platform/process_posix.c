/* process_posix.c - process.h with posix_spawn (never a bare fork in a
 * multi-threaded host) and pipes read with poll. */
#include "process.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

struct vxl_child {
    pid_t pid;
    int fd[2]; /* read ends of stdout and stderr; -1 once at their end */
};

/* Moves a descriptor above 0..2, so that a host running with a standard
 * stream closed cannot make the child's dup2s overwrite each other. */
static int above_stdio(int fd)
{
    if (fd > 2) return fd;
    int moved = fcntl(fd, F_DUPFD_CLOEXEC, 3);
    close(fd);
    return moved;
}

/* A pipe, both ends O_CLOEXEC and above 0..2. */
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

static int spawn(pid_t *pid, const char *program, char *const argv[], int out_w, int err_w)
{
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t at;
    sigset_t none, all;
    sigemptyset(&none);
    sigfillset(&all);
    int rc = posix_spawn_file_actions_init(&fa);
    if (rc) return rc;
    rc = posix_spawnattr_init(&at);
    if (rc) {
        posix_spawn_file_actions_destroy(&fa);
        return rc;
    }
    if (!rc) rc = posix_spawn_file_actions_adddup2(&fa, out_w, 1);
    if (!rc) rc = posix_spawn_file_actions_adddup2(&fa, err_w, 2);
    if (!rc) rc = posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    /* The host's own descriptors without O_CLOEXEC stay open in the child:
     * glibc 2.28's posix_spawn cannot close them, so the helpers close
     * them first thing (io/helper_main.c). */
    if (!rc) rc = posix_spawnattr_setflags(&at, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    if (!rc) rc = posix_spawnattr_setsigmask(&at, &none);
    if (!rc) rc = posix_spawnattr_setsigdefault(&at, &all);
    if (!rc) rc = posix_spawn(pid, program, &fa, &at, argv, environ);
    posix_spawnattr_destroy(&at);
    posix_spawn_file_actions_destroy(&fa);
    return rc;
}

vxl_child *vxl_child_start(const char *program, char *const argv[])
{
    vxl_child *c = malloc(sizeof *c);
    if (!c) {
        errno = ENOMEM;
        return NULL;
    }
    int out[2], err[2];
    if (pipe_above_stdio(out)) {
        free(c);
        return NULL;
    }
    if (pipe_above_stdio(err)) {
        int saved = errno;
        close(out[0]);
        close(out[1]);
        free(c);
        errno = saved;
        return NULL;
    }
    /* a larger pipe: fewer wake-ups for the voxels (best effort; 64 KiB
     * otherwise) */
    (void)fcntl(out[1], F_SETPIPE_SZ, 1 << 20);
    int rc = spawn(&c->pid, program, argv, out[1], err[1]);
    close(out[1]);
    close(err[1]);
    if (rc) {
        close(out[0]);
        close(err[0]);
        free(c);
        errno = rc;
        return NULL;
    }
    c->fd[VXL_CHILD_OUT] = out[0];
    c->fd[VXL_CHILD_ERR] = err[0];
    return c;
}

int vxl_child_wait(vxl_child *c, int timeout_ms, int *ready)
{
    *ready = 0;
    struct pollfd p[2] = {{.fd = c->fd[0], .events = POLLIN}, {.fd = c->fd[1], .events = POLLIN}};
    int n = poll(p, 2, timeout_ms);
    if (n < 0) return errno == EINTR ? 0 : -1;
    for (int s = 0; s < 2; s++)
        if (p[s].revents) *ready |= 1 << s;
    return 0;
}

int64_t vxl_child_read(vxl_child *c, int stream, void *buf, size_t n)
{
    if (c->fd[stream] < 0) return 0;
    ssize_t k = read(c->fd[stream], buf, n);
    if (k == 0) {
        close(c->fd[stream]);
        c->fd[stream] = -1;
    }
    return (int64_t)k;
}

int vxl_child_open(const vxl_child *c, int stream) { return c->fd[stream] >= 0; }

void vxl_child_kill(vxl_child *c) { kill(c->pid, SIGKILL); }

void vxl_child_finish(vxl_child *c, vxl_child_end *end)
{
    memset(end, 0, sizeof *end);
    for (int s = 0; s < 2; s++)
        if (c->fd[s] >= 0) close(c->fd[s]);
    int status = 0;
    pid_t w;
    while ((w = waitpid(c->pid, &status, 0)) < 0 && errno == EINTR) {}
    /* ECHILD: the host reaps children itself (SIGCHLD ignored) */
    end->reaped = w == c->pid;
    if (end->reaped && WIFEXITED(status)) {
        end->exited = 1;
        end->code = WEXITSTATUS(status);
    } else if (end->reaped && WIFSIGNALED(status)) {
        end->signaled = 1;
        end->signal = WTERMSIG(status);
    }
    free(c);
}

int vxl_is_program(const char *path) { return access(path, X_OK) == 0; }

/* glibc's sigabbrev_np is 2.32, newer than the library may need. */
const char *vxl_signal_name(int sig)
{
    switch (sig) {
    case SIGSEGV: return "SEGV";
    case SIGBUS: return "BUS";
    case SIGABRT: return "ABRT";
    case SIGFPE: return "FPE";
    case SIGILL: return "ILL";
    case SIGKILL: return "KILL";
    case SIGTERM: return "TERM";
    case SIGXCPU: return "XCPU";
    case SIGXFSZ: return "XFSZ";
    case SIGPIPE: return "PIPE";
    case SIGTRAP: return "TRAP";
    case SIGSYS: return "SYS";
    default: return NULL;
    }
}

const char *vxl_program_suffix(void) { return ""; }
