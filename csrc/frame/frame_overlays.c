/* frame_overlays.c - params.overlays checked into f->overlays
 * (frame.h). Each overlay's transfer function and window are resolved
 * against its own volume exactly as the base volume's are
 * (vxl_frame_resolve_tf); its classification key keys the GL side's
 * transfer-function texture and brick occupancy, so a frame that changes
 * only the camera rebuilds neither. docs/overlays.md. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "frame.h"
#include "mat4.h"

#define MAX_SAMPLES_PER_RAY 16384 /* frame.c's bound on every ray, now over the union of the boxes */

/* What of the frame overlays cannot go with (one message per conflict). */
static int check_combination(const vxl_frame *f, const vxl_render_params *p, vxl_err *e)
{
    if (f->technique != VXL_TECHNIQUE_RAYCAST)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "overlays need the ray caster (technique 0), not technique %u", f->technique);
    if (f->mode != VXL_MODE_DVR)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "overlays need the DVR mode, not mode %u (%s)", f->mode,
                        vxl_mode_name(f->mode) ? vxl_mode_name(f->mode) : "?");
    if (f->labels.on && f->labels.mode == VXL_LABEL_MODE_SURFACE)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "overlays cannot go with SURFACE labels (labels replace the ray march): use mask or tint");
    if (f->classify == VXL_CLASSIFY_PREINT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "overlays cannot go with pre-integrated classification (classify preint): use post or pre");
    if (f->gopacity != 0)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "overlays cannot go with gradient_opacity %u: use 0 (none)",
                        f->gopacity);
    (void)p;
    return VXL_OK;
}

/* Style i (at `stride` bytes apart) against its volume g into ov. */
static int resolve_one(vxl_frame *f, vxl_frame_overlay *ov, const vxl_overlay_style *s, uint32_t i,
                       const vxl_volume_geom *g, vxl_err *e)
{
    if (s->blend >= VXL_BLEND_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "overlays[%u].blend %u is unknown (0 over, 1 add, 2 max)", i,
                        s->blend);
    const uint32_t interp = s->interpolation_set ? s->interpolation : VXL_INTERP_LINEAR;
    if (interp >= VXL_INTERP_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "overlays[%u].interpolation %u is unknown (0 nearest, 1 linear, 2 cubic)", i, interp);
    if (s->reserved) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "overlays[%u].reserved is %u: it must be 0", i, s->reserved);
    if (s->has_model) {
        double inv[16];
        vxl_mat4_from_float(ov->model, s->model);
        if (!vxl_mat4_is_finite(ov->model) || !vxl_mat4_invert(inv, ov->model))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "overlays[%u].model is not finite or not invertible", i);
    } else {
        memcpy(ov->model, g->affine, sizeof ov->model); /* checked invertible when the slot was set */
    }
    /* the base volume's own resolution of a table and window, on this volume */
    vxl_render_params q;
    memset(&q, 0, sizeof q);
    q.preset = s->preset;
    q.tf_size = s->tf_size;
    q.tf_rgba = s->tf_rgba;
    q.has_window = s->has_window;
    q.window_low = s->window_low;
    q.window_high = s->window_high;
    q.opacity_scale = s->opacity_scale;
    q.color_space = f->color_space; /* a preset's colours decoded as the base volume's are */
    int rc = vxl_frame_resolve_table(&ov->table, &q, g, "overlays", i, e);
    if (rc) return rc;
    ov->slot = s->slot;
    ov->blend = s->blend;
    ov->interpolation = interp;
    ov->shading = f->shading && !s->shading_off;
    return VXL_OK;
}

/* The ray walks the union of the boxes: its longest path, in base voxels,
 * bounds the samples, and the step widens so that bound stays 16384. */
