/* brick_loader.c - the streaming loader threads (brick_loader.h): a wanted
 * list the renderer replaces each frame, a bounded queue of read bricks,
 * and the first read error, all behind one mutex. Several threads read at
 * once (a source's read is thread-safe, brick_source.h): on a brick cache
 * each read is mostly inflate, which one core cannot keep up with while the
 * renderer waits. Each thread reads straight into its staging buffer, so
 * more threads hold no more memory than the queue. */
#include "brick_loader.h"

#include "threads.h"
#include <stdlib.h>
#include <string.h>

#include "paging.h"

#define MAX_THREADS 4 /* enough to keep inflate off the renderer's wait on usual machines */

struct vxl_brick_loader {
    vxl_brick_source *src;
    uint32_t brick, edge, bpv;
    size_t brick_bytes;
    vxl_thread threads[MAX_THREADS];
    uint32_t n_threads;
    vxl_mutex lock;
    vxl_cond work;    /* the loaders wait here for wanted bricks or free buffers */
    vxl_cond arrived; /* the renderer waits here for read bricks */
    vxl_brick_key *want;
    uint32_t n_want, want_cap, next;
    vxl_loaded_brick *done; /* a ring of queue_bricks */
    uint32_t done_head, done_count;
    uint8_t **spare;        /* staging buffers not in use */
    uint32_t n_spare, allocated, queue_bricks;
    uint32_t busy;          /* threads reading now */
    vxl_brick_key reading[MAX_THREADS]; /* what they read (the first busy entries, unordered) */
    vxl_brick_key *coming;  /* MAX_THREADS + queue_bricks: scratch of vxl_loader_want */
    int stop, rc;
    uint64_t gen;           /* counts wanted lists: a read's failure counts only for its own list */
    vxl_err err;            /* the first failed read, until the renderer takes it */
};

static uint32_t clampu(int64_t i, uint32_t n) { return i < 0 ? 0 : i >= (int64_t)n ? n - 1 : (uint32_t)i; }

/* Reads brick k with its ghost into dst (edge^3 voxels): the part inside
 * the level from the source, packed at dst's start, then spread in place to
 * its place in the brick, the voxels outside the level repeating the
 * level's edge voxels. Per axis the brick's voxel d (0..edge-1) comes from
 * the box's voxel d - a[ax] for d in [a, b), the first below a and the last
 * from b on; a is 0 or 1 and the box is at most edge wide, so every box row
 * lies at or before its brick row: moving rows from the last to the first
 * never overwrites a box row still to be moved. */
static int read_brick(vxl_brick_loader *l, vxl_brick_key k, uint8_t *dst, vxl_err *e)
{
    const vxl_brick_source *s = l->src;
    if (k.level >= s->n_levels) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "level %u of %u", k.level, s->n_levels);
    const uint32_t *dims = s->level_dims[k.level], P = l->brick, E = l->edge, bpv = l->bpv;
    const uint32_t grid[3] = {(dims[0] + P - 1) / P, (dims[1] + P - 1) / P, (dims[2] + P - 1) / P};
    const uint32_t c[3] = {k.brick % grid[0], k.brick / grid[0] % grid[1], k.brick / (grid[0] * grid[1])};
    uint32_t lo[3], size[3], a[3], b[3];
    for (int ax = 0; ax < 3; ax++) {
        lo[ax] = clampu((int64_t)c[ax] * P - VXL_PAGE_GHOST, dims[ax]);
        size[ax] = clampu((int64_t)c[ax] * P + P, dims[ax]) - lo[ax] + 1;
        a[ax] = (uint32_t)(lo[ax] + VXL_PAGE_GHOST - (int64_t)c[ax] * P); /* 1 at the level's start, else 0 */
        b[ax] = a[ax] + size[ax];
    }
    if (c[0] >= grid[0] || c[1] >= grid[1] || c[2] >= grid[2] || b[0] > E || b[1] > E || b[2] > E)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "brick %u is outside level %u's grid", k.brick, k.level);
    int rc = s->ops->read(l->src, k.level, lo, size, dst, e);
    if (rc) return rc;
    if (a[0] == 0 && a[1] == 0 && a[2] == 0 && b[0] == E && b[1] == E && b[2] == E) return VXL_OK; /* in place */
    const size_t row = (size_t)size[0] * bpv;
    for (uint32_t z = E; z-- > 0;) {
        const uint32_t sz = z < a[2] ? 0 : z >= b[2] ? size[2] - 1 : z - a[2];
        for (uint32_t y = E; y-- > 0;) {
            const uint32_t sy = y < a[1] ? 0 : y >= b[1] ? size[1] - 1 : y - a[1];
            uint8_t *out = dst + ((size_t)y + (size_t)E * z) * E * bpv;
            memmove(out + (size_t)a[0] * bpv, dst + ((size_t)sy + (size_t)size[1] * sz) * row, row);
            for (uint32_t x = 0; x < a[0]; x++) memcpy(out + (size_t)x * bpv, out + (size_t)a[0] * bpv, bpv);
            for (uint32_t x = b[0]; x < E; x++) memcpy(out + (size_t)x * bpv, out + (size_t)(b[0] - 1) * bpv, bpv);
        }
    }
    return VXL_OK;
}

