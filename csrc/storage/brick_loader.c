/* brick_loader.c - the streaming loader thread (brick_loader.h): a wanted
 * list the renderer replaces each frame, a bounded queue of read bricks,
 * and the first read error, all behind one mutex. */
#include "brick_loader.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "paging.h"

struct vxl_brick_loader {
    vxl_brick_source *src;
    uint32_t brick, edge, bpv;
    size_t brick_bytes;
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t work;    /* the loader waits here for wanted bricks or free buffers */
    pthread_cond_t arrived; /* the renderer waits here for read bricks */
    vxl_brick_key *want;
    uint32_t n_want, want_cap, next;
    vxl_loaded_brick *done; /* a ring of queue_bricks */
    uint32_t done_head, done_count;
    uint8_t **spare;        /* staging buffers not in use */
    uint32_t n_spare, allocated, queue_bricks;
    uint8_t *read_buf;      /* the box as the source returns it, before the ghost is filled in */
    int busy, stop, rc;
    vxl_err err;            /* the first failed read, until the renderer takes it */
};

static uint32_t clampu(int64_t i, uint32_t n) { return i < 0 ? 0 : i >= (int64_t)n ? n - 1 : (uint32_t)i; }

/* Reads brick k with its ghost into dst: the part inside the level from the
 * source, the rest repeating the level's edge voxels. */
static int read_brick(vxl_brick_loader *l, vxl_brick_key k, uint8_t *dst, vxl_err *e)
{
    const vxl_brick_source *s = l->src;
    if (k.level >= s->n_levels) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "level %u of %u", k.level, s->n_levels);
    const uint32_t *dims = s->level_dims[k.level], P = l->brick, E = l->edge, bpv = l->bpv;
    const uint32_t grid[3] = {(dims[0] + P - 1) / P, (dims[1] + P - 1) / P, (dims[2] + P - 1) / P};
    const uint32_t c[3] = {k.brick % grid[0], k.brick / grid[0] % grid[1], k.brick / (grid[0] * grid[1])};
    uint32_t lo[3], size[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = clampu((int64_t)c[a] * P - VXL_PAGE_GHOST, dims[a]);
        size[a] = clampu((int64_t)c[a] * P + P, dims[a]) - lo[a] + 1;
    }
    int rc = s->ops->read(l->src, k.level, lo, size, l->read_buf, e);
    if (rc) return rc;
    for (uint32_t z = 0; z < E; z++) {
        const uint32_t sz = clampu((int64_t)c[2] * P + z - VXL_PAGE_GHOST, dims[2]) - lo[2];
        for (uint32_t y = 0; y < E; y++) {
            const uint32_t sy = clampu((int64_t)c[1] * P + y - VXL_PAGE_GHOST, dims[1]) - lo[1];
            const uint8_t *row = l->read_buf + ((size_t)sy + (size_t)size[1] * sz) * size[0] * bpv;
            uint8_t *out = dst + ((size_t)y + (size_t)E * z) * E * bpv;
            for (uint32_t x = 0; x < E; x++) {
                const uint32_t sx = clampu((int64_t)c[0] * P + x - VXL_PAGE_GHOST, dims[0]) - lo[0];
                memcpy(out + (size_t)x * bpv, row + (size_t)sx * bpv, bpv);
            }
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

static void *loop(void *p)
{
    vxl_brick_loader *l = p;
    pthread_mutex_lock(&l->lock);
    for (;;) {
        while (!l->stop && (l->next == l->n_want || !can_allocate(l) || l->rc)) pthread_cond_wait(&l->work, &l->lock);
        if (l->stop) break;
        const vxl_brick_key k = l->want[l->next++];
        uint8_t *buf = buffer(l);
        if (!buf) {
            l->rc = vxl_fail(&l->err, VXL_ERR_NO_MEMORY, "out of memory for a %zu-byte brick staging buffer", l->brick_bytes);
            pthread_cond_broadcast(&l->arrived);
            continue;
        }
        l->busy = 1;
        pthread_mutex_unlock(&l->lock);
        vxl_err e = {0};
        int rc = read_brick(l, k, buf, &e);
        pthread_mutex_lock(&l->lock);
        l->busy = 0;
        if (rc) {
            l->spare[l->n_spare++] = buf;
            l->rc = rc;
            l->err = e;
        } else {
            l->done[(l->done_head + l->done_count++) % l->queue_bricks] = (vxl_loaded_brick){k, buf};
        }
        pthread_cond_broadcast(&l->arrived);
    }
    pthread_mutex_unlock(&l->lock);
    return NULL;
}

static void free_loader(vxl_brick_loader *l)
{
    for (uint32_t i = 0; i < l->done_count; i++) free(l->done[(l->done_head + i) % l->queue_bricks].texels);
    for (uint32_t i = 0; i < l->n_spare; i++) free(l->spare[i]);
    free(l->done);
    free(l->spare);
    free(l->want);
    free(l->read_buf);
    free(l);
}

int vxl_loader_start(vxl_brick_loader **out, vxl_brick_source *src, uint32_t brick, uint32_t queue_bricks, vxl_err *e)
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
    l->read_buf = malloc(l->brick_bytes);
    if (!l->done || !l->spare || !l->read_buf) {
        free_loader(l);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the brick loader's queue");
    }
    pthread_mutex_init(&l->lock, NULL);
    pthread_cond_init(&l->work, NULL);
    pthread_cond_init(&l->arrived, NULL);
    if (pthread_create(&l->thread, NULL, loop, l)) {
        pthread_cond_destroy(&l->work);
        pthread_cond_destroy(&l->arrived);
        pthread_mutex_destroy(&l->lock);
        free_loader(l);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "cannot start the brick loader thread");
    }
    *out = l;
    return VXL_OK;
}

