/* test_platform.c - the platform room's seams (csrc/platform/), the same
 * checks on every OS: built for Linux with the rest of the C tests, and for
 * Windows (build/windows-x64/test_platform.exe), run under Wine by
 * ./build.sh test. Threads, locks, run-once and per-thread values under
 * contention; a system library opened and a function found; files and
 * folders with non-ASCII UTF-8 names written, renamed, listed, read at
 * offsets and removed; a child program's output, exit code and kill (the
 * child is tests/child_program.c, built next to this test); the monotonic
 * clock and the processor count; paths split and judged absolute as the
 * OS does, and the user's cache folder. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "dynlib.h"
#include "files.h"
#include "harness.h"
#include "utf8_temp.h"
#include "os.h"
#include "process.h"
#include "threads.h"

#define THREADS 8
#define ROUNDS 2000

typedef struct shared {
    vxl_mutex lock;
    vxl_cond turn;
    int counter, next; /* next: whose turn (round-robin through the condition) */
    vxl_tls key;
} shared;

static vxl_once once = VXL_ONCE_INIT;
static int once_runs;       /* written by the one run_once only */
static int tls_freed;       /* counted under the shared lock by the destructor */
static vxl_mutex freed_lock = VXL_MUTEX_INIT;

static void count_once(void) { once_runs++; }

static void free_value(void *p)
{
    vxl_mutex_lock(&freed_lock);
    tls_freed++;
    vxl_mutex_unlock(&freed_lock);
    free(p);
}

typedef struct worker {
    shared *s;
    int id, own_value_ok;
} worker;

static void *work(void *p)
{
    worker *w = p;
    vxl_once_run(&once, count_once);
    int *mine = malloc(sizeof *mine);
    *mine = w->id;
    vxl_tls_set(w->s->key, mine);
    for (int i = 0; i < ROUNDS; i++) {
        vxl_mutex_lock(&w->s->lock);
        while (w->s->next != w->id) vxl_cond_wait(&w->s->turn, &w->s->lock);
        w->s->counter++;
        w->s->next = (w->s->next + 1) % THREADS;
        vxl_cond_broadcast(&w->s->turn);
        vxl_mutex_unlock(&w->s->lock);
    }
    const int *back = vxl_tls_get(w->s->key);
    w->own_value_ok = back == mine && *back == w->id;
    return NULL;
}

TEST(threads_take_turns_and_keep_their_own_values)
{
    shared s;
    memset(&s, 0, sizeof s);
    REQUIRE(vxl_mutex_init(&s.lock) == 0 && vxl_cond_init(&s.turn) == 0);
    REQUIRE(vxl_tls_create(&s.key, free_value) == 0);
    vxl_thread t[THREADS];
    worker w[THREADS];
    for (int i = 0; i < THREADS; i++) {
        w[i] = (worker){&s, i, 0};
        REQUIRE(vxl_thread_start(&t[i], work, &w[i]) == 0);
    }
    for (int i = 0; i < THREADS; i++) vxl_thread_join(t[i]);
    CHECK(s.counter == THREADS * ROUNDS);
    CHECK(once_runs == 1);
    for (int i = 0; i < THREADS; i++) CHECKF(w[i].own_value_ok, "thread %d saw another's value", i);
    CHECKF(tls_freed == THREADS, "%d of %d per-thread values freed when their threads ended", tls_freed, THREADS);
    CHECK(vxl_tls_get(s.key) == NULL); /* this thread set none */
    vxl_tls_delete(s.key);
    vxl_cond_destroy(&s.turn);
    vxl_mutex_destroy(&s.lock);
    CHECK(vxl_cpu_count() >= 1);
}

TEST(a_system_library_opens_and_a_missing_one_says_why)
{
    const int windows = !strcmp(vxl_os_name(), "windows");
    const char *lib = windows ? "kernel32.dll" : "libc.so.6", *fn = windows ? "GetTickCount64" : "strlen";
    char why[256] = "";
    vxl_dynlib *l = vxl_dynlib_open(lib, why, sizeof why);
    CHECKF(l != NULL, "%s: %s", lib, why);
    CHECK(l && vxl_dynlib_symbol(l, fn) != NULL);
    CHECK(l && vxl_dynlib_symbol(l, "no_such_function_anywhere") == NULL);
    vxl_dynlib_close(l);
    CHECK(vxl_dynlib_open("no-such-library-of-voxlight.so", why, sizeof why) == NULL && why[0]);
    char self[4096];
    CHECK(vxl_dynlib_path_of((const void *)&vxl_os_name, self, sizeof self) == 0 && strstr(self, "test_platform"));
}

