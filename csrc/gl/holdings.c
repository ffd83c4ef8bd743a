/* holdings.c - the holders of GL memory, read for the budget (holdings.h). */
#include "holdings.h"

#include <stdarg.h>

void vxl_holding_register(vxl_gpu *g, vxl_holder who, uint64_t (*bytes)(const void *state), const void *state)
{
    g->holdings[who] = (vxl_holding){bytes, state};
}

uint64_t vxl_holding_counter(const void *bytes) { return *(const uint64_t *)bytes; }

void vxl_holdings(const vxl_gpu *g, uint64_t held[VXL_HOLD_COUNT])
{
    for (int h = 0; h < VXL_HOLD_COUNT; h++)
        held[h] = g->holdings[h].bytes ? g->holdings[h].bytes(g->holdings[h].state) : 0;
}

int vxl_holdings_ask(vxl_gpu *g, vxl_holder who, uint64_t bytes, const char *hint, const char *what, ...)
{
    uint64_t held[VXL_HOLD_COUNT];
    vxl_holdings(g, held);
    va_list ap;
    va_start(ap, what);
    int rc = vxl_budget_vask(g->budget, held, who, bytes, &g->err, hint, what, ap);
    va_end(ap);
    return rc;
}
