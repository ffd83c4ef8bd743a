/* storage_streamed.c - sparse storage of a streamed volume
 * (docs/streaming.md): the voxels stay in the volume's brick source and the
 * GL side holds a pool of page bricks of any level, read on demand by the
 * loader thread (brick_loader.c) and uploaded here, on the renderer's
 * thread. The page plan of every level and the skipping grid come from the
 * source's min-max index, so no pass over the voxels is made and no CPU
 * copy of them is kept: the CPU holds the index, the page tables and the
 * loader's bounded staging queue.
 *
 * A frame picks its level as sparse storage does (the finest whose visible
 * bricks fit the budget) and then either waits until every visible brick of
 * that level is resident (F12), or (progressive, the viewport) waits only
 * for the coarsest level's visible bricks, asks for those of every finer
 * level down to the chosen one (coarser first, each nearest to the eye
 * first), and draws whatever has arrived: the frame's page table is its
 * level's, in which a visible brick not read yet stands in for its finest
 * resident coarser ancestor (shader define PAGED_MIXED, lib/common.glsl),
 * so each brick refines as it arrives. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "brick_loader.h"
#include "clock.h"
#include "budget.h"
#include "mat4.h"
#include "storage.h"

#define STREAM_QUEUE_BYTES (64ull << 20) /* the loader's staging queue at most (or a 16th of the budget) */


typedef struct vxl_stream {
    vxl_brick_source *src;   /* retained: the caller may destroy the volume */
    vxl_brick_loader *loader;
    uint64_t first[VXL_LOD_LEVELS + 1]; /* level k's bricks are first[k] .. first[k+1] - 1 of the arrays below */
    int32_t *slot_of;        /* per brick: its pool slot, -1 when not resident */
    uint8_t *need;           /* per brick: the last frame can read it */
    float *entries;          /* per brick: its page entry (RGBA, as paged.c's) */
    float *mixed;            /* the drawn level's entries with ancestors standing in (level 0's count) */
    GLuint page_tex;         /* `mixed` on the GPU: the one page table drawn */
    int dirty;               /* an entry, the visible set or the level changed since `mixed` was made */
    uint32_t mixed_level;    /* the level `mixed` is of */
    uint32_t coarsest_drawn; /* the coarsest level a visible brick of `mixed` reads */
    uint32_t needed[VXL_LOD_LEVELS], constant[VXL_LOD_LEVELS];
    uint64_t need_key;       /* the occupancy, reach and `all` need was derived for */
    int need_valid;
    uint32_t target, coarse; /* the frame's level (budget) and the coarsest it keeps (progressive: the
                                coarsest level, waited for, and every level between, for stepwise refinement) */
    uint64_t missing_target, missing_coarse;
    uint32_t capacity, slots[3];
    uint64_t *slot_brick;    /* per slot: the brick + 1 it holds, 0 free */
    uint32_t hand;           /* where the search for a free slot goes on */
    uint32_t queue_bricks;
    vxl_loaded_brick *arrived;
    int uploaded;            /* bricks uploaded since the pool generation last moved */
    uint64_t read_mark;      /* the source's bytes_read at the end of the last frame */
    uint32_t refine_pending, stream_level;
    uint64_t bytes_read;
    double load_ms;
} vxl_stream;

static double now_ms(void) { return vxl_monotonic_s() * 1e3; }

static uint32_t clamp_voxel(int64_t i, uint32_t n) { return i < 0 ? 0 : i >= (int64_t)n ? n - 1 : (uint32_t)i; }

/* Min and max of the level-0 voxels lo..hi (inclusive, inside the volume)
 * from the index: the index bricks overlapping the box, whose one-voxel
 * apron adds the ghost of a box that starts and ends on index bricks. */
static void index_range(const vxl_brick_source *s, const uint32_t lo[3], const uint32_t hi[3], float *mn, float *mx)
{
    const uint32_t b = s->index_brick;
    uint32_t l[3], h[3];
    for (int a = 0; a < 3; a++) {
        l[a] = clamp_voxel(lo[a] / b, s->index_dims[a]);
        h[a] = clamp_voxel(hi[a] / b, s->index_dims[a]);
    }
    float a0 = INFINITY, a1 = -INFINITY;
    for (uint32_t z = l[2]; z <= h[2]; z++)
        for (uint32_t y = l[1]; y <= h[1]; y++)
            for (uint32_t x = l[0]; x <= h[0]; x++) {
                const float *m = s->minmax + 2 * (x + (size_t)s->index_dims[0] * (y + (size_t)s->index_dims[1] * z));
                a0 = m[0] < a0 ? m[0] : a0;
                a1 = m[1] > a1 ? m[1] : a1;
            }
    *mn = a0;
    *mx = a1;
}

