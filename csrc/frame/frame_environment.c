/* frame_environment.c - params.environment (the World's light, voxlight.h's
 * vxl_environment) validated into the frame: the map's size and pixels, its
 * strength and rotation, and the key the GL side caches its reduction and
 * its irradiance volume by. The pixels stay the caller's. */
#include <math.h>

#include "frame.h"
#include "hash.h"

/* 2^26 pixels (8192 x 8192, 768 MiB of floats) bounds the reduction's work
 * and a garbage size; an HDRI is seldom beyond 16k x 8k = 2^27, and the
 * add-on passes at most 128 x 64. */
#define MAX_PIXELS (1u << 26)

int vxl_frame_resolve_environment(vxl_frame *f, const vxl_render_params *p, vxl_err *e)
{
    const vxl_environment *m = p->environment;
    if (!m) return VXL_OK;
    if (m->struct_size != 0 && m->struct_size < sizeof *m)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                        "environment.struct_size = %u is smaller than vxl_environment (%zu bytes)", m->struct_size,
                        sizeof *m);
    if (m->reserved) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "environment.reserved is %u: it must be 0", m->reserved);
    if (m->width < 1 || m->height < 1 || (uint64_t)m->width * m->height > MAX_PIXELS)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "environment map %ux%u must have 1 to %u pixels", m->width,
                        m->height, MAX_PIXELS);
    if (!m->rgb) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "environment.rgb is NULL");
    if (!(m->strength >= 0 && m->strength <= 1e6))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "environment.strength = %g must be in [0, 1e6]",
                        (double)m->strength);
    if (!isfinite(m->rotation_deg))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "environment.rotation_deg is not a finite number");
    const size_t n = (size_t)m->width * m->height * 3;
    for (size_t i = 0; i < n; i++)
        if (!(m->rgb[i] >= 0 && m->rgb[i] <= 3.4e38f)) /* NaN fails too */
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                            "environment pixel %zu (x %zu, y %zu) channel %zu is %g: radiance must be finite and >= 0",
                            i / 3, i / 3 % m->width, i / 3 / m->width, i % 3, (double)m->rgb[i]);
    f->env.on = 1;
    f->env.rgb = m->rgb;
    f->env.width = m->width;
    f->env.height = m->height;
    f->env.strength = m->strength;
    /* one turn is no turn: the key and the reduction see the same angle */
    f->env.rotation_deg = (float)fmod(m->rotation_deg, 360.0);
    uint64_t key = m->key ? m->key : vxl_fnv_words(14695981039346656037ull, m->rgb, n * sizeof *m->rgb);
    const float shape[4] = {(float)m->width, (float)m->height, f->env.strength, f->env.rotation_deg};
    key = vxl_fnv(key, shape, sizeof shape);
    f->env.key = key ? key : 1;
    return VXL_OK;
}
