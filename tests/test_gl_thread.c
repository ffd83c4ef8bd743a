/* test_gl_thread.c - the GL thread's shared lock: contexts on one Mesa
 * llvmpipe screen take turns (csrc/gl/context.h explains the Mesa race).
 * Links gl_thread.c and context.c directly: the lock is internal. */
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <string.h>

#include "context.h"
#include "gl_thread.h"
#include "harness.h"

typedef struct hold_job {
    vxl_gl_thread *t;
    pthread_mutex_t *m;
    int busy_inside; /* trylock's answer from inside the job */
} hold_job;

static int job_hold(void *p)
{
    hold_job *j = p;
    vxl_gl_thread_hold(j->t, j->m);
    j->busy_inside = j->m && pthread_mutex_trylock(j->m) == EBUSY;
    return 0;
}

static int job_probe(void *p)
{
    hold_job *j = p;
    j->busy_inside = pthread_mutex_trylock(j->m) == EBUSY;
    if (!j->busy_inside) pthread_mutex_unlock(j->m);
    return 0;
}

TEST(every_job_after_hold_runs_holding_the_lock)
{
    pthread_mutex_t m = PTHREAD_MUTEX_INITIALIZER;
    vxl_gl_thread t;
    REQUIRE(vxl_gl_thread_start(&t) == 0);
    hold_job j = {&t, &m, 0};
    CHECK(vxl_gl_thread_call(&t, job_probe, &j) == 0);
    CHECKF(!j.busy_inside, "a job held a lock before any hold");
    CHECK(vxl_gl_thread_call(&t, job_hold, &j) == 0);
    CHECKF(j.busy_inside, "the holding job itself runs without the lock");
    /* between jobs the lock is free: other renderers' threads get their turn */
    CHECK(pthread_mutex_trylock(&m) == 0);
    pthread_mutex_unlock(&m);
    j.busy_inside = 0;
    CHECK(vxl_gl_thread_call(&t, job_probe, &j) == 0);
    CHECKF(j.busy_inside, "a later job runs without the lock");
    /* the last job (a renderer's close) holds it too */
    j.busy_inside = 0;
    vxl_gl_thread_stop(&t, job_probe, &j);
    CHECKF(j.busy_inside, "the closing job runs without the lock");
    CHECK(pthread_mutex_trylock(&m) == 0);
    pthread_mutex_unlock(&m);
}

TEST(hold_null_releases)
{
    pthread_mutex_t m = PTHREAD_MUTEX_INITIALIZER;
    vxl_gl_thread t;
    REQUIRE(vxl_gl_thread_start(&t) == 0);
    hold_job j = {&t, &m, 0};
    CHECK(vxl_gl_thread_call(&t, job_hold, &j) == 0);
    hold_job off = {&t, NULL, 0};
    CHECK(vxl_gl_thread_call(&t, job_hold, &off) == 0);
    j.busy_inside = 1;
    CHECK(vxl_gl_thread_call(&t, job_probe, &j) == 0);
    CHECKF(!j.busy_inside, "a job still holds the lock after hold(NULL)");
    vxl_gl_thread_stop(&t, NULL, NULL);
}

/* Two threads sharing one lock: their jobs never overlap. */
typedef struct overlap_job {
    vxl_gl_thread *t;
    pthread_mutex_t *m;
    atomic_int *inside;
    atomic_int *overlaps;
} overlap_job;

static int job_overlap(void *p)
{
    overlap_job *j = p;
    if (j->m) vxl_gl_thread_hold(j->t, j->m);
    if (atomic_fetch_add(j->inside, 1) != 0) atomic_fetch_add(j->overlaps, 1);
    for (int i = 0; i < 200; i++) sched_yield();
    atomic_fetch_sub(j->inside, 1);
    return 0;
}

typedef struct caller {
    overlap_job job;
    int calls;
} caller;

static void *call_many(void *p)
{
    caller *c = p;
    for (int i = 0; i < c->calls; i++) vxl_gl_thread_call(c->job.t, job_overlap, &c->job);
    return NULL;
}

TEST(threads_sharing_a_lock_take_turns)
{
    pthread_mutex_t m = PTHREAD_MUTEX_INITIALIZER;
    atomic_int inside = 0, overlaps = 0;
    vxl_gl_thread t[2];
    caller c[2];
    pthread_t th[2];
    for (int k = 0; k < 2; k++) {
        REQUIRE(vxl_gl_thread_start(&t[k]) == 0);
        c[k] = (caller){{&t[k], &m, &inside, &overlaps}, 300};
    }
    for (int k = 0; k < 2; k++) REQUIRE(pthread_create(&th[k], NULL, call_many, &c[k]) == 0);
    for (int k = 0; k < 2; k++) pthread_join(th[k], NULL);
    for (int k = 0; k < 2; k++) vxl_gl_thread_stop(&t[k], NULL, NULL);
    CHECKF(atomic_load(&overlaps) == 0, "%d jobs of two threads sharing a lock overlapped", atomic_load(&overlaps));
}

TEST(llvmpipe_contexts_share_their_screens_lock)
{
    const char *llvmpipe = "llvmpipe (LLVM 15.0.6, 256 bits)";
    int osmesa = vxl_context_screen_kind("osmesa", llvmpipe);
    int egl = vxl_context_screen_kind("egl-surfaceless", llvmpipe);
    CHECK(osmesa != 0 && egl != 0 && osmesa != egl);
    CHECK(vxl_context_screen_lock(osmesa) != NULL);
    CHECK(vxl_context_screen_lock(osmesa) == vxl_context_screen_lock(vxl_context_screen_kind("osmesa", llvmpipe)));
    CHECK(vxl_context_screen_lock(osmesa) != vxl_context_screen_lock(egl));
    /* a GPU driver needs no turns */
    CHECK(vxl_context_screen_kind("egl-device", "NVIDIA H100 80GB HBM3/PCIe/SSE2") == 0);
    CHECK(vxl_context_screen_lock(0) == NULL);
    CHECK(vxl_context_screen_kind("egl-device", llvmpipe) != 0);
    CHECK(vxl_context_screen_kind(NULL, llvmpipe) == 0 && vxl_context_screen_kind("osmesa", NULL) == 0);
}

int main(void)
{
    RUN(every_job_after_hold_runs_holding_the_lock);
    RUN(hold_null_releases);
    RUN(threads_sharing_a_lock_take_turns);
    RUN(llvmpipe_contexts_share_their_screens_lock);
    return TEST_SUMMARY();
}