/* A staging buffer, or NULL when all queue_bricks are in use (lock held). */
static uint8_t *buffer(vxl_brick_loader *l)
{
    if (l->n_spare) return l->spare[--l->n_spare];
    if (l->allocated == l->queue_bricks) return NULL;
    uint8_t *b = malloc(l->brick_bytes);
    if (b) l->allocated++;
    return b;
}

static int can_allocate(const vxl_brick_loader *l) { return l->n_spare || l->allocated < l->queue_bricks; }

static int same_key(vxl_brick_key a, vxl_brick_key b) { return a.level == b.level && a.brick == b.brick; }

static int key_order(const void *a, const void *b)
{
    const vxl_brick_key *x = a, *y = b;
    if (x->level != y->level) return x->level < y->level ? -1 : 1;
    return x->brick < y->brick ? -1 : x->brick > y->brick;
}

/* The keys being read or arrived untaken, sorted (lock held), into l->coming:
 * the renderer asks again for every brick it has not uploaded yet, so a new
 * wanted list names those too; vxl_loader_want leaves them out, as reading
 * them twice would only cost time. */
static uint32_t sort_coming(vxl_brick_loader *l)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < l->busy; i++) l->coming[n++] = l->reading[i];
    for (uint32_t i = 0; i < l->done_count; i++) l->coming[n++] = l->done[(l->done_head + i) % l->queue_bricks].key;
    qsort(l->coming, n, sizeof *l->coming, key_order);
    return n;
}

static void *loop(void *p)
{
    vxl_brick_loader *l = p;
    vxl_mutex_lock(&l->lock);
    for (;;) {
        while (!l->stop && (l->next == l->n_want || !can_allocate(l) || l->rc)) vxl_cond_wait(&l->work, &l->lock);
        if (l->stop) break;
        const vxl_brick_key k = l->want[l->next++];
        const uint64_t gen = l->gen;
        uint8_t *buf = buffer(l);
        if (!buf) {
            l->rc = vxl_fail(&l->err, VXL_ERR_NO_MEMORY, "out of memory for a %zu-byte brick staging buffer", l->brick_bytes);
            vxl_cond_broadcast(&l->arrived);
            continue;
        }
        l->reading[l->busy++] = k;
        vxl_mutex_unlock(&l->lock);
        vxl_err e = {0};
        int rc = read_brick(l, k, buf, &e);
        vxl_mutex_lock(&l->lock);
        for (uint32_t i = 0; i < l->busy; i++) /* drop k from what is being read */
            if (same_key(l->reading[i], k)) {
                l->reading[i] = l->reading[--l->busy];
                break;
            }
        if (rc) {
            l->spare[l->n_spare++] = buf;
            /* A read the frame that wanted it no longer waits for (a newer
             * list, or its error already reported) fails nobody: the next
             * frame asks for the brick again if it needs it. */
            if (!l->rc && gen == l->gen) { /* the first error; another thread's is the same disk's */
                l->rc = rc;
                l->err = e;
            }
        } else {
            l->done[(l->done_head + l->done_count++) % l->queue_bricks] = (vxl_loaded_brick){k, buf};
        }
        vxl_cond_broadcast(&l->arrived);
    }
    vxl_mutex_unlock(&l->lock);
    return NULL;
}

static void free_loader(vxl_brick_loader *l)
{
    for (uint32_t i = 0; i < l->done_count; i++) free(l->done[(l->done_head + i) % l->queue_bricks].texels);
    for (uint32_t i = 0; i < l->n_spare; i++) free(l->spare[i]);
    free(l->done);
    free(l->spare);
    free(l->coming);
    free(l->want);
    free(l);
}

/* n, else one thread per core (the renderer's thread waits or uploads
 * meanwhile); at most MAX_THREADS and the queue's buffers. */
static uint32_t threads_for(uint32_t n, uint32_t queue_bricks)
{
    if (!n) {
        const unsigned cores = vxl_cpu_count();
        n = cores > MAX_THREADS ? MAX_THREADS : cores;
    }
    if (n > MAX_THREADS) n = MAX_THREADS;
    return n < queue_bricks ? n : queue_bricks;
}

int vxl_loader_start(vxl_brick_loader **out, vxl_brick_source *src, uint32_t brick, uint32_t queue_bricks, vxl_err *e)
{
    return vxl_loader_start_threads(out, src, brick, queue_bricks, 0, e);
}

