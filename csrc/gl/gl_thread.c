/* gl_thread.c - the single-slot job queue of a renderer's GL thread. */
#include "gl_thread.h"

#include <string.h>

static void *thread_main(void *p)
{
    vxl_gl_thread *t = p;
    pthread_mutex_lock(&t->lock);
    for (;;) {
        while (!t->pending && !t->quit) pthread_cond_wait(&t->cond, &t->lock);
        if (t->pending) {
            vxl_job_fn fn = t->job;
            void *arg = t->arg;
            pthread_mutex_unlock(&t->lock);
            t->held = t->exclusive;
            if (t->held) pthread_mutex_lock(t->held);
            int r = fn ? fn(arg) : 0;
            if (t->held) pthread_mutex_unlock(t->held);
            t->held = NULL;
            pthread_mutex_lock(&t->lock);
            t->result = r;
            t->pending = 0;
            t->done = 1;
            pthread_cond_broadcast(&t->cond);
            continue;
        }
        if (t->quit) break;
    }
    pthread_mutex_unlock(&t->lock);
    return NULL;
}

int vxl_gl_thread_start(vxl_gl_thread *t)
{
    memset(t, 0, sizeof *t);
    if (pthread_mutex_init(&t->call_lock, NULL)) return -1;
    if (pthread_mutex_init(&t->lock, NULL)) {
        pthread_mutex_destroy(&t->call_lock);
        return -1;
    }
    if (pthread_cond_init(&t->cond, NULL)) {
        pthread_mutex_destroy(&t->lock);
        pthread_mutex_destroy(&t->call_lock);
        return -1;
    }
    if (pthread_create(&t->thread, NULL, thread_main, t)) {
        pthread_cond_destroy(&t->cond);
        pthread_mutex_destroy(&t->lock);
        pthread_mutex_destroy(&t->call_lock);
        return -1;
    }
    t->started = 1;
    return 0;
}

int vxl_gl_thread_call(vxl_gl_thread *t, vxl_job_fn fn, void *arg)
{
    pthread_mutex_lock(&t->call_lock);
    pthread_mutex_lock(&t->lock);
    t->job = fn;
    t->arg = arg;
    t->done = 0;
    t->pending = 1;
    pthread_cond_broadcast(&t->cond);
    while (!t->done) pthread_cond_wait(&t->cond, &t->lock);
    int r = t->result;
    pthread_mutex_unlock(&t->lock);
    pthread_mutex_unlock(&t->call_lock);
    return r;
}

void vxl_gl_thread_hold(vxl_gl_thread *t, pthread_mutex_t *m)
{
    t->exclusive = m;
    if (t->held == m) return;
    if (t->held) pthread_mutex_unlock(t->held);
    t->held = m;
    if (m) pthread_mutex_lock(m);
}

void vxl_gl_thread_stop(vxl_gl_thread *t, vxl_job_fn fn, void *arg)
{
    if (!t->started) return;
    if (fn) vxl_gl_thread_call(t, fn, arg);
    pthread_mutex_lock(&t->lock);
    t->quit = 1;
    pthread_cond_broadcast(&t->cond);
    pthread_mutex_unlock(&t->lock);
    pthread_join(t->thread, NULL);
    pthread_cond_destroy(&t->cond);
    pthread_mutex_destroy(&t->lock);
    pthread_mutex_destroy(&t->call_lock);
    t->started = 0;
}