/* The page plan of level k from the index alone: a brick is constant when
 * the level-0 voxels under it and its ghost hold one value (a coarser voxel
 * is assumed to lie within the range of the voxels it covers, as box and
 * nearest downsampling give); low is their minimum. Level 0 with an index
 * brick dividing the page brick finds exactly paging.c's constant bricks. */
static int pages_from_index(vxl_pages *pg, const vxl_brick_source *s, uint32_t k, uint32_t brick, vxl_err *e)
{
    memset(pg, 0, sizeof *pg);
    pg->brick = brick;
    pg->bytes_per_voxel = s->texture_bits / 8;
    for (int a = 0; a < 3; a++) pg->grid[a] = (s->level_dims[k][a] + brick - 1) / brick;
    const uint64_t n = vxl_page_count(pg);
    pg->data_index = malloc(n * sizeof *pg->data_index);
    pg->low = malloc(n * sizeof *pg->low);
    if (!pg->data_index || !pg->low) {
        vxl_pages_free(pg);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the page table of level %u", k);
    }
    const int64_t scale = 1ll << k, widen = k ? scale : 0; /* level 0: the index's apron is the ghost */
    for (uint64_t i = 0; i < n; i++) {
        const uint64_t c[3] = {i % pg->grid[0], i / pg->grid[0] % pg->grid[1], i / ((uint64_t)pg->grid[0] * pg->grid[1])};
        uint32_t lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = clamp_voxel((int64_t)c[a] * brick * scale - widen, s->level_dims[0][a]);
            hi[a] = clamp_voxel(((int64_t)c[a] * brick + brick) * scale - 1 + widen, s->level_dims[0][a]);
        }
        float mn, mx;
        index_range(s, lo, hi, &mn, &mx);
        pg->low[i] = mn;
        pg->data_index[i] = mn == mx ? -1 : (int32_t)pg->n_data++;
    }
    return VXL_OK;
}

/* The skipping grid (bricks of `size`) from the index: the same grid as
 * vxl_bricks_minmax_cpu when the index bricks are that size. */
static int grid_from_index(vxl_bricks *b, const vxl_brick_source *s, uint32_t size, vxl_err *e)
{
    memset(b, 0, sizeof *b);
    b->size = size;
    for (int a = 0; a < 3; a++) b->dims[a] = (s->level_dims[0][a] + size - 1) / size;
    const size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    if (!(b->minmax = malloc(n * 2 * sizeof(float)))) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for the brick grid");
    for (size_t i = 0; i < n; i++) {
        const size_t c[3] = {i % b->dims[0], i / b->dims[0] % b->dims[1], i / ((size_t)b->dims[0] * b->dims[1])};
        uint32_t lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = (uint32_t)(c[a] * size);
            hi[a] = clamp_voxel((int64_t)c[a] * size + size - 1, s->level_dims[0][a]);
        }
        index_range(s, lo, hi, &b->minmax[2 * i], &b->minmax[2 * i + 1]);
    }
    return VXL_OK;
}

static uint32_t page_brick_of(const vxl_storage_state *st)
{
    return st->page_brick_request ? st->page_brick_request : VXL_DEFAULT_PAGE_BRICK;
}

static uint64_t brick_bytes(const vxl_pages *pg)
{
    const uint64_t e = vxl_page_edge(pg);
    return e * e * e * pg->bytes_per_voxel;
}

/* Staging buffers: 64 MiB or a 16th of the budget, at least 2 bricks. */
static uint32_t queue_bricks_for(const vxl_storage_state *st, const vxl_pages *pg)
{
    uint64_t bytes = st->gpu->budget / 16 < STREAM_QUEUE_BYTES ? st->gpu->budget / 16 : STREAM_QUEUE_BYTES;
    uint64_t n = bytes / brick_bytes(pg);
    return n < 2 ? 2 : n > 4096 ? 4096 : (uint32_t)n;
}

/* What the storage holds whatever the pool: the loader's staging queue
 * (vxl_loader_bytes: its threads read into those buffers), every level's
 * entries on the CPU, and the drawn table at most level 0's size twice
 * (`mixed` on the CPU, its texture on the GPU); 16 bytes an entry. */
static uint64_t fixed_bytes(const vxl_pages *levels, uint32_t n_levels, uint32_t queue)
{
    uint64_t b = (uint64_t)queue * brick_bytes(&levels[0]) + 2 * vxl_page_count(&levels[0]) * 16;
    for (uint32_t k = 0; k < n_levels; k++) b += vxl_page_count(&levels[k]) * 16;
    return b;
}