TEST(the_clock_never_goes_back)
{
    double last = vxl_monotonic_s();
    for (int i = 0; i < 100000; i++) {
        const double t = vxl_monotonic_s();
        if (t < last) {
            CHECKF(0, "%.9f after %.9f", t, last);
            break;
        }
        last = t;
    }
}

TEST(files_with_utf8_names_are_written_renamed_listed_and_read)
{
    char dir[4096], tmp[4200], final[4200];
    utf8_temp_folder("platform", dir, sizeof dir);
    REQUIRE(vxl_mkdir(dir) == 0);
    CHECK(vxl_mkdir(dir) == 0); /* already there */
    CHECK(vxl_is_dir(dir) && !vxl_is_file(dir));
    CHECK(vxl_dir_writable(dir));
    snprintf(final, sizeof final, "%s/données-Ω.bin", dir);
    vxl_remove(final);
    snprintf(tmp, sizeof tmp, "%s/part-XXXXXX", dir);
    FILE *f = vxl_temp_file(tmp);
    REQUIRE(f != NULL);
    CHECK(strstr(tmp, "XXXXXX") == NULL);
    enum { N = 300000 };
    static uint8_t data[N], back[N];
    for (int i = 0; i < N; i++) data[i] = (uint8_t)(i * 131 + (i >> 9));
    CHECK(fwrite(data, 1, N, f) == N);
    CHECK(vxl_fsync(f) == 0);
    CHECK(fclose(f) == 0);
    CHECK(vxl_rename(tmp, final) == 0);
    CHECK(!vxl_is_file(tmp) && vxl_is_file(final));

    vxl_path_info info;
    CHECK(vxl_path_stat(final, &info) == 0 && info.kind == VXL_PATH_FILE && info.size == N && info.mtime_ns > 0);
    const int fd = vxl_file_open_read(final, 1);
    REQUIRE(fd >= 0);
    CHECK(vxl_file_stat(fd, &info) == 0 && info.size == N);
    const uint64_t offsets[] = {0, 1, 4095, 4096, 123457, N - 10};
    for (size_t k = 0; k < sizeof offsets / sizeof offsets[0]; k++) {
        const uint64_t o = offsets[k];
        const size_t want = N - o < 5000 ? (size_t)(N - o) : 5000;
        CHECKF(vxl_file_pread(fd, back, want, o) == (int64_t)want && !memcmp(back, data + o, want), "at %llu",
               (unsigned long long)o);
    }
    CHECK(vxl_file_pread(fd, back, 10, N) == 0); /* at the end */
    uint64_t d = 0, h = 0;
    const int extent = vxl_file_data_extent(fd, 0, &d, &h);
    CHECK(extent == 0 || (extent == 1 && d == 0 && h >= N));
    vxl_file_close(fd);

    f = vxl_fopen(final, "rb");
    REQUIRE(f != NULL);
    CHECK(vxl_fseek(f, 200000) == 0 && fread(back, 1, 100, f) == 100 && !memcmp(back, data + 200000, 100));
    fclose(f);

    int listed = 0;
    vxl_dir *list = vxl_dir_open(dir);
    REQUIRE(list != NULL);
    for (const char *name; (name = vxl_dir_next(list)) != NULL;) {
        CHECK(strcmp(name, ".") && strcmp(name, ".."));
        listed += !strcmp(name, "données-Ω.bin");
    }
    vxl_dir_close(list);
    CHECK(listed == 1);

    char real[4096];
    CHECK(vxl_real_path(final, real, sizeof real) != NULL && strstr(real, "données-Ω.bin"));
    CHECK(vxl_remove(final) == 0 && !vxl_is_file(final));
    CHECK(vxl_path_stat(final, &info) == -1 && info.kind == VXL_PATH_NONE);
    CHECK(vxl_file_open_read(final, 0) < 0);
}

/* tests/child_program next to this program. */
static int child_path(char *out, size_t n)
{
    char self[4096];
    if (vxl_dynlib_path_of((const void *)&vxl_os_name, self, sizeof self)) return -1;
    char *slash = strrchr(self, '/'), *back = strrchr(self, '\\');
    if (back > slash) slash = back;
    if (slash) *slash = 0;
    const int windows = !strcmp(vxl_os_name(), "windows");
    return snprintf(out, n, "%s/child_program%s", slash ? self : ".", windows ? ".exe" : "") < (int)n ? 0 : -1;
}

typedef struct output {
    char out[400000], err[4096];
    size_t n_out, n_err;
} output;

