/* frame_cut.c - params.cutaway validated and resolved into the
 * frame: every field checked with a message naming it, clip planes and the
 * crop box moved into voxel space (frame_cut.h), cutters checked (counts,
 * arrays, indices, finite vertices). */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "frame_cut.h"
#include "mat4.h"

#define MAX_CUT_STRUCT_SIZE 4096u         /* far beyond any layout; bounds a garbage stride */
#define MAX_CUTTER_TRIANGLES (1u << 24)   /* 16.7 M: the peel's vertex buffer stays addressable */
#define MAX_CUTTER_VERTICES (1u << 26)

/* The caller's struct as this library's: zero past its struct_size. */
static int read_sized(void *out, size_t size, const void *in, uint32_t struct_size, const char *what, vxl_err *e)
{
    if (struct_size < sizeof(uint32_t) || struct_size > MAX_CUT_STRUCT_SIZE)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "%s.struct_size = %u must be in [%zu, %u]", what, struct_size,
                        sizeof(uint32_t), MAX_CUT_STRUCT_SIZE);
    memset(out, 0, size);
    memcpy(out, in, struct_size < size ? struct_size : size);
    return VXL_OK;
}

static int finite_all(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

static int resolve_plane(vxl_frame_cut *c, const double model[16], const vxl_clip_plane *cp, uint32_t i, vxl_err *e)
{
    if (cp->reserved)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.clip_planes[%u].reserved is %u: it must be 0", i,
                        cp->reserved);
    if (!finite_all(cp->plane, 4))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.clip_planes[%u].plane is not finite", i);
    double n = sqrt((double)cp->plane[0] * cp->plane[0] + (double)cp->plane[1] * cp->plane[1] +
                    (double)cp->plane[2] * cp->plane[2]);
    if (!(n > 0))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "cutaway.clip_planes[%u].plane has a zero normal (a, b, c): it keeps no side", i);
    if (!(cp->thickness >= 0) || !isfinite(cp->thickness))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "cutaway.clip_planes[%u].thickness = %g must be finite and >= 0 (0: the half-space)", i,
                        cp->thickness);
    /* A plane is a covector: world (a, b, c, d) / |n| pulled back through
     * voxel -> world is model^T times it, so the voxel-space function is the
     * same signed world distance. */
    double w[4] = {cp->plane[0] / n, cp->plane[1] / n, cp->plane[2] / n, cp->plane[3] / n};
    for (int r = 0; r < 4; r++) {
        double s = 0;
        for (int k = 0; k < 4; k++) s += model[r * 4 + k] * w[k];
        c->plane[i][r] = s;
    }
    c->thickness[i] = cp->thickness;
    return VXL_OK;
}

static int resolve_crop(vxl_frame_cut *c, const double model[16], const float box[16], vxl_err *e)
{
    if (!finite_all(box, 16)) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.crop_box is not finite");
    double b[16], inv[16];
    vxl_mat4_from_float(b, box);
    if (b[3] != 0 || b[7] != 0 || b[11] != 0 || b[15] != 1)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "cutaway.crop_box must be affine (bottom row 0, 0, 0, 1): it is a box -> world placement");
    /* a box thinner than 1e-9 of its largest extent has no inside to keep */
    double det = b[0] * (b[5] * b[10] - b[9] * b[6]) - b[4] * (b[1] * b[10] - b[9] * b[2]) +
                 b[8] * (b[1] * b[6] - b[5] * b[2]);
    double scale = 0;
    for (int k = 0; k < 11; k++)
        if (k != 3 && k != 7) scale = fmax(scale, fabs(b[k]));
    if (!(fabs(det) > 1e-9 * scale * scale * scale) || !vxl_mat4_invert(inv, b))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.crop_box is singular: the box has no volume");
    vxl_mat4_mul(c->crop, inv, model); /* voxel -> world -> box */
    if (!vxl_mat4_is_finite(c->crop))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.crop_box in voxel space is not finite");
    c->has_crop = 1;
    return VXL_OK;
}

static int resolve_cutter(vxl_frame_cut *c, const vxl_cutaway *ca, uint32_t i, vxl_err *e)
{
    uint32_t stride = ca->cutters[0].struct_size;
    vxl_cutter k;
    int rc = read_sized(&k, sizeof k, (const unsigned char *)ca->cutters + (size_t)i * stride, stride,
                        i ? "cutaway.cutters[i]" : "cutaway.cutters[0]", e);
    if (rc) return rc;
    if (k.struct_size != stride)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "cutaway.cutters[%u].struct_size = %u differs from cutters[0]'s %u (one array, one layout)", i,
                        k.struct_size, stride);
    if (k.remove_outside > 1)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.cutters[%u].remove_outside = %u must be 0 or 1", i,
                        k.remove_outside);
    if (k.triangle_count > MAX_CUTTER_TRIANGLES || k.vertex_count > MAX_CUTTER_VERTICES)
        return vxl_fail(e, VXL_ERR_LIMIT, "cutaway.cutters[%u]: %u triangles, %u vertices exceed %u, %u", i,
                        k.triangle_count, k.vertex_count, MAX_CUTTER_TRIANGLES, MAX_CUTTER_VERTICES);
    if (k.triangle_count && (!k.vertices || !k.indices || !k.vertex_count))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "cutaway.cutters[%u] has %u triangles but its vertices or indices are NULL (or no vertices)", i,
                        k.triangle_count);
    if (k.triangle_count && !finite_all(k.vertices, (size_t)k.vertex_count * 3))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.cutters[%u].vertices are not all finite", i);
    for (size_t j = 0; j < (size_t)k.triangle_count * 3; j++)
        if (k.indices[j] >= k.vertex_count)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.cutters[%u].indices[%zu] = %u is out of range (%u vertices)",
                            i, j, k.indices[j], k.vertex_count);
    c->cutters[i] = (vxl_frame_cutter){.remove_outside = k.remove_outside,
                                       .vertices = k.triangle_count ? k.vertices : NULL,
                                       .indices = k.triangle_count ? k.indices : NULL,
                                       .vertex_count = k.triangle_count ? k.vertex_count : 0,
                                       .triangle_count = k.triangle_count};
    return VXL_OK;
}

