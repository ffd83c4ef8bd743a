/* frame_path.c - the PATH shading model's fields of vxl_render_params (the
 * sample range, the bounce limit, the seed) validated into the frame, and
 * the features PATH does not draw yet, refused by name instead of drawn
 * wrong (clip planes and the crop box it draws: path.frag cuts every
 * segment of a path by them). */
#include "frame.h"

int vxl_frame_resolve_path(vxl_frame *f, const vxl_render_params *p, vxl_err *e)
{
    f->path_samples = p->path_samples ? p->path_samples : 1;
    f->path_offset = p->path_sample_offset;
    f->path_bounces = p->path_bounces ? p->path_bounces : VXL_PATH_DEFAULT_BOUNCES;
    f->path_seed = p->path_seed;
    if (f->shading_model != VXL_SHADING_PATH) return VXL_OK;
    /* the tracer classifies each lookup after interpolation and keeps no
     * gradient from one collision to the next: nothing to build for those */
    if (f->shading) {
        f->classify = VXL_CLASSIFY_POST;
        f->reuse = 0;
    }
    if (f->path_samples > VXL_PATH_MAX_SAMPLES)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path_samples = %u exceeds %u per call", f->path_samples,
                        VXL_PATH_MAX_SAMPLES);
    /* the sample index is a 32-bit integer in the shader: the range must not wrap */
    if (f->path_offset > UINT32_MAX - f->path_samples)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path_sample_offset %u + path_samples %u passes 2^32",
                        f->path_offset, f->path_samples);
    if (f->path_bounces > VXL_PATH_MAX_BOUNCES)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path_bounces = %u exceeds %u", f->path_bounces,
                        VXL_PATH_MAX_BOUNCES);
    return VXL_OK;
}

int vxl_frame_path_check(const vxl_frame *f, vxl_err *e)
{
    if (!f->shading || f->shading_model != VXL_SHADING_PATH) return VXL_OK;
    const char *what = f->gopacity                          ? "gradient_opacity"
                       : f->mode != VXL_MODE_DVR            ? "a mode other than DVR"
                       : f->technique != VXL_TECHNIQUE_RAYCAST ? "a slicing technique"
                       : f->matcap_rgba                     ? "a MatCap"
                       : f->cut.cutter_count                ? "cutter meshes (clip planes and the crop box it does)"
                       : f->labels.on                       ? "labels"
                       : f->overlays.count                  ? "overlays"
                                                            : NULL;
    if (what) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "shading model path does not draw %s yet", what);
    return VXL_OK;
}
