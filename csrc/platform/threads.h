/* threads.h - threads, locks, condition variables, run-once and per-thread
 * values: the library's one seam to the OS's threads. One implementation
 * per OS (threads_posix.c, threads_win32.c); nothing else includes
 * <pthread.h>. The types
 * are the OS's own, so a lock costs no extra allocation and can be
 * initialised statically (VXL_MUTEX_INIT, VXL_ONCE_INIT). */
#ifndef VXL_THREADS_H
#define VXL_THREADS_H

#ifdef _WIN32
/* SRWLOCK, CONDITION_VARIABLE and INIT_ONCE are one pointer each, zero
 * when unused (threads_win32.c checks the sizes); <windows.h> stays out of
 * every file that takes a lock. */
typedef struct vxl_mutex { void *p; } vxl_mutex;
typedef struct vxl_cond { void *p; } vxl_cond;
typedef struct vxl_thread { void *handle; } vxl_thread;
typedef struct vxl_once { void *p; } vxl_once;
typedef unsigned long vxl_tls;
#define VXL_MUTEX_INIT {0}
#define VXL_ONCE_INIT {0}
#else
#include <pthread.h>

typedef pthread_mutex_t vxl_mutex;
typedef pthread_cond_t vxl_cond;
typedef pthread_t vxl_thread;
typedef pthread_once_t vxl_once;
typedef pthread_key_t vxl_tls;
#define VXL_MUTEX_INIT PTHREAD_MUTEX_INITIALIZER
#define VXL_ONCE_INIT PTHREAD_ONCE_INIT
#endif

/* 0 on success, else the OS's error number (nothing to destroy then). */
int vxl_mutex_init(vxl_mutex *m);
void vxl_mutex_lock(vxl_mutex *m);
void vxl_mutex_unlock(vxl_mutex *m);
void vxl_mutex_destroy(vxl_mutex *m);

int vxl_cond_init(vxl_cond *c);
void vxl_cond_wait(vxl_cond *c, vxl_mutex *m);
void vxl_cond_broadcast(vxl_cond *c);
void vxl_cond_destroy(vxl_cond *c);

/* Starts fn(arg) on a new thread; 0 on success, else the OS's error number. */
int vxl_thread_start(vxl_thread *t, void *(*fn)(void *), void *arg);
void vxl_thread_join(vxl_thread t);

/* fn runs exactly once per `once`, whichever thread comes first; the
 * others wait for it to finish. */
void vxl_once_run(vxl_once *once, void (*fn)(void));

/* A value per thread, freed with dtor when a thread that set one ends.
 * 0 on success. */
int vxl_tls_create(vxl_tls *key, void (*dtor)(void *));
void *vxl_tls_get(vxl_tls key);
int vxl_tls_set(vxl_tls key, void *value);
void vxl_tls_delete(vxl_tls key);

/* The processors online, at least 1. */
unsigned vxl_cpu_count(void);

#endif