/* Bytes of a pool of n slots (UINT64_MAX: over the texture limit). */
static uint64_t pool_bytes_for(const vxl_storage_state *st, const vxl_pages *pg, uint32_t n, uint32_t slots[3])
{
    const uint64_t e = vxl_page_edge(pg);
    if (!vxl_pool_layout(st, n, (uint32_t)e, slots)) return UINT64_MAX;
    return slots[0] * e * slots[1] * e * slots[2] * e * pg->bytes_per_voxel;
}

static int plan_streamed(vxl_storage_state *st, const vxl_volume *v, uint32_t asked, vxl_storage_plan *out)
{
    memset(out, 0, sizeof *out);
    vxl_err *e = &st->gpu->err;
    const vxl_brick_source *s = v->source;
    if (!s) return vxl_fail(e, VXL_ERR_STATE, "the volume is not streamed");
    if (asked != VXL_STORAGE_AUTO && asked != VXL_STORAGE_SPARSE)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "storage %s needs every voxel in memory, and this volume is streamed (read on demand): use "
                        "storage auto or sparse, or load it with streaming off",
                        vxl_storage_name(asked));
    if (s->texture_bits != v->texture_bits || !s->n_levels || s->n_levels > VXL_SOURCE_MAX_LEVELS || !s->minmax ||
        !s->index_brick)
        return vxl_fail(e, VXL_ERR_STATE, "the volume's brick source has no index or levels in its texture format");
    for (int a = 0; a < 3; a++) /* the index and levels are read unchecked from here on */
        if (s->level_dims[0][a] != v->dims[a] || !v->dims[a] ||
            s->index_dims[a] != (v->dims[a] + s->index_brick - 1) / s->index_brick)
            return vxl_fail(e, VXL_ERR_STATE, "the volume's brick source does not match its %ux%ux%u voxels", v->dims[0],
                            v->dims[1], v->dims[2]);
    for (uint32_t k = 1; k < s->n_levels; k++)
        for (int a = 0; a < 3; a++)
            if (!s->level_dims[k][a] || s->level_dims[k][a] > s->level_dims[k - 1][a])
                return vxl_fail(e, VXL_ERR_STATE, "level %u of the volume's brick source is not coarser than level %u", k,
                                k - 1);
    const uint32_t brick = page_brick_of(st);
    if (brick != 8 && brick != 16 && brick != 32 && brick != 64)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "page brick %u: use 8, 16, 32 or 64 voxels", brick);
    out->mode = VXL_STORAGE_SPARSE;
    out->n_levels = s->n_levels < VXL_LOD_LEVELS ? s->n_levels : VXL_LOD_LEVELS;
    int rc = VXL_OK;
    for (uint32_t k = 0; k < out->n_levels && !rc; k++) {
        rc = pages_from_index(&out->levels[k], s, k, brick, e);
        memcpy(out->level_dims[k], s->level_dims[k], sizeof out->level_dims[k]);
    }
    if (!rc) rc = grid_from_index(&out->bricks, s, vxl_skip_brick_size(), e);
    if (!rc) {
        uint32_t slots[3];
        const uint64_t fixed = fixed_bytes(out->levels, out->n_levels, queue_bricks_for(st, &out->levels[0]));
        const uint64_t pool = pool_bytes_for(st, &out->levels[0], 1, slots);
        rc = vxl_budget_ask(st->gpu->budget, NULL, VXL_HOLD_STORAGE, fixed + pool, e, NULL,
                            "the page tables and staging queue of a streamed %ux%ux%u volume", v->dims[0], v->dims[1],
                            v->dims[2]);
    }
    if (rc) vxl_storage_plan_free(out);
    return rc;
}

static void release_streamed(vxl_storage_state *st)
{
    vxl_stream *s = st->stream;
    if (s) {
        vxl_loader_stop(s->loader); /* joined: no read is in progress past here */
        if (s->page_tex) st->gpu->gl.DeleteTextures(1, &s->page_tex);
        free(s->slot_of);
        free(s->need);
        free(s->entries);
        free(s->mixed);
        free(s->slot_brick);
        free(s->arrived);
        vxl_brick_source_free(s->src);
        free(s);
        st->stream = NULL;
    }
    st->page_tex = 0; /* the page table above */
    vxl_paged_release(st);
}

static void set_absent(const vxl_pages *pg, uint64_t i, float *pe)
{
    pe[0] = pe[1] = pe[2] = 0;
    pe[3] = pg->low[i]; /* constant: its value; not resident: its minimum, transparent where it is not visible */
}

