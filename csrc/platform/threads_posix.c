/* threads_posix.c - threads.h with POSIX threads. */
#include "threads.h"

#include <unistd.h>

int vxl_mutex_init(vxl_mutex *m) { return pthread_mutex_init(m, NULL); }
void vxl_mutex_lock(vxl_mutex *m) { pthread_mutex_lock(m); }
void vxl_mutex_unlock(vxl_mutex *m) { pthread_mutex_unlock(m); }
void vxl_mutex_destroy(vxl_mutex *m) { pthread_mutex_destroy(m); }

int vxl_cond_init(vxl_cond *c) { return pthread_cond_init(c, NULL); }
void vxl_cond_wait(vxl_cond *c, vxl_mutex *m) { pthread_cond_wait(c, m); }
void vxl_cond_broadcast(vxl_cond *c) { pthread_cond_broadcast(c); }
void vxl_cond_destroy(vxl_cond *c) { pthread_cond_destroy(c); }

int vxl_thread_start(vxl_thread *t, void *(*fn)(void *), void *arg) { return pthread_create(t, NULL, fn, arg); }
void vxl_thread_join(vxl_thread t) { pthread_join(t, NULL); }

void vxl_once_run(vxl_once *once, void (*fn)(void)) { pthread_once(once, fn); }

int vxl_tls_create(vxl_tls *key, void (*dtor)(void *)) { return pthread_key_create(key, dtor); }
void *vxl_tls_get(vxl_tls key) { return pthread_getspecific(key); }
int vxl_tls_set(vxl_tls key, void *value) { return pthread_setspecific(key, value); }
void vxl_tls_delete(vxl_tls key) { pthread_key_delete(key); }

unsigned vxl_cpu_count(void)
{
    const long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1u : (unsigned)n;
}