void vxl_loader_stop(vxl_brick_loader *l)
{
    if (!l) return;
    pthread_mutex_lock(&l->lock);
    l->stop = 1;
    pthread_cond_broadcast(&l->work);
    pthread_mutex_unlock(&l->lock);
    pthread_join(l->thread, NULL); /* after the read in progress, if any */
    pthread_cond_destroy(&l->work);
    pthread_cond_destroy(&l->arrived);
    pthread_mutex_destroy(&l->lock);
    free_loader(l);
}

uint64_t vxl_loader_bytes(const vxl_brick_loader *l)
{
    return l ? ((uint64_t)l->queue_bricks + 1) * l->brick_bytes : 0;
}

int vxl_loader_want(vxl_brick_loader *l, const vxl_brick_key *keys, uint32_t n, vxl_err *e)
{
    pthread_mutex_lock(&l->lock);
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
        if (n) memcpy(l->want, keys, (size_t)n * sizeof *keys);
        l->n_want = n;
        l->next = 0;
        pthread_cond_broadcast(&l->work);
    }
    pthread_mutex_unlock(&l->lock);
    return rc;
}

uint32_t vxl_loader_take(vxl_brick_loader *l, vxl_loaded_brick *out, uint32_t max, int wait)
{
    pthread_mutex_lock(&l->lock);
    while (wait && !l->done_count && !l->rc && (l->busy || (l->next < l->n_want && can_allocate(l))))
        pthread_cond_wait(&l->arrived, &l->lock);
    uint32_t n = 0;
    for (; n < max && l->done_count; n++, l->done_count--) {
        out[n] = l->done[l->done_head];
        l->done_head = (l->done_head + 1) % l->queue_bricks;
    }
    pthread_mutex_unlock(&l->lock);
    return n;
}

void vxl_loader_recycle(vxl_brick_loader *l, const vxl_loaded_brick *b, uint32_t n)
{
    pthread_mutex_lock(&l->lock);
    for (uint32_t i = 0; i < n; i++) l->spare[l->n_spare++] = b[i].texels;
    if (n) pthread_cond_broadcast(&l->work);
    pthread_mutex_unlock(&l->lock);
}

int vxl_loader_error(vxl_brick_loader *l, vxl_err *e)
{
    pthread_mutex_lock(&l->lock);
    const int rc = l->rc;
    if (rc) {
        vxl_fail(e, rc, "%s", l->err.msg);
        l->rc = 0;
        l->n_want = l->next = 0; /* the next frame says what it still wants */
    }
    pthread_mutex_unlock(&l->lock);
    return rc;
}