static int install_streamed(vxl_storage_state *st, const vxl_volume *v, vxl_storage_plan *plan)
{
    memcpy(st->levels, plan->levels, sizeof st->levels);
    memcpy(st->level_dims, plan->level_dims, sizeof st->level_dims);
    st->n_levels = plan->n_levels;
    st->level = 0;
    st->mode = plan->mode;
    st->volume_bytes = 0;
    memset(plan->levels, 0, sizeof plan->levels);
    vxl_stream *s = calloc(1, sizeof *s);
    if (!s) return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the streamed storage");
    st->stream = s;
    s->src = v->source;
    vxl_brick_source_retain(s->src);
    for (uint32_t k = 0; k < st->n_levels; k++) s->first[k + 1] = s->first[k] + vxl_page_count(&st->levels[k]);
    const uint64_t n = s->first[st->n_levels];
    s->queue_bricks = queue_bricks_for(st, &st->levels[0]);
    s->slot_of = malloc(n * sizeof *s->slot_of);
    s->need = calloc(n ? n : 1, 1);
    s->entries = malloc(n * 4 * sizeof *s->entries);
    s->mixed = malloc((n ? vxl_page_count(&st->levels[0]) : 1) * 4 * sizeof *s->mixed);
    s->arrived = malloc(s->queue_bricks * sizeof *s->arrived);
    if (!s->slot_of || !s->need || !s->entries || !s->mixed || !s->arrived)
        return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the page tables of %llu bricks",
                        (unsigned long long)n);
    for (uint32_t k = 0; k < st->n_levels; k++) {
        const vxl_pages *pg = &st->levels[k];
        for (uint64_t i = 0; i < vxl_page_count(pg); i++) {
            s->slot_of[s->first[k] + i] = -1;
            set_absent(pg, i, s->entries + 4 * (s->first[k] + i));
            s->constant[k] += pg->data_index[i] < 0;
        }
    }
    s->dirty = 1;
    s->read_mark = __atomic_load_n(&s->src->bytes_read, __ATOMIC_RELAXED);
    return vxl_loader_start(&s->loader, s->src, st->levels[0].brick, s->queue_bricks, &st->gpu->err);
}

static uint32_t level_of(const vxl_stream *s, uint64_t flat)
{
    uint32_t k = 0;
    while (flat >= s->first[k + 1]) k++;
    return k;
}

/* Whether the frame cannot spare brick `flat`: one it reads at its level or
 * at the level it waits for. */
static int pinned(const vxl_stream *s, uint64_t flat)
{
    if (!s->need[flat]) return 0;
    const uint32_t k = level_of(s, flat);
    return k >= s->target && k <= s->coarse;
}

/* A pool slot for a new brick: a free one, else one whose brick the frame
 * does not pin (taken out of its page table); -1 when every slot is pinned. */
static int64_t take_slot(vxl_storage_state *st)
{
    vxl_stream *s = st->stream;
    for (uint32_t t = 0; t < s->capacity; t++) {
        const uint32_t h = (s->hand + t) % s->capacity;
        const uint64_t held = s->slot_brick[h];
        if (held && pinned(s, held - 1)) continue;
        if (held) {
            const uint64_t flat = held - 1;
            const uint32_t k = level_of(s, flat);
            s->slot_of[flat] = -1;
            set_absent(&st->levels[k], flat - s->first[k], s->entries + 4 * flat);
            s->dirty = 1;
        }
        s->hand = (h + 1) % s->capacity;
        return h;
    }
    return -1;
}

/* Uploads an arrived brick into the pool, if the frame still reads it. */
static void upload_brick(vxl_storage_state *st, const vxl_loaded_brick *b)
{
    vxl_stream *s = st->stream;
    if (b->key.level >= st->n_levels || b->key.brick >= s->first[b->key.level + 1] - s->first[b->key.level]) return;
    const uint64_t flat = s->first[b->key.level] + b->key.brick;
    if (s->slot_of[flat] >= 0 || !s->need[flat]) return; /* a second copy, or no longer visible */
    const int64_t slot = take_slot(st);
    if (slot < 0) return;
    const vxl_pages *pg = &st->levels[b->key.level];
    const uint32_t e = vxl_page_edge(pg), bpv = pg->bytes_per_voxel;
    uint32_t o[3];
    vxl_slot_origin((uint32_t)slot, s->slots, e, o);
    vxl_gl *gl = &st->gpu->gl;
    gl->TexSubImage3D(GL_TEXTURE_3D, 0, (GLint)o[0], (GLint)o[1], (GLint)o[2], (GLsizei)e, (GLsizei)e, (GLsizei)e, GL_RED,
                      vxl_texel_type(bpv), b->texels);
    float *pe = s->entries + 4 * flat;
    for (int a = 0; a < 3; a++) pe[a] = (float)(o[a] + VXL_PAGE_GHOST);
    pe[3] = -1;
    s->slot_of[flat] = (int32_t)slot;
    s->slot_brick[slot] = flat + 1;
    s->dirty = 1;
    s->uploaded = 1;
    if (b->key.level == s->target && s->missing_target) s->missing_target--;
    if (b->key.level == s->coarse && s->coarse != s->target && s->missing_coarse) s->missing_coarse--;
}

