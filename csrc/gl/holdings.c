/* holdings.c - the renderer's holdings for the budget (holdings.h). */
#include "holdings.h"

#include <stdarg.h>

#include "renderer_internal.h"

void vxl_holdings(const vxl_renderer *r, uint64_t held[VXL_HOLD_COUNT])
{
    held[VXL_HOLD_STORAGE] = r->storage.ops ? r->storage.ops->resident_bytes(r) : 0;
    held[VXL_HOLD_GRADIENTS] = r->gradients.bytes;
    held[VXL_HOLD_BSPLINE] = r->bspline.bytes;
    held[VXL_HOLD_CLASSIFIED] = r->classification.classified_bytes;
}

int vxl_holdings_ask(vxl_renderer *r, vxl_holder who, uint64_t bytes, const char *hint, const char *what, ...)
{
    uint64_t held[VXL_HOLD_COUNT];
    vxl_holdings(r, held);
    va_list ap;
    va_start(ap, what);
    int rc = vxl_budget_vask(r->budget, held, who, bytes, &r->err, hint, what, ap);
    va_end(ap);
    return rc;
}
