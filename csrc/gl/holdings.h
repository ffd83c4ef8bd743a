/* holdings.h - the holders of GL memory (budget.h) as the accountant sees
 * them: each subsystem registers, once, how to read what it holds, and
 * every ask of a derived volume is charged with what the others hold. The
 * accountant reads no subsystem's struct. The storage asks budget.h
 * directly: it replaces everything, so it needs no holdings. */
#ifndef VXL_HOLDINGS_H
#define VXL_HOLDINGS_H

#include <stdint.h>

#include "budget.h"
#include "gpu.h"

/* Holder `who` reports its bytes through bytes(state) from now on. */
void vxl_holding_register(vxl_gpu *g, vxl_holder who, uint64_t (*bytes)(const void *state), const void *state);
/* The bytes function of a holder whose state is its byte count (a uint64_t). */
uint64_t vxl_holding_counter(const void *bytes);
/* Fills held[VXL_HOLD_COUNT] with the bytes each holder holds now (0: none registered). */
void vxl_holdings(const vxl_gpu *g, uint64_t held[VXL_HOLD_COUNT]);
/* vxl_budget_ask against the budget, the holdings and the error slot of g. */
int vxl_holdings_ask(vxl_gpu *g, vxl_holder who, uint64_t bytes, const char *hint, const char *what, ...)
    __attribute__((format(printf, 5, 6)));

#endif