/* Uploads what the loader has read (wait: blocks for at least one brick
 * unless the loader has nothing left to read); returns how many arrived, or
 * -1 with the loader's error set in the renderer's error slot. */
static int64_t drain(vxl_storage_state *st, int wait)
{
    vxl_stream *s = st->stream;
    vxl_gl *gl = &st->gpu->gl;
    int64_t total = 0;
    for (;;) {
        const uint32_t n = vxl_loader_take(s->loader, s->arrived, s->queue_bricks, wait && !total);
        if (n && st->pool_tex) {
            gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
            gl->BindTexture(GL_TEXTURE_3D, st->pool_tex);
            for (uint32_t i = 0; i < n; i++) upload_brick(st, &s->arrived[i]);
        }
        vxl_loader_recycle(s->loader, s->arrived, n);
        total += n;
        if (!n) break;
    }
    vxl_err le = {0};
    const int rc = vxl_loader_error(s->loader, &le);
    if (rc) {
        vxl_fail(&st->gpu->err, rc, "reading a brick of the streamed volume: %s", le.msg);
        return -1;
    }
    return total;
}

/* A pool of at least `required` slots. The first is exactly that: laid
 * out as sparse storage lays out the same bricks, it filters them the same
 * way to the last bit (llvmpipe's filter weights depend on the texture's
 * size). A grown one takes room to spare when the budget allows (twice the
 * old, a quarter over the need), and keeps its bricks: each is copied on
 * the GL side to where its slot lies in the new layout. */
static int ensure_pool(vxl_storage_state *st, uint32_t required, uint64_t fixed)
{
    vxl_stream *s = st->stream;
    if (st->pool_tex && s->capacity >= required) return VXL_OK;
    const vxl_pages *pg = &st->levels[0];
    uint32_t cap = st->pool_tex ? required + required / 4 + 8 : required, slots[3];
    if (cap < 2 * (uint64_t)s->capacity) cap = 2 * s->capacity;
    uint64_t bytes = pool_bytes_for(st, pg, cap, slots);
    if (bytes == UINT64_MAX || !vxl_budget_fits(st->gpu->budget, NULL, VXL_HOLD_STORAGE, bytes + fixed)) {
        cap = required ? required : 1;
        bytes = pool_bytes_for(st, pg, cap, slots);
    }
    if (bytes == UINT64_MAX)
        return vxl_fail(&st->gpu->err, VXL_ERR_LIMIT, "%u bricks of %u^3 voxels do not fit a pool texture within the 3D texture limit of %d",
                        cap, vxl_page_edge(pg), st->gpu->info.max_3d_texture_size);
    uint64_t *sb = calloc(cap, sizeof *sb);
    if (!sb) return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for a pool of %u bricks", cap);
    vxl_gl *gl = &st->gpu->gl;
    gl->GetError();
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    const GLuint old = st->pool_tex;
    st->pool_tex = vxl_texture_new(st->gpu, GL_TEXTURE_3D, GL_LINEAR);
    const uint32_t e = vxl_page_edge(pg), bpv = pg->bytes_per_voxel;
    gl->TexImage3D(GL_TEXTURE_3D, 0, (GLint)vxl_texel_internal_format(bpv), (GLsizei)(slots[0] * e), (GLsizei)(slots[1] * e),
                   (GLsizei)(slots[2] * e), 0, GL_RED, vxl_texel_type(bpv), NULL);
    for (uint32_t i = 0; i < s->capacity; i++) { /* slot i stays slot i, at its place in the new layout */
        if (!(sb[i] = s->slot_brick[i])) continue;
        uint32_t o[3], n[3];
        vxl_slot_origin(i, s->slots, e, o);
        vxl_slot_origin(i, slots, e, n);
        gl->CopyImageSubData(old, GL_TEXTURE_3D, 0, (GLint)o[0], (GLint)o[1], (GLint)o[2], st->pool_tex, GL_TEXTURE_3D, 0,
                             (GLint)n[0], (GLint)n[1], (GLint)n[2], (GLsizei)e, (GLsizei)e, (GLsizei)e);
        const uint64_t flat = sb[i] - 1;
        float *pe = s->entries + 4 * flat;
        for (int a = 0; a < 3; a++) pe[a] = (float)(n[a] + VXL_PAGE_GHOST);
        s->dirty = 1;
    }
    if (old) gl->DeleteTextures(1, &old);
    free(s->slot_brick);
    s->slot_brick = sb;
    s->capacity = cap;
    memcpy(s->slots, slots, sizeof slots);
    for (int a = 0; a < 3; a++) st->pool_dims[a] = slots[a] * e;
    st->pool_generation++;
    return vxl_gl_check(st->gpu, "allocating the streamed brick pool");
}

