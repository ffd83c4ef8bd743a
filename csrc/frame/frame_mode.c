/* frame_mode.c - the render mode (voxlight.h's VXL_MODE_*) and the
 * MatCap of a frame: validated here so the GL side only draws.
 *
 * What combines with what. The projections (MIP, MINIP, AVERAGE) classify
 * the one value they project and ISO colours the surface with the table at
 * iso_value, so the per-sample classification variants have nothing to act
 * on there: pre-classification (colours interpolated before the projection),
 * pre-integration (segments between samples) and Levoy's gradient opacity
 * (per-sample opacity) are refused outside DVR rather than silently dropped.
 * The slicing comparison techniques composite slices with DVR's rule and have
 * no projection: they too are DVR only, and shade with the material and
 * lights (a MatCap with them is refused). Shading applies to DVR and ISO (a
 * projection has no surface); the MatCap replaces the lights where shading
 * applies and is ignored otherwise (a caller may keep one set while shading
 * is off or the mode projects, as the Blender panel may). */
#include <math.h>
#include <stddef.h>

#include "frame.h"

#define MATCAP_MAX_SIDE 4096

static int resolve_matcap(vxl_frame *f, const vxl_matcap *m, int shading, vxl_err *e)
{
    if (!m) return VXL_OK;
    if (m->struct_size != 0 && m->struct_size < sizeof *m)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "matcap.struct_size = %u is smaller than vxl_matcap (%zu bytes)",
                        m->struct_size, sizeof *m);
    if (m->reserved)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "matcap.reserved is %u: it must be 0", m->reserved);
    if (m->width < 1 || m->height < 1 || m->width > MATCAP_MAX_SIDE || m->height > MATCAP_MAX_SIDE)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "matcap size %ux%u must be in [1, %d] per side", m->width,
                        m->height, MATCAP_MAX_SIDE);
    if (!m->rgba) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "matcap.rgba is NULL");
    if (!shading || !vxl_mode_shades(f->mode)) return VXL_OK; /* nothing shades */
    if (f->technique != VXL_TECHNIQUE_RAYCAST) /* slices.frag shades with the material and lights only */
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "matcap works with technique raycast only, not %s",
                        vxl_technique_name(f->technique));
    f->matcap_rgba = m->rgba;
    f->matcap_width = m->width;
    f->matcap_height = m->height;
    f->matcap_key = m->key;
    return VXL_OK;
}

int vxl_frame_resolve_mode(vxl_frame *f, const vxl_render_params *p, vxl_err *e)
{
    if (p->mode >= VXL_MODE_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown mode %u (0 dvr, 1 mip, 2 minip, 3 average, 4 iso)",
                        p->mode);
    f->mode = p->mode;
    const char *name = vxl_mode_name(p->mode);
    if (p->mode == VXL_MODE_ISO && !isfinite(p->iso_value))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "iso_value = %g is not a finite number (mode iso)",
                        (double)p->iso_value);
    if (p->mode != VXL_MODE_DVR) {
        if (p->classify != VXL_CLASSIFY_POST)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                            "classify %s works in mode dvr only: mode %s classifies the %s (use classify post)",
                            vxl_classify_name(p->classify), name,
                            p->mode == VXL_MODE_ISO ? "iso value" : "projected value");
        if (p->gradient_opacity != VXL_GOPACITY_OFF)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                            "gradient_opacity %s works in mode dvr only (mode %s has no per-sample opacity)",
                            vxl_gradient_opacity_name(p->gradient_opacity), name);
        if (p->technique != VXL_TECHNIQUE_RAYCAST)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "technique %s works in mode dvr only (mode %s is ray cast)",
                            vxl_technique_name(p->technique), name);
    }
    return resolve_matcap(f, p->matcap, !p->shading_off, e);
}