static void widen_to_union(vxl_frame *f, const vxl_volume_geom *const geoms[VXL_MAX_OVERLAYS], const vxl_volume_geom *base)
{
    double lo[3], hi[3], base_inv[16];
    for (int a = 0; a < 3; a++) {
        lo[a] = -0.5;
        hi[a] = base->dims[a] - 0.5;
    }
    if (!vxl_mat4_invert(base_inv, f->model)) return; /* checked by resolve_matrices */
    for (uint32_t k = 0; k < f->overlays.count; k++) {
        const vxl_frame_overlay *ov = &f->overlays.ov[k];
        const vxl_volume_geom *g = geoms[ov->slot];
        double m[16];
        vxl_mat4_mul(m, base_inv, ov->model); /* overlay voxel -> base voxel */
        for (int c = 0; c < 8; c++) {
            double v[4] = {(c & 1) ? g->dims[0] - 0.5 : -0.5, (c & 2) ? g->dims[1] - 0.5 : -0.5,
                           (c & 4) ? g->dims[2] - 0.5 : -0.5, 1.0}, w[4];
            vxl_mat4_transform(m, v, w);
            for (int a = 0; a < 3; a++) {
                double x = w[3] != 0 ? w[a] / w[3] : w[a];
                if (!isfinite(x)) continue;
                lo[a] = fmin(lo[a], x);
                hi[a] = fmax(hi[a], x);
            }
        }
    }
    double diag = 0;
    for (int a = 0; a < 3; a++) diag += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    diag = sqrt(diag);
    if (!(diag < 1e12)) return;
    f->step = (float)fmax(f->step, diag / MAX_SAMPLES_PER_RAY);
    int steps = (int)ceil(diag / f->step) + 2;
    if (steps > f->max_steps) f->max_steps = steps;
}

int vxl_frame_resolve_overlays(vxl_frame *f, const vxl_render_params *pin, const vxl_volume_geom *const geoms[VXL_MAX_OVERLAYS],
                               const vxl_volume_geom *base, vxl_err *e)
{
    vxl_render_params params;
    int rc = vxl_render_params_read(&params, pin, e);
    if (rc) return rc;
    const vxl_render_params *p = &params;
    if (p->overlay_count == 0) return VXL_OK;
    if (p->overlay_count > VXL_MAX_OVERLAYS)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "overlay_count %u exceeds %d", p->overlay_count, VXL_MAX_OVERLAYS);
    if (!p->overlays)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "params.overlays is NULL with overlay_count %u", p->overlay_count);
    if ((rc = check_combination(f, p, e))) return rc;
    uint32_t stride = p->overlays[0].struct_size ? p->overlays[0].struct_size : (uint32_t)sizeof(vxl_overlay_style);
    if (stride < sizeof(vxl_overlay_style))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "overlays[0].struct_size %u is smaller than vxl_overlay_style (%zu)",
                        stride, sizeof(vxl_overlay_style));
    uint32_t listed = 0;
    for (uint32_t i = 0; i < p->overlay_count && !rc; i++) {
        const vxl_overlay_style *s = (const vxl_overlay_style *)((const char *)p->overlays + (size_t)i * stride);
        if (s->slot >= VXL_MAX_OVERLAYS)
            rc = vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "overlays[%u].slot %u is out of range (< %d)", i, s->slot,
                          VXL_MAX_OVERLAYS);
        else if (listed & (1u << s->slot))
            rc = vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "overlays[%u]: slot %u is listed twice", i, s->slot);
        else if (!geoms[s->slot])
            rc = vxl_fail(e, VXL_ERR_STATE, "overlays[%u]: overlay slot %u is empty: call vxl_renderer_set_overlay first",
                          i, s->slot);
        else {
            listed |= 1u << s->slot;
            f->overlays.count = i + 1; /* so vxl_frame_free frees what this one allocates */
            rc = resolve_one(f, &f->overlays.ov[i], s, i, geoms[s->slot], e);
        }
    }
    if (rc) {
        vxl_frame_overlays_free(f);
        return rc;
    }
    widen_to_union(f, geoms, base);
    return VXL_OK;
}

void vxl_frame_overlays_free(vxl_frame *f)
{
    for (uint32_t k = 0; k < VXL_MAX_OVERLAYS; k++) {
        free(f->overlays.ov[k].table.tf_copy);
        f->overlays.ov[k].table.tf_copy = NULL;
    }
    f->overlays.count = 0;
}
