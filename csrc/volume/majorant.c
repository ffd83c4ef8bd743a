/* majorant.c - the PATH model's majorant grid (majorant.h). Delta tracking
 * is unbiased only while the majorant bounds the extinction everywhere in a
 * brick, so the bound errs upwards: the table entries a brick's range can
 * reach are widened by one entry each way (as the occupancy is, bricks.c)
 * and the result rounded up past the shader's float arithmetic. */
#include "majorant.h"

#include <math.h>
#include <stddef.h>

double vxl_voxel_extinction(double a)
{
    if (!(a > 0)) return 0;
    if (a >= 1) return VXL_MAX_VOXEL_EXTINCTION;
    double s = -log1p(-a);
    return s < VXL_MAX_VOXEL_EXTINCTION ? s : VXL_MAX_VOXEL_EXTINCTION;
}

/* Table position of normalised value v (classify.glsl's window_pos times the last index). */
static double table_pos(const vxl_occupancy_rule *f, double v)
{
    double x = (v - f->window_offset) * f->window_scale;
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return x * (f->tf_size - 1);
}

static double entry_opacity(const vxl_occupancy_rule *f, long i)
{
    double a = f->tf[4 * i + 3] * (double)f->opacity_scale;
    return a < 0 ? 0 : a > 1 ? 1 : a;
}

void vxl_bricks_majorant(const vxl_bricks *b, const vxl_occupancy_rule *f, int whole_table, float *out)
{
    size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    double whole = 0;
    for (long i = 0; i < (long)f->tf_size; i++) whole = fmax(whole, entry_opacity(f, i));
    for (size_t k = 0; k < n; k++) {
        double a = whole;
        double u0 = table_pos(f, b->minmax[2 * k]), u1 = table_pos(f, b->minmax[2 * k + 1]);
        if (!whole_table && !isnan(u0) && !isnan(u1)) {
            if (u0 > u1) {
                double t = u0;
                u0 = u1;
                u1 = t;
            }
            long lo = (long)floor(u0) - 1, hi = (long)floor(u1) + 2;
            if (lo < 0) lo = 0;
            if (hi > (long)f->tf_size - 1) hi = (long)f->tf_size - 1;
            a = 0;
            for (long i = lo; i <= hi; i++) a = fmax(a, entry_opacity(f, i));
        }
        double s = vxl_voxel_extinction(a);
        /* the shader's float -log(1 - a) may land an ulp or two above */
        out[k] = s > 0 ? (float)(s * 1.001 + 1e-6) : 0.0f;
    }
}
