/* label_bricks.c - which label ids each brick of the label volume (with its
 * apron) holds, and from that, per table, where visible labels can be
 * (label_bricks.h). */
#include "label_bricks.h"

#include <stdlib.h>
#include <string.h>

#include "bricks.h"
#include "voxlight.h"

void vxl_label_bricks_free(vxl_label_bricks *b)
{
    free(b->start);
    free(b->ids);
    free(b->clipped);
    free(b->distance);
    free(b->words);
    memset(b, 0, sizeof *b);
}

uint64_t vxl_label_bricks_count(const vxl_label_bricks *b)
{
    return (uint64_t)b->dims[0] * b->dims[1] * b->dims[2];
}

uint64_t vxl_label_bricks_bytes(const vxl_label_bricks *b)
{
    uint64_t n = vxl_label_bricks_count(b);
    return b->start ? n * (sizeof *b->start + 2 + sizeof *b->words) + (uint64_t)b->start[n] * sizeof *b->ids : 0;
}

/* Appends id to the growing list (*ids, *len of *cap); 0, or -1 out of memory. */
static int push_id(uint16_t **ids, uint64_t *len, uint64_t *cap, uint16_t id)
{
    if (*len == *cap) {
        uint64_t c = *cap ? 2 * *cap : 4096;
        uint16_t *n = realloc(*ids, c * sizeof *n);
        if (!n) return -1;
        *ids = n;
        *cap = c;
    }
    (*ids)[(*len)++] = id;
    return 0;
}

int vxl_label_bricks_build(vxl_label_bricks *b, const uint16_t *ids, const uint32_t dims[3])
{
    vxl_label_bricks_free(b);
    for (int a = 0; a < 3; a++) b->dims[a] = (dims[a] + VXL_LABEL_BRICK - 1) / VXL_LABEL_BRICK;
    const uint64_t n = vxl_label_bricks_count(b);
    /* seen[id] = the last brick that listed id + 1: distinct ids in one pass */
    uint32_t *seen = calloc((size_t)VXL_MAX_LABEL_ID + 1, sizeof *seen);
    b->start = malloc((size_t)(n + 1) * sizeof *b->start);
    b->clipped = malloc((size_t)n);
    uint64_t len = 0, cap = 0;
    int rc = seen && b->start && b->clipped ? 0 : -1;
    const int64_t A = VXL_LABEL_APRON, B = VXL_LABEL_BRICK;
    for (uint64_t i = 0; i < n && !rc; i++) {
        const uint64_t bx = i % b->dims[0], by = (i / b->dims[0]) % b->dims[1], bz = i / ((uint64_t)b->dims[0] * b->dims[1]);
        const int64_t lo[3] = {(int64_t)bx * B - A, (int64_t)by * B - A, (int64_t)bz * B - A};
        int64_t c0[3], c1[3]; /* the brick with its apron, clipped to the volume: [c0, c1) */
        int clipped = 0;
        for (int a = 0; a < 3; a++) {
            int64_t hi = lo[a] + B + 2 * A;
            c0[a] = lo[a] < 0 ? 0 : lo[a];
            c1[a] = hi > (int64_t)dims[a] ? (int64_t)dims[a] : hi;
            clipped |= lo[a] < 0 || hi > (int64_t)dims[a];
        }
        b->clipped[i] = (uint8_t)clipped;
        b->start[i] = (uint32_t)len;
        const uint32_t stamp = (uint32_t)i + 1;
        for (int64_t z = c0[2]; z < c1[2] && !rc; z++)
            for (int64_t y = c0[1]; y < c1[1] && !rc; y++) {
                const uint16_t *row = ids + (size_t)(dims[0] * ((uint64_t)dims[1] * (uint64_t)z + (uint64_t)y));
                for (int64_t x = c0[0]; x < c1[0]; x++) {
                    uint16_t id = row[x];
                    if (seen[id] == stamp) continue;
                    seen[id] = stamp;
                    if ((rc = push_id(&b->ids, &len, &cap, id))) break;
                }
            }
        /* the list indexes with 32 bits: at most 65536 ids per brick, far below for any real volume */
        if (!rc && len > UINT32_MAX) rc = -1;
    }
    free(seen);
    if (!rc) {
        b->start[n] = (uint32_t)len;
        b->distance = malloc((size_t)n);
        b->words = malloc((size_t)n * sizeof *b->words);
        if (!b->ids) b->ids = malloc(sizeof *b->ids); /* an empty volume lists nothing */
        if (!b->distance || !b->words || !b->ids) rc = -1;
    }
    if (rc) vxl_label_bricks_free(b);
    return rc;
}

int vxl_label_bricks_classify(vxl_label_bricks *b, const uint8_t *visible)
{
    const uint64_t n = vxl_label_bricks_count(b);
    for (uint64_t i = 0; i < n; i++) {
        uint32_t word = 0;
        int any = 0;
        for (uint32_t k = b->start[i]; k < b->start[i + 1] && !any; k++) {
            const uint16_t id = b->ids[k];
            any = (visible[id >> 3] >> (id & 7)) & 1;
            if (any && b->start[i + 1] - b->start[i] == 1 && !b->clipped[i]) word = VXL_LABEL_UNIFORM | (uint32_t)id << 16;
        }
        b->distance[i] = any ? 0 : 255;
        b->words[i] = word;
    }
    if (vxl_bricks_chebyshev(b->distance, b->dims)) return -1;
    for (uint64_t i = 0; i < n; i++) b->words[i] |= b->distance[i];
    return 0;
}