typedef struct ranked {
    double d;
    vxl_brick_key key;
} ranked;

static int by_distance(const void *a, const void *b)
{
    const double x = ((const ranked *)a)->d, y = ((const ranked *)b)->d;
    return x < y ? -1 : x > y;
}

/* The eye in voxel space, or 0 if unknown (probes). */
static int eye_voxel(const vxl_frame *f, double eye[3])
{
    double mv[16], inv[16], o[4] = {0, 0, 0, 1}, p[4];
    if (!f) return 0;
    vxl_mat4_mul(mv, f->view, f->model);
    if (!vxl_mat4_invert(inv, mv)) return 0;
    vxl_mat4_transform(inv, o, p);
    if (!(fabs(p[3]) > 1e-12)) return 0;
    for (int a = 0; a < 3; a++) eye[a] = p[a] / p[3];
    return 1;
}

static uint64_t count_missing(const vxl_stream *s, const vxl_pages *pg, uint32_t k)
{
    uint64_t m = 0;
    for (uint64_t i = 0; i < vxl_page_count(pg); i++) m += s->need[s->first[k] + i] && s->slot_of[s->first[k] + i] < 0;
    return m;
}

/* Asks the loader for the missing visible bricks, level by level from the
 * coarsest kept (waited for when progressive) to the frame's, each level's
 * nearest to the eye first (they cover the most of the screen). */
static int request(vxl_storage_state *st, const vxl_frame *f)
{
    vxl_stream *s = st->stream;
    uint64_t n = 0;
    for (uint32_t k = s->target; k <= s->coarse; k++) n += count_missing(s, &st->levels[k], k);
    ranked *list = malloc((n ? n : 1) * sizeof *list);
    vxl_brick_key *keys = malloc((n ? n : 1) * sizeof *keys);
    if (!list || !keys) {
        free(list);
        free(keys);
        return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the list of %llu wanted bricks", (unsigned long long)n);
    }
    double eye[3];
    const int has_eye = eye_voxel(f, eye);
    uint64_t m = 0;
    for (uint32_t k = s->coarse + 1; k-- > s->target;) {
        const vxl_pages *pg = &st->levels[k];
        const uint64_t start = m;
        for (uint64_t i = 0; i < vxl_page_count(pg); i++) {
            const uint64_t flat = s->first[k] + i;
            if (!s->need[flat] || s->slot_of[flat] >= 0 || m == n) continue;
            const double scale = (double)(1u << k) * pg->brick;
            const double c[3] = {(i % pg->grid[0] + 0.5) * scale, (i / pg->grid[0] % pg->grid[1] + 0.5) * scale,
                                 (i / ((uint64_t)pg->grid[0] * pg->grid[1]) + 0.5) * scale};
            double d = 0;
            for (int a = 0; a < 3 && has_eye; a++) d += (c[a] - eye[a]) * (c[a] - eye[a]);
            list[m++] = (ranked){d, {k, (uint32_t)i}};
        }
        qsort(list + start, m - start, sizeof *list, by_distance);
    }
    for (uint64_t i = 0; i < m; i++) keys[i] = list[i].key;
    int rc = vxl_loader_want(s->loader, keys, (uint32_t)m, &st->gpu->err);
    free(list);
    free(keys);
    return rc;
}

/* Waits until the level's visible bricks are resident (*missing reaches 0). */
static int wait_for(vxl_storage_state *st, const vxl_frame *f, const uint64_t *missing)
{
    int idle = 0;
    while (*missing) {
        const int64_t n = drain(st, 1);
        if (n < 0) return st->gpu->err.code;
        if (n) {
            idle = 0;
            continue;
        }
        /* the loader ran out of work with bricks still missing (dropped as
         * not visible by an earlier frame): ask again, once */
        if (idle++) return vxl_fail(&st->gpu->err, VXL_ERR_STATE, "the brick loader stopped with %llu visible bricks missing",
                                    (unsigned long long)*missing);
        int rc = request(st, f);
        if (rc) return rc;
    }
    return VXL_OK;
}