int vxl_frame_cut_resolve(vxl_frame_cut *c, const vxl_render_params *p, const double model[16], uint32_t technique,
                          vxl_err *e)
{
    memset(c, 0, sizeof *c);
    if (!p->cutaway) return VXL_OK;
    vxl_cutaway ca;
    int rc = read_sized(&ca, sizeof ca, p->cutaway, p->cutaway->struct_size, "cutaway", e);
    if (rc) return rc;
    if (ca.reserved)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.reserved is %u: it must be 0", ca.reserved);
    if (ca.clip_plane_count > VXL_MAX_CLIP_PLANES)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.clip_plane_count %u exceeds %d", ca.clip_plane_count,
                        VXL_MAX_CLIP_PLANES);
    if (ca.cutter_count > VXL_MAX_CUTTERS)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.cutter_count %u exceeds %d", ca.cutter_count,
                        VXL_MAX_CUTTERS);
    if (ca.cutter_count && !ca.cutters)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.cutters is NULL with cutter_count %u", ca.cutter_count);
    if (ca.has_crop > 1)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.has_crop = %u must be 0 or 1", ca.has_crop);
    if (ca.caps_off > 1)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "cutaway.caps_off = %u must be 0 or 1", ca.caps_off);
    for (uint32_t i = 0; i < ca.clip_plane_count && !rc; i++) rc = resolve_plane(c, model, &ca.clip_planes[i], i, e);
    if (!rc && ca.has_crop) rc = resolve_crop(c, model, ca.crop_box, e);
    for (uint32_t i = 0; i < ca.cutter_count && !rc; i++) rc = resolve_cutter(c, &ca, i, e);
    if (rc) return rc;
    c->plane_count = ca.clip_plane_count;
    c->cutter_count = ca.cutter_count;
    c->caps = !ca.caps_off;
    c->any = c->plane_count || c->has_crop || c->cutter_count;
    if (c->any && technique != VXL_TECHNIQUE_RAYCAST)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "cutaway: the slicing techniques (technique %u) do not cut; use technique 0 (raycast)",
                        technique);
    return VXL_OK;
}

/* Keeps lo <= a + b t (and a + b t <= hi when hi > lo) on [*t0, *t1]; n:
 * the function's gradient, the cap's normal when it moves *t0. */
static int keep_between(double a, double b, double lo, double hi, int slab, const double n[3], double *t0, double *t1,
                        double cap[3])
{
    if (b == 0) return a >= lo && (!slab || a <= hi);
    double ta = (lo - a) / b, tb = slab ? (hi - a) / b : (b > 0 ? INFINITY : -INFINITY);
    double enter = fmin(ta, tb), leave = fmax(ta, tb);
    if (enter > *t0) {
        *t0 = enter;
        memcpy(cap, n, 3 * sizeof *n);
    }
    if (leave < *t1) *t1 = leave;
    return *t0 < *t1;
}

int vxl_frame_cut_interval(const vxl_frame_cut *c, const double o[3], const double dir[3], double *t0, double *t1,
                           double cap[3])
{
    cap[0] = cap[1] = cap[2] = 0;
    for (uint32_t i = 0; i < c->plane_count; i++) {
        const double *q = c->plane[i];
        double a = q[0] * o[0] + q[1] * o[1] + q[2] * o[2] + q[3], b = q[0] * dir[0] + q[1] * dir[1] + q[2] * dir[2];
        if (!keep_between(a, b, 0, c->thickness[i], c->thickness[i] > 0, q, t0, t1, cap)) return 0;
    }
    if (c->has_crop)
        for (int r = 0; r < 3; r++) {
            const double n[3] = {c->crop[r], c->crop[4 + r], c->crop[8 + r]}; /* row r: d(box r) / d(voxel) */
            double a = n[0] * o[0] + n[1] * o[1] + n[2] * o[2] + c->crop[12 + r];
            double b = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
            if (!keep_between(a, b, -1, 1, 1, n, t0, t1, cap)) return 0;
        }
    return *t0 < *t1;
}

int vxl_frame_cut_keeps(const vxl_frame_cut *c, const double p[3])
{
    for (uint32_t i = 0; i < c->plane_count; i++) {
        const double *q = c->plane[i];
        double d = q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3];
        if (!(d >= 0) || (c->thickness[i] > 0 && d > c->thickness[i])) return 0;
    }
    if (c->has_crop)
        for (int r = 0; r < 3; r++) {
            double b = c->crop[r] * p[0] + c->crop[4 + r] * p[1] + c->crop[8 + r] * p[2] + c->crop[12 + r];
            if (!(b >= -1 && b <= 1)) return 0;
        }
    return 1;
}

void vxl_frame_cut_plane_floats(const vxl_frame_cut *c, float planes[VXL_MAX_CLIP_PLANES][4],
                                float thickness[VXL_MAX_CLIP_PLANES])
{
    memset(planes, 0, sizeof(float[VXL_MAX_CLIP_PLANES][4]));
    memset(thickness, 0, sizeof(float[VXL_MAX_CLIP_PLANES]));
    for (uint32_t i = 0; i < c->plane_count && i < VXL_MAX_CLIP_PLANES; i++) {
        for (int k = 0; k < 4; k++) planes[i][k] = (float)c->plane[i][k];
        thickness[i] = (float)c->thickness[i];
    }
}