/* Everything the child writes, until both streams end. */
static int drain(vxl_child *c, output *o)
{
    while (vxl_child_open(c, VXL_CHILD_OUT) || vxl_child_open(c, VXL_CHILD_ERR)) {
        int ready;
        if (vxl_child_wait(c, 60000, &ready)) return -1;
        if (!ready) return -1; /* a minute without a byte: the child hangs */
        if (ready & (1 << VXL_CHILD_OUT)) {
            int64_t k = vxl_child_read(c, VXL_CHILD_OUT, o->out + o->n_out, sizeof o->out - o->n_out);
            if (k > 0) o->n_out += (size_t)k;
        }
        if (ready & (1 << VXL_CHILD_ERR)) {
            int64_t k = vxl_child_read(c, VXL_CHILD_ERR, o->err + o->n_err, sizeof o->err - 1 - o->n_err);
            if (k > 0) o->n_err += (size_t)k;
        }
    }
    return 0;
}

TEST(a_child_program_writes_exits_and_is_killed)
{
    char prog[4200];
    REQUIRE(child_path(prog, sizeof prog) == 0);
    REQUIRE(vxl_is_program(prog));
    static output o;
    memset(&o, 0, sizeof o);
    char *const argv[] = {prog, "out:hello \"quoted\" words\\", "err:oops", "bytes:300000", "exit:3", NULL};
    vxl_child *c = vxl_child_start(prog, argv);
    REQUIRE(c != NULL);
    CHECK(drain(c, &o) == 0);
    vxl_child_end end;
    vxl_child_finish(c, &end);
    CHECK(end.reaped && end.exited && end.code == 3);
    const char *line = "hello \"quoted\" words\\";
    const size_t head = strlen(line);
    CHECKF(o.n_out >= head + 1 && !memcmp(o.out, line, head), "%.*s", (int)(o.n_out < 60 ? o.n_out : 60), o.out);
    /* text-mode stdout on Windows may turn \n into \r\n: skip the line's end */
    size_t at = head;
    while (at < o.n_out && (o.out[at] == '\r' || o.out[at] == '\n')) at++;
    int same = o.n_out - at == 300000;
    for (size_t k = 0; same && k < 300000; k++) same = o.out[at + k] == 'a' + (int)(k % 26);
    CHECKF(same, "%zu bytes after the line", o.n_out - at);
    o.err[o.n_err] = 0;
    CHECK(strstr(o.err, "oops") != NULL);

    char *const hang[] = {prog, "hang", NULL};
    c = vxl_child_start(prog, hang);
    REQUIRE(c != NULL);
    vxl_child_kill(c);
    vxl_child_finish(c, &end);
    CHECK(end.reaped && (end.signaled || end.exited));

    char missing[4300];
    snprintf(missing, sizeof missing, "%s-missing", prog);
    char *const none[] = {missing, NULL};
    CHECK(!vxl_is_program(missing));
    c = vxl_child_start(missing, none);
    if (c) { /* POSIX starts it and the exec fails in the child: exit 127 */
        vxl_child_finish(c, &end);
        CHECK(end.exited && end.code == 127);
    }
}

/* Paths as the OS spells them: both separators split on every OS (a
 * Windows program is handed either); what is absolute differs; the user's
 * cache folder is the OS's own. */
TEST(paths_are_split_and_judged_as_the_os_does)
{
    const int windows = !strcmp(vxl_os_name(), "windows");
    const char *p = "scans/one\\two.nhdr";
    CHECK(vxl_path_last_separator(p) == p + 9 && vxl_path_last_separator("name") == NULL);
    CHECK(vxl_path_is_separator('/') && vxl_path_is_separator('\\') && !vxl_path_is_separator(':'));
    CHECK(vxl_path_is_absolute("/data/a.nii") == 1 && !vxl_path_is_absolute("a.raw") &&
          !vxl_path_is_absolute("sub/a.raw") && !vxl_path_is_absolute(""));
    CHECK(vxl_path_is_absolute("C:\\scans\\a.raw") == windows && vxl_path_is_absolute("d:/a.raw") == windows &&
          vxl_path_is_absolute("\\\\server\\share\\a.raw") == windows && !vxl_path_is_absolute("C:a.raw"));
    char dir[4096];
    REQUIRE(vxl_user_cache_dir(dir, sizeof dir) == 0);
    const char *tail = windows ? "\\voxlight" : "/voxlight";
    CHECKF(strlen(dir) > strlen(tail) && !strcmp(dir + strlen(dir) - strlen(tail), tail) && vxl_path_is_absolute(dir),
           "%s", dir);
    char tiny[4];
    CHECK(vxl_user_cache_dir(tiny, sizeof tiny) == -1);
}

int main(void)
{
    RUN(threads_take_turns_and_keep_their_own_values);
    RUN(a_system_library_opens_and_a_missing_one_says_why);
    RUN(the_clock_never_goes_back);
    RUN(files_with_utf8_names_are_written_renamed_listed_and_read);
    RUN(a_child_program_writes_exits_and_is_killed);
    RUN(paths_are_split_and_judged_as_the_os_does);
    return TEST_SUMMARY();
}