/* The page table of level L as drawn: each visible data brick of L that is
 * not resident reads its finest resident coarser ancestor instead. With
 * brick n at every level and s = 2^(k-L), ancestor bc = b / s (clamped to
 * its grid: a pyramid that floors odd sizes) holds level-L position q at
 * (q + 0.5) / s - 0.5 - bc n of its brick, so the entry (w = -s) keeps
 * xyz = corner + (b n + 0.5) / s - 0.5 - bc n and the shader adds
 * (q - b n) / s: sums of integers and multiples of 1/16, exact in float.
 * Constant and invisible bricks keep their value, resident ones their own
 * entry, so a frame with every visible brick of L resident draws exactly
 * that level's table. Returns the coarsest level a visible brick reads. */
static uint32_t make_mixed(vxl_stream *s, const vxl_pages *levels, uint32_t n_levels, uint32_t L)
{
    const vxl_pages *pg = &levels[L];
    const uint64_t count = vxl_page_count(pg);
    const uint32_t n = pg->brick;
    uint32_t coarsest = L;
    memcpy(s->mixed, s->entries + 4 * s->first[L], count * 4 * sizeof *s->mixed);
    for (uint64_t i = 0; i < count; i++) {
        const uint64_t flat = s->first[L] + i;
        if (pg->data_index[i] < 0 || !s->need[flat] || s->slot_of[flat] >= 0) continue;
        const uint64_t b[3] = {i % pg->grid[0], i / pg->grid[0] % pg->grid[1], i / ((uint64_t)pg->grid[0] * pg->grid[1])};
        float *pe = s->mixed + 4 * i;
        for (uint32_t k = L + 1; k < n_levels; k++) {
            const vxl_pages *pk = &levels[k];
            const uint32_t sh = k - L;
            uint64_t bc[3];
            for (int a = 0; a < 3; a++) bc[a] = (b[a] >> sh) < pk->grid[a] ? b[a] >> sh : pk->grid[a] - 1;
            const uint64_t j = bc[0] + pk->grid[0] * (bc[1] + (uint64_t)pk->grid[1] * bc[2]);
            if (pk->data_index[j] < 0) { /* one value there, so here too (the plan is the same index's) */
                pe[0] = pe[1] = pe[2] = 0;
                pe[3] = pk->low[j];
            } else if (s->slot_of[s->first[k] + j] >= 0) {
                const float *ae = s->entries + 4 * (s->first[k] + j);
                const double scale = (double)(1u << sh);
                for (int a = 0; a < 3; a++)
                    pe[a] = (float)(ae[a] + ((double)b[a] * n + 0.5) / scale - 0.5 - (double)bc[a] * n);
                pe[3] = (float)-scale;
            } else
                continue;
            coarsest = k > coarsest ? k : coarsest;
            break;
        }
    }
    return coarsest;
}

