/* holdings.h - what the renderer's holders (budget.h) hold on the GL side,
 * read in one place, and the ask of a derived volume, which is charged with
 * everything else resident. The storage asks budget.h directly: it
 * replaces everything, so it needs no holdings (and must not depend on what
 * is derived from it). */
#ifndef VXL_HOLDINGS_H
#define VXL_HOLDINGS_H

#include <stdint.h>

#include "budget.h"

typedef struct vxl_renderer vxl_renderer;

/* Fills held[VXL_HOLD_COUNT] with the bytes each holder holds now. */
void vxl_holdings(const vxl_renderer *r, uint64_t held[VXL_HOLD_COUNT]);
/* vxl_budget_ask against the renderer's budget, its holdings and its error. */
int vxl_holdings_ask(vxl_renderer *r, vxl_holder who, uint64_t bytes, const char *hint, const char *what, ...)
    __attribute__((format(printf, 5, 6)));

#endif
