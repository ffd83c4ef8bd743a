/* budget.c - the memory budget's accountant (budget.h): one formula, one
 * message. */
#include "budget.h"

#include <stdio.h>

uint64_t vxl_budget_in_all(const uint64_t *held, vxl_holder who, uint64_t bytes)
{
    for (int h = 0; held && h < VXL_HOLD_COUNT; h++) {
        if (h == (int)who) continue; /* replaced by what it asks for */
        if (bytes > UINT64_MAX - held[h]) return UINT64_MAX;
        bytes += held[h];
    }
    return bytes;
}

int vxl_budget_fits(uint64_t limit, const uint64_t *held, vxl_holder who, uint64_t bytes)
{
    return vxl_budget_in_all(held, who, bytes) <= limit;
}

int vxl_budget_vask(uint64_t limit, const uint64_t *held, vxl_holder who, uint64_t bytes, vxl_err *e, const char *hint,
                    const char *what, va_list ap)
{
    const uint64_t all = vxl_budget_in_all(held, who, bytes);
    if (all <= limit) return VXL_OK;
    char name[256], in_all[64] = "";
    vsnprintf(name, sizeof name, what, ap);
    if (all != bytes) snprintf(in_all, sizeof in_all, " (%.1f MiB in all with what the renderer holds)", all / 1048576.0);
    return vxl_fail(e, VXL_ERR_LIMIT, "%s: %.1f MiB%s, over the renderer's memory budget of %.1f MiB%s", name,
                    bytes / 1048576.0, in_all, limit / 1048576.0, hint ? hint : "");
}

int vxl_budget_ask(uint64_t limit, const uint64_t *held, vxl_holder who, uint64_t bytes, vxl_err *e, const char *hint,
                   const char *what, ...)
{
    va_list ap;
    va_start(ap, what);
    int rc = vxl_budget_vask(limit, held, who, bytes, e, hint, what, ap);
    va_end(ap);
    return rc;
}