static int prepare_streamed(vxl_storage_state *st, const vxl_frame *f)
{
    vxl_stream *s = st->stream;
    vxl_paged_see(st, f, 0);
    const int progressive = f && f->progressive;
    s->load_ms = 0;
    if (drain(st, 0) < 0) return st->gpu->err.code; /* what arrived since the last frame */
    const uint32_t C = st->n_levels - 1;
    uint64_t fixed = fixed_bytes(st->levels, st->n_levels, s->queue_bricks);
    /* what each level's frame reads follows the occupancy: re-derived when it changes */
    const uint64_t need_key = (st->grid->tf_key * 1099511628211ull ^ st->visible_reach) * 2 + (st->visible_all != 0);
    if (!s->need_valid || need_key != s->need_key) {
        for (uint32_t k = 0; k < st->n_levels; k++)
            s->needed[k] = vxl_pages_needed(&st->levels[k], st->grid, st->visible_reach, 1u << k, st->visible_all, NULL,
                                            s->need + s->first[k]);
        s->dirty = 1;
    }
    s->need_key = need_key;
    s->need_valid = 1;
    /* the finest level whose visible bricks (with the coarser levels kept
     * for progressive frames) and what the frame derives from them fit */
    uint64_t wanted = 0, bytes = UINT64_MAX;
    uint32_t L = 0, slots[3];
    int fits = 0;
    for (; L < st->n_levels; L++) { /* f == NULL (probes): full resolution only */
        uint32_t count = 0;
        for (uint32_t k = L; k <= (progressive ? C : L); k++) count += s->needed[k];
        bytes = pool_bytes_for(st, &st->levels[0], count, slots);
        if (bytes != UINT64_MAX && f && f->classify == VXL_CLASSIFY_PRE) bytes += bytes / st->levels[0].bytes_per_voxel * 4;
        if (bytes != UINT64_MAX) bytes += fixed;
        if (L == 0) wanted = bytes;
        if ((fits = vxl_budget_fits(st->gpu->budget, NULL, VXL_HOLD_STORAGE, bytes)) || !f) break;
    }
    if (!fits)
        return vxl_budget_ask(st->gpu->budget, NULL, VXL_HOLD_STORAGE, bytes, &st->gpu->err, NULL,
                              "the visible bricks of the streamed volume at %ux coarser, %.1f MiB at full resolution",
                              1u << (L < st->n_levels ? L : C), wanted / 1048576.0);
    s->target = L;
    s->coarse = progressive ? C : L;
    uint32_t required = 0;
    for (uint32_t k = L; k <= s->coarse; k++) required += s->needed[k];
    int rc = ensure_pool(st, required, fixed);
    if (rc) return rc;
    s->missing_target = count_missing(s, &st->levels[L], L);
    s->missing_coarse = s->coarse != L ? count_missing(s, &st->levels[C], C) : 0;
    if ((rc = request(st, f))) return rc;
    const double t0 = now_ms();
    rc = wait_for(st, f, s->coarse != L ? &s->missing_coarse : &s->missing_target);
    s->load_ms = now_ms() - t0;
    if (rc) return rc;
    if (drain(st, 0) < 0) return st->gpu->err.code;
    /* the table drawn, made again and uploaded only when what it says changed */
    const int remade = s->dirty || s->mixed_level != L || !s->page_tex;
    if (remade) {
        s->coarsest_drawn = make_mixed(s, st->levels, st->n_levels, L);
        s->mixed_level = L;
        st->gpu->gl.ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
        vxl_page_table_upload(st, &s->page_tex, &st->levels[L], s->mixed);
        s->dirty = 0;
    }
    s->refine_pending = (uint32_t)count_missing(s, &st->levels[L], L); /* 0 for F12, which waited */
    s->stream_level = s->coarsest_drawn;
    if ((rc = vxl_gl_check(st->gpu, "uploading streamed bricks"))) return rc;
    if (s->uploaded || remade || st->level != L) st->pool_generation++; /* what is derived from the pool or read through the table is stale */
    s->uploaded = 0;
    st->level = L;
    st->page_tex = s->page_tex;
    st->pages_resident = s->needed[L];
    st->pages_constant = s->constant[L];
    st->pool_bytes = pool_bytes_for(st, &st->levels[0], s->capacity, slots) + fixed;
    st->lod_wanted_bytes = L ? wanted : 0;
    const uint64_t read = __atomic_load_n(&s->src->bytes_read, __ATOMIC_RELAXED);
    s->bytes_read = read - s->read_mark;
    s->read_mark = read;
    return VXL_OK;
}

/* The derived filters are computed from CPU bricks, which a streamed volume
 * does not keep. */
static int check_streamed(vxl_storage_state *st, uint32_t filter, uint32_t classify)
{
    (void)classify;
    if (filter == VXL_FILTER_PRECOMPUTED || filter == VXL_FILTER_CUBIC)
        return vxl_fail(&st->gpu->err, VXL_ERR_INVALID_ARGUMENT,
                        "the %s filter derives its volume from every brick on the CPU, which a streamed volume does not "
                        "keep: use an on-the-fly filter (central differences, ...) or load it with streaming off",
                        vxl_filter_name(filter));
    return VXL_OK;
}

static int derive_streamed(vxl_storage_state *st, uint32_t which, int arg)
{
    (void)arg;
    return vxl_fail(&st->gpu->err, VXL_ERR_STATE, "%s cannot be derived from a streamed volume",
                    which == VXL_DERIVED_GRADIENTS ? "precomputed gradients" : "cubic B-spline coefficients");
}

static void report_streamed(const vxl_storage_state *st, vxl_render_stats *out)
{
    vxl_paged_report(st, out);
    const vxl_stream *s = st->stream;
    if (!s) return;
    out->lod_level = s->target; /* the level the budget allows; stream_level says what was drawn */
    out->refine_pending = s->refine_pending;
    out->stream_level = s->stream_level;
    out->bytes_read = s->bytes_read;
    out->load_ms = s->load_ms;
}

/* Programs sample through the mixed page table (PAGED_MIXED): a variant
 * of its own, so every other storage's programs stay as they are. */
static uint32_t sample_flags_streamed(const vxl_storage_state *st)
{
    (void)st;
    return VXL_FLAG_PAGED | VXL_FLAG_PAGED_MIXED;
}

const vxl_storage_ops vxl_storage_streamed = {
    .plan = plan_streamed,
    .install = install_streamed,
    .check_filter = check_streamed,
    .prepare = prepare_streamed,
    .sample_flags = sample_flags_streamed,
    .bind = vxl_paged_bind,
    .texels = vxl_paged_texels,
    .resident_bytes = vxl_paged_resident_bytes,
    .report = report_streamed,
    .derive = derive_streamed,
    .needs_occupancy = 1,
    .release = release_streamed,
};
