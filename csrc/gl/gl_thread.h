/* gl_thread.h - one worker thread per renderer that owns its GL context.
 * Making an OSMesa/EGL context current on a host thread (Blender's main
 * thread) breaks the host's own GL, so all GL work is handed to this thread
 * and the caller waits. Calls from several threads are serialised.
 *
 * A thread may also hold a lock shared with other renderers' threads around
 * each of its jobs (vxl_gl_thread_hold): contexts on one Mesa llvmpipe screen
 * must never run GL at the same time (context.h, vxl_context_screen_lock). */
#ifndef VXL_GL_THREAD_H
#define VXL_GL_THREAD_H

#include "threads.h"

typedef int (*vxl_job_fn)(void *arg);

typedef struct vxl_gl_thread {
    vxl_thread thread;
    vxl_mutex call_lock; /* one caller at a time */
    vxl_mutex lock;
    vxl_cond cond;
    vxl_job_fn job;
    void *arg;
    int result;
    int pending, done, quit, started;
    /* touched on the GL thread only: the lock every job runs under (NULL:
     * none) and the one the running job holds */
    vxl_mutex *exclusive, *held;
} vxl_gl_thread;

int vxl_gl_thread_start(vxl_gl_thread *t);
/* Runs fn(arg) on the GL thread and returns its result. */
int vxl_gl_thread_call(vxl_gl_thread *t, vxl_job_fn fn, void *arg);
/* From inside a job: the rest of this job, and every later job of this
 * thread, runs holding m (NULL: no lock). Locks m before returning. */
void vxl_gl_thread_hold(vxl_gl_thread *t, vxl_mutex *m);
/* Runs fn(arg) (may be NULL) as the last job, then joins the thread. */
void vxl_gl_thread_stop(vxl_gl_thread *t, vxl_job_fn fn, void *arg);

#endif
