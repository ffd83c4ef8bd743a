/* gl_thread.c - the single-slot job queue of a renderer's GL thread. */
#include "gl_thread.h"

#include <string.h>

static void *thread_main(void *p)
{
    vxl_gl_thread *t = p;
    vxl_mutex_lock(&t->lock);
    for (;;) {
        while (!t->pending && !t->quit) vxl_cond_wait(&t->cond, &t->lock);
        if (t->pending) {
            vxl_job_fn fn = t->job;
            void *arg = t->arg;
            vxl_mutex_unlock(&t->lock);
            t->held = t->exclusive;
            if (t->held) vxl_mutex_lock(t->held);
            int r = fn ? fn(arg) : 0;
            if (t->held) vxl_mutex_unlock(t->held);
            t->held = NULL;
            vxl_mutex_lock(&t->lock);
            t->result = r;
            t->pending = 0;
            t->done = 1;
            vxl_cond_broadcast(&t->cond);
            continue;
        }
        if (t->quit) break;
    }
    vxl_mutex_unlock(&t->lock);
    return NULL;
}

int vxl_gl_thread_start(vxl_gl_thread *t)
{
    memset(t, 0, sizeof *t);
    if (vxl_mutex_init(&t->call_lock)) return -1;
    if (vxl_mutex_init(&t->lock)) {
        vxl_mutex_destroy(&t->call_lock);
        return -1;
    }
    if (vxl_cond_init(&t->cond)) {
        vxl_mutex_destroy(&t->lock);
        vxl_mutex_destroy(&t->call_lock);
        return -1;
    }
    if (vxl_thread_start(&t->thread, thread_main, t)) {
        vxl_cond_destroy(&t->cond);
        vxl_mutex_destroy(&t->lock);
        vxl_mutex_destroy(&t->call_lock);
        return -1;
    }
    t->started = 1;
    return 0;
}

int vxl_gl_thread_call(vxl_gl_thread *t, vxl_job_fn fn, void *arg)
{
    vxl_mutex_lock(&t->call_lock);
    vxl_mutex_lock(&t->lock);
    t->job = fn;
    t->arg = arg;
    t->done = 0;
    t->pending = 1;
    vxl_cond_broadcast(&t->cond);
    while (!t->done) vxl_cond_wait(&t->cond, &t->lock);
    int r = t->result;
    vxl_mutex_unlock(&t->lock);
    vxl_mutex_unlock(&t->call_lock);
    return r;
}

void vxl_gl_thread_hold(vxl_gl_thread *t, vxl_mutex *m)
{
    t->exclusive = m;
    if (t->held == m) return;
    if (t->held) vxl_mutex_unlock(t->held);
    t->held = m;
    if (m) vxl_mutex_lock(m);
}

void vxl_gl_thread_stop(vxl_gl_thread *t, vxl_job_fn fn, void *arg)
{
    if (!t->started) return;
    if (fn) vxl_gl_thread_call(t, fn, arg);
    vxl_mutex_lock(&t->lock);
    t->quit = 1;
    vxl_cond_broadcast(&t->cond);
    vxl_mutex_unlock(&t->lock);
    vxl_thread_join(t->thread);
    vxl_cond_destroy(&t->cond);
    vxl_mutex_destroy(&t->lock);
    vxl_mutex_destroy(&t->call_lock);
    t->started = 0;
}
