/* frame_lighting.c - validates and resolves the lighting fields of
 * vxl_render_params into a vxl_frame: the shading model, the
 * lights' shapes (spot cones, softness), occlusion and anisotropy. */
#include <math.h>
#include <string.h>

#include "frame.h"
#include "mat4.h"

#define MAX_AO_RADIUS 64.0f       /* voxels */
#define MAX_ANISOTROPY 0.99f      /* |g| -> 1 makes the phase function a delta */
#define MIN_ILLUMINATION_SIZE 8u
#define MAX_ILLUMINATION_SIZE 1024u
#define MAX_SHAPE_STRUCT_SIZE 4096u /* far beyond any layout; bounds a garbage stride */
#define NO_CONE (-2.0f)
/* pi as a float caller writes it ((float)M_PI rounds up): a full angle */
#define MAX_ANGLE ((double)(float)M_PI)

/* v must lie in [lo, hi] and be finite; the message names the field. */
static int check_range(vxl_err *e, const char *field, int light, double v, double lo, double hi)
{
    if (v >= lo && v <= hi) return VXL_OK;
    if (light >= 0)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light_shapes[%d].%s = %g is out of range [%g, %g]", light,
                        field, v, lo, hi);
    return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "%s = %g is out of range [%g, %g]", field, v, lo, hi);
}

/* The world position or unit direction of light i (frame.c resolved it to
 * view space; the headlight exists only there). */
static int world_light(vxl_frame *f, const vxl_render_params *p, int i, vxl_err *e)
{
    double w[4];
    if (p->light_count == 0) {
        double inv[16], v[4] = {f->light_pos[i][0], f->light_pos[i][1], f->light_pos[i][2], 0};
        if (!vxl_mat4_invert(inv, f->view))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "the view matrix is singular");
        vxl_mat4_transform(inv, v, w);
    } else {
        for (int k = 0; k < 3; k++) w[k] = p->lights[i].position[k];
        w[3] = p->lights[i].position[3] != 0 ? 1 : 0;
    }
    if (w[3] == 0) {
        double n = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        if (!(n > 0) || !isfinite(n)) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light %d direction is zero", i);
        for (int k = 0; k < 3; k++) w[k] /= n;
    }
    for (int k = 0; k < 4; k++) f->light_world[i][k] = (float)w[k];
    return VXL_OK;
}

/* light_shapes[i] as this library's struct: zero past its struct_size. */
static int read_shape(const vxl_render_params *p, uint32_t i, vxl_light_shape *out, vxl_err *e)
{
    uint32_t stride = p->light_shapes[0].struct_size;
    if (stride < sizeof(uint32_t) || stride > MAX_SHAPE_STRUCT_SIZE)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light_shapes[0].struct_size = %u must be in [%zu, %u]", stride,
                        sizeof(uint32_t), MAX_SHAPE_STRUCT_SIZE);
    const unsigned char *base = (const unsigned char *)p->light_shapes + (size_t)i * stride;
    memset(out, 0, sizeof *out);
    memcpy(out, base, stride < sizeof *out ? stride : sizeof *out);
    if (out->struct_size != stride)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "light_shapes[%u].struct_size = %u differs from light_shapes[0]'s %u (one array, one layout)",
                        i, out->struct_size, stride);
    return VXL_OK;
}

static int resolve_shape(vxl_frame *f, const vxl_light_shape *s, int i, vxl_err *e)
{
    int point = f->light_world[i][3] != 0;
    int rc = check_range(e, "spot_angle", i, s->spot_angle, 0, MAX_ANGLE);
    if (!rc) rc = check_range(e, "spot_blend", i, s->spot_blend, 0, 1);
    /* a sun's angular diameter beyond pi would be a light from every side */
    if (!rc) rc = check_range(e, "size", i, s->size, 0, point ? 1e30 : MAX_ANGLE);
    if (rc) return rc;
    f->light_size[i] = s->size;
    f->light_spot_blend[i] = s->spot_blend;
    if (s->spot_angle == 0) return VXL_OK;
    if (!point)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "light_shapes[%d].spot_angle = %g needs a point light (position w = 1), not a directional one",
                        i, s->spot_angle);
    double d[4] = {s->spot_direction[0], s->spot_direction[1], s->spot_direction[2], 0}, v[4];
    for (int k = 0; k < 3; k++)
        if (!isfinite(d[k]))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light_shapes[%d].spot_direction is not finite", i);
    vxl_mat4_transform(f->view, d, v);
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(n > 0) || !isfinite(n))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "light_shapes[%d].spot_direction is zero with spot_angle %g", i,
                        s->spot_angle);
    for (int k = 0; k < 3; k++) f->light_spot_dir[i][k] = (float)(v[k] / n);
    f->light_spot_cos[i] = (float)cos(0.5 * s->spot_angle);
    return VXL_OK;
}

int vxl_frame_resolve_lighting(vxl_frame *f, const vxl_render_params *p, vxl_err *e)
{
    if (p->shading_model >= VXL_SHADING_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown shading_model %u (there are %d)", p->shading_model,
                        VXL_SHADING_COUNT);
    f->shading_model = p->shading_model;
    int rc = check_range(e, "ambient_occlusion", -1, p->ambient_occlusion, 0, MAX_AO_RADIUS);
    if (!rc) rc = check_range(e, "occlusion_strength", -1, p->occlusion_strength, 0, 1);
    if (!rc) rc = check_range(e, "anisotropy", -1, p->anisotropy, -MAX_ANISOTROPY, MAX_ANISOTROPY);
    if (rc) return rc;
    f->ao_radius = p->ambient_occlusion;
    f->ao_strength = p->occlusion_strength == 0 ? 1.0f : p->occlusion_strength;
    f->anisotropy = p->anisotropy;
    if (p->illumination_size != 0 &&
        (p->illumination_size < MIN_ILLUMINATION_SIZE || p->illumination_size > MAX_ILLUMINATION_SIZE))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "illumination_size = %u must be 0 (automatic) or in [%u, %u]",
                        p->illumination_size, MIN_ILLUMINATION_SIZE, MAX_ILLUMINATION_SIZE);
    f->illumination_size = p->illumination_size;
    for (int i = 0; i < f->light_count; i++) {
        f->light_spot_cos[i] = NO_CONE;
        rc = world_light(f, p, i, e);
        if (rc) return rc;
    }
    /* the headlight (light_count 0) has no entries in light_shapes */
    if (!p->light_shapes || p->light_count == 0) return VXL_OK;
    for (uint32_t i = 0; i < p->light_count; i++) {
        vxl_light_shape s;
        rc = read_shape(p, i, &s, e);
        if (!rc) rc = resolve_shape(f, &s, (int)i, e);
        if (rc) return rc;
    }
    return VXL_OK;
}

double vxl_frame_spot_mask(const vxl_frame *f, int i, double cos_a)
{
    double c = f->light_spot_cos[i];
    if (c < -1) return 1; /* no cone */
    double blend = (1 - c) * f->light_spot_blend[i];
    if (!(blend > 0)) return cos_a > c ? 1 : 0;
    double x = (cos_a - c) / blend;
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return x * x * (3 - 2 * x);
}