int vxl_loader_start_threads(vxl_brick_loader **out, vxl_brick_source *src, uint32_t brick, uint32_t queue_bricks,
                             uint32_t n_threads, vxl_err *e)
{
    *out = NULL;
    vxl_brick_loader *l = calloc(1, sizeof *l);
    if (!l) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the brick loader");
    l->src = src;
    l->brick = brick;
    l->edge = brick + 2 * VXL_PAGE_GHOST;
    l->bpv = src->texture_bits / 8;
    l->brick_bytes = (size_t)l->edge * l->edge * l->edge * l->bpv;
    l->queue_bricks = queue_bricks ? queue_bricks : 1;
    l->done = calloc(l->queue_bricks, sizeof *l->done);
    l->spare = calloc(l->queue_bricks, sizeof *l->spare);
    l->coming = calloc((size_t)l->queue_bricks + MAX_THREADS, sizeof *l->coming);
    if (!l->done || !l->spare || !l->coming) {
        free_loader(l);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the brick loader's queue");
    }
    vxl_mutex_init(&l->lock);
    vxl_cond_init(&l->work);
    vxl_cond_init(&l->arrived);
    const uint32_t want = threads_for(n_threads, l->queue_bricks);
    while (l->n_threads < want && !vxl_thread_start(&l->threads[l->n_threads], loop, l)) l->n_threads++;
    if (!l->n_threads) {
        vxl_cond_destroy(&l->work);
        vxl_cond_destroy(&l->arrived);
        vxl_mutex_destroy(&l->lock);
        free_loader(l);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "cannot start the brick loader thread");
    }
    *out = l; /* fewer threads than wanted (a thread limit) still load, more slowly */
    return VXL_OK;
}

void vxl_loader_stop(vxl_brick_loader *l)
{
    if (!l) return;
    vxl_mutex_lock(&l->lock);
    l->stop = 1;
    vxl_cond_broadcast(&l->work);
    vxl_mutex_unlock(&l->lock);
    for (uint32_t i = 0; i < l->n_threads; i++) vxl_thread_join(l->threads[i]); /* after the reads in progress */
    vxl_cond_destroy(&l->work);
    vxl_cond_destroy(&l->arrived);
    vxl_mutex_destroy(&l->lock);
    free_loader(l);
}

uint64_t vxl_loader_bytes(const vxl_brick_loader *l)
{
    return l ? (uint64_t)l->queue_bricks * l->brick_bytes : 0;
}

int vxl_loader_want(vxl_brick_loader *l, const vxl_brick_key *keys, uint32_t n, vxl_err *e)
{
    vxl_mutex_lock(&l->lock);
    int rc = VXL_OK;
    if (n > l->want_cap) {
        vxl_brick_key *w = realloc(l->want, (size_t)n * sizeof *w);
        if (w) {
            l->want = w;
            l->want_cap = n;
        } else {
            rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for a list of %u wanted bricks", n);
        }
    }
    if (!rc) {
        const uint32_t c = sort_coming(l);
        uint32_t m = 0;
        for (uint32_t i = 0; i < n; i++)
            if (!c || !bsearch(&keys[i], l->coming, c, sizeof *l->coming, key_order)) l->want[m++] = keys[i];
        l->n_want = m;
        l->next = 0;
        l->gen++;
        vxl_cond_broadcast(&l->work);
    }
    vxl_mutex_unlock(&l->lock);
    return rc;
}

uint32_t vxl_loader_take(vxl_brick_loader *l, vxl_loaded_brick *out, uint32_t max, int wait)
{
    vxl_mutex_lock(&l->lock);
    while (wait && !l->done_count && !l->rc && (l->busy || (l->next < l->n_want && can_allocate(l))))
        vxl_cond_wait(&l->arrived, &l->lock);
    uint32_t n = 0;
    for (; n < max && l->done_count; n++, l->done_count--) {
        out[n] = l->done[l->done_head];
        l->done_head = (l->done_head + 1) % l->queue_bricks;
    }
    vxl_mutex_unlock(&l->lock);
    return n;
}

void vxl_loader_recycle(vxl_brick_loader *l, const vxl_loaded_brick *b, uint32_t n)
{
    vxl_mutex_lock(&l->lock);
    for (uint32_t i = 0; i < n; i++) l->spare[l->n_spare++] = b[i].texels;
    if (n) vxl_cond_broadcast(&l->work);
    vxl_mutex_unlock(&l->lock);
}

int vxl_loader_error(vxl_brick_loader *l, vxl_err *e)
{
    vxl_mutex_lock(&l->lock);
    const int rc = l->rc;
    if (rc) {
        vxl_fail(e, rc, "%s", l->err.msg);
        l->rc = 0;
        l->n_want = l->next = 0; /* the next frame says what it still wants */
        l->gen++;
    }
    vxl_mutex_unlock(&l->lock);
    return rc;
}
