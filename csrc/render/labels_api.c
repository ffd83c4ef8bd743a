/* labels_api.c - renderer calls: the label volume goes to the
 * labels room (labels/labels.h) on the renderer's GL thread. */
#include "renderer_internal.h"
#include "voxlight_dev.h"

typedef struct labels_job {
    vxl_renderer *r;
    const vxl_volume *v;
    uint64_t counts[2];
} labels_job;

static int job_set_labels(void *p)
{
    labels_job *j = p;
    return vxl_labels_set(&j->r->labels, j->v);
}

int vxl_renderer_set_labels(vxl_renderer *r, const vxl_volume *labels)
{
    if (!r) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer is NULL");
    if (labels && labels->source) /* the label volume is uploaded whole */
        return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT,
                        "a label map is uploaded whole and this one is streamed: load it with streaming off");
    labels_job j = {r, labels, {0, 0}};
    int rc = vxl_gl_thread_call(&r->thread, job_set_labels, &j);
    if (rc) vxl_publish_error(&r->gpu.err);
    return rc;
}

static int job_uploads(void *p)
{
    labels_job *j = p;
    j->counts[0] = j->r->labels.volume_uploads;
    j->counts[1] = j->r->labels.table_uploads;
    return VXL_OK;
}

int vxl_renderer_label_uploads(vxl_renderer *r, uint64_t *volume_uploads, uint64_t *table_uploads)
{
    if (!r) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer is NULL");
    labels_job j = {r, NULL, {0, 0}};
    int rc = vxl_gl_thread_call(&r->thread, job_uploads, &j);
    if (volume_uploads) *volume_uploads = j.counts[0];
    if (table_uploads) *table_uploads = j.counts[1];
    return rc;
}
