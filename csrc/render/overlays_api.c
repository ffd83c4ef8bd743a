/* overlays_api.c - overlay call: the volume goes to the overlay
 * room (overlay/overlays.h) on the renderer's GL thread. */
#include "renderer_internal.h"

typedef struct overlay_job {
    vxl_renderer *r;
    uint32_t slot;
    const vxl_volume *v;
} overlay_job;

static int job_set_overlay(void *p)
{
    overlay_job *j = p;
    return vxl_overlays_set(&j->r->overlays, j->slot, j->v);
}

int vxl_renderer_set_overlay(vxl_renderer *r, uint32_t slot, const vxl_volume *vol)
{
    if (!r) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer is NULL");
    if (slot >= VXL_MAX_OVERLAYS) {
        int rc = vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "overlay slot %u is out of range (< %d)", slot,
                          VXL_MAX_OVERLAYS);
        vxl_publish_error(&r->gpu.err);
        return rc;
    }
    overlay_job j = {r, slot, vol};
    int rc = vxl_gl_thread_call(&r->thread, job_set_overlay, &j);
    if (rc) vxl_publish_error(&r->gpu.err);
    return rc;
}
