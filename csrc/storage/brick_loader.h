/* brick_loader.h - the loader threads of a renderer that streams a volume
 * (docs/streaming.md). The renderer's thread says which page bricks it
 * wants, in priority order; the loader reads each with its one-voxel ghost
 * border (out-of-volume voxels repeat the edge voxel, as paging.c's bricks
 * do) from the volume's brick source into a bounded queue of staging
 * buffers, which the renderer's thread uploads and hands back. CPU only, no
 * GL; one loader per storage state, started at install, joined at release,
 * so nothing is global and a renderer destroyed while loading waits for
 * the reads in progress and frees everything. */
#ifndef VXL_BRICK_LOADER_H
#define VXL_BRICK_LOADER_H

#include <stdint.h>

#include "brick_source.h"
#include "error.h"

typedef struct vxl_brick_key {
    uint32_t level; /* the source's level */
    uint32_t brick; /* page brick index within the level's grid, x fastest */
} vxl_brick_key;

typedef struct vxl_loaded_brick {
    vxl_brick_key key;
    uint8_t *texels; /* edge^3 voxels, ghost included, x fastest; the loader's staging buffer */
} vxl_loaded_brick;

typedef struct vxl_brick_loader vxl_brick_loader;

/* Starts the threads reading from src (which must outlive the loader)
 * bricks of `brick` voxels per edge (ghost excluded) with at most
 * queue_bricks staging buffers (allocated as needed; a thread reads into
 * one of them, so the threads add no memory). One thread per core, at most
 * 4 and queue_bricks: the source's read is thread-safe (brick_source.h). */
int vxl_loader_start(vxl_brick_loader **out, vxl_brick_source *src, uint32_t brick, uint32_t queue_bricks, vxl_err *e);
/* The same with n_threads threads (1..4; 0 = one per core, as above). */
int vxl_loader_start_threads(vxl_brick_loader **out, vxl_brick_source *src, uint32_t brick, uint32_t queue_bricks,
                             uint32_t n_threads, vxl_err *e);
/* Stops and joins the threads, frees the queue; NULL is a no-op. */
void vxl_loader_stop(vxl_brick_loader *l);
/* CPU bytes the loader may hold: its staging buffers. */
uint64_t vxl_loader_bytes(const vxl_brick_loader *l);
/* Replaces what the loader reads next by keys[0..n-1], in that order. */
int vxl_loader_want(vxl_brick_loader *l, const vxl_brick_key *keys, uint32_t n, vxl_err *e);
/* Takes up to max arrived bricks into out; with wait, blocks until one
 * arrives, or the loader has nothing left to read, or a read failed. Give
 * each taken brick's buffer back with vxl_loader_recycle. */
uint32_t vxl_loader_take(vxl_brick_loader *l, vxl_loaded_brick *out, uint32_t max, int wait);
void vxl_loader_recycle(vxl_brick_loader *l, const vxl_loaded_brick *b, uint32_t n);
/* A failed read: its code and message into e (the loader then waits for a
 * new wanted list), clearing it; VXL_OK when none. */
int vxl_loader_error(vxl_brick_loader *l, vxl_err *e);

#endif
