/* scene_transmittance.c - vxl_scene_transmittance: the frame
 * resolved as vxl_render resolves it, with a shading model that has
 * illumination volumes, everything the light's volume derives from
 * prepared as a frame prepares it (so a frame rendered with the same
 * parameters leaves nothing to rebuild), then light/transmittance.c's pass,
 * on the renderer's GL thread. */
#include "renderer_internal.h"
#include "transmittance.h"

typedef struct transmittance_job {
    vxl_renderer *r;
    const vxl_render_params *p;
    uint32_t light;
    float *out;
} transmittance_job;

static int job_transmittance(void *arg)
{
    transmittance_job *j = arg;
    vxl_renderer *r = j->r;
    vxl_err *e = &r->gpu.err;
    if (!r->storage.has_volume) return vxl_fail(e, VXL_ERR_STATE, "no volume: call vxl_renderer_set_volume first");
    vxl_render_params q; /* read up to the caller's struct_size, never past */
    int rc = vxl_render_params_read(&q, j->p, e);
    if (rc) return rc;
    if (!q.scene_depth) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "scene_transmittance needs params.scene_depth");
    const uint32_t lights = q.light_count ? q.light_count : 1; /* 0: the headlight */
    if (j->light >= lights)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light %u is out of range: the params have %u light%s", j->light,
                        lights, lights == 1 ? "" : "s");
    q.struct_size = sizeof q;
    /* the illumination volumes of the frame's own model; Phong and unshaded
     * frames have none, so the shadowed model's are built (the same) */
    if (q.shading_off || q.shading_model == VXL_SHADING_PHONG) q.shading_model = VXL_SHADING_SHADOWED;
    q.shading_off = 0;
    q.ambient_occlusion = 0; /* not read here; a cached occlusion volume stays valid */
    q.matcap = NULL;         /* nor is the MatCap, whose checks follow the shading just forced on */
    q.environment = NULL;    /* nor the World's light: light_count 0 stays the headlight here */
    vxl_frame f;
    rc = vxl_frame_resolve(&f, &q, &r->storage.geom, e);
    if (rc) return rc;
    r->gpu.gl.GetError();
    vxl_upload_tf(r, &f);
    if ((f.skip || r->storage.ops->needs_occupancy) && (rc = vxl_skipping_prepare(&r->skipping, &f))) goto done;
    if ((rc = r->storage.ops->prepare(&r->storage, &f))) goto done;
    if ((rc = vxl_illumination_prepare(&r->illumination, &f))) goto done;
    rc = vxl_scene_transmittance_pass(&r->illumination, &f, (int)j->light, j->out);
done:
    vxl_frame_free(&f);
    return rc;
}

int vxl_scene_transmittance(vxl_renderer *r, const vxl_render_params *p, uint32_t light, float *out)
{
    if (!r) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer is NULL");
    if (!p || !out) return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "params or the output buffer is NULL");
    transmittance_job j = {r, p, light, out};
    int rc = vxl_gl_thread_call(&r->thread, job_transmittance, &j);
    if (rc) vxl_publish_error(&r->gpu.err);
    return rc;
}
