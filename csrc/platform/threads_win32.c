/* threads_win32.c - threads.h with Windows' slim reader/writer locks,
 * condition variables, one-time initialisation and fiber-local storage
 * (whose destructor runs when a thread ends, as a pthread key's does). */
#include "threads.h"

#include <errno.h>
#include <stdlib.h>
#include <windows.h>

_Static_assert(sizeof(vxl_mutex) == sizeof(SRWLOCK), "vxl_mutex holds an SRWLOCK");
_Static_assert(sizeof(vxl_cond) == sizeof(CONDITION_VARIABLE), "vxl_cond holds a CONDITION_VARIABLE");
_Static_assert(sizeof(vxl_once) == sizeof(INIT_ONCE), "vxl_once holds an INIT_ONCE");

int vxl_mutex_init(vxl_mutex *m)
{
    InitializeSRWLock((SRWLOCK *)m);
    return 0;
}
void vxl_mutex_lock(vxl_mutex *m) { AcquireSRWLockExclusive((SRWLOCK *)m); }
void vxl_mutex_unlock(vxl_mutex *m) { ReleaseSRWLockExclusive((SRWLOCK *)m); }
void vxl_mutex_destroy(vxl_mutex *m) { (void)m; }

int vxl_cond_init(vxl_cond *c)
{
    InitializeConditionVariable((CONDITION_VARIABLE *)c);
    return 0;
}
void vxl_cond_wait(vxl_cond *c, vxl_mutex *m) { SleepConditionVariableSRW((CONDITION_VARIABLE *)c, (SRWLOCK *)m, INFINITE, 0); }
void vxl_cond_broadcast(vxl_cond *c) { WakeAllConditionVariable((CONDITION_VARIABLE *)c); }
void vxl_cond_destroy(vxl_cond *c) { (void)c; }

typedef struct start {
    void *(*fn)(void *);
    void *arg;
} start;

static DWORD WINAPI trampoline(LPVOID p)
{
    start s = *(start *)p;
    free(p);
    s.fn(s.arg);
    return 0;
}

int vxl_thread_start(vxl_thread *t, void *(*fn)(void *), void *arg)
{
    start *s = malloc(sizeof *s);
    if (!s) return ENOMEM;
    s->fn = fn;
    s->arg = arg;
    HANDLE h = CreateThread(NULL, 0, trampoline, s, 0, NULL);
    if (!h) {
        free(s);
        return EAGAIN;
    }
    t->handle = h;
    return 0;
}

void vxl_thread_join(vxl_thread t)
{
    WaitForSingleObject((HANDLE)t.handle, INFINITE);
    CloseHandle((HANDLE)t.handle);
}

typedef struct once_call {
    void (*fn)(void);
} once_call;

static BOOL CALLBACK run_once(PINIT_ONCE once, PVOID param, PVOID *ctx)
{
    (void)once;
    (void)ctx;
    ((once_call *)param)->fn();
    return TRUE;
}

void vxl_once_run(vxl_once *once, void (*fn)(void))
{
    once_call call = {fn};
    InitOnceExecuteOnce((PINIT_ONCE)once, run_once, &call, NULL);
}

int vxl_tls_create(vxl_tls *key, void (*dtor)(void *))
{
    /* FLS callbacks take the value as pthread key destructors do */
    DWORD k = FlsAlloc((PFLS_CALLBACK_FUNCTION)dtor);
    if (k == FLS_OUT_OF_INDEXES) return EAGAIN;
    *key = k;
    return 0;
}
void *vxl_tls_get(vxl_tls key) { return FlsGetValue(key); }
int vxl_tls_set(vxl_tls key, void *value) { return FlsSetValue(key, value) ? 0 : EINVAL; }
void vxl_tls_delete(vxl_tls key) { FlsFree(key); }

unsigned vxl_cpu_count(void)
{
    SYSTEM_INFO si;
    GetSystemInfo(&si);
    return si.dwNumberOfProcessors ? (unsigned)si.dwNumberOfProcessors : 1u;
}
