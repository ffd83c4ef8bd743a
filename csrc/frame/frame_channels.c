/* frame_channels.c - params.channels checked into f->channels (frame.h).
 * Each drawn channel's table and window are resolved against that
 * channel's own value mapping exactly as the scalar's are
 * (vxl_frame_resolve_tf); its classification key keys the GL side's table
 * texture and brick occupancy, so a frame that changes only the camera or
 * another channel rebuilds neither. docs/channels.md. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "frame.h"

void vxl_channel_default_color(uint32_t c, float rgb[3])
{
    /* red, green, blue, magenta, cyan, yellow, orange, white: the first
     * three as an RGB image would show them, the rest apart from those */
    static const float palette[VXL_MAX_CHANNELS][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1},   {1, 0, 1},
                                                        {0, 1, 1}, {1, 1, 0}, {1, 0.5f, 0}, {1, 1, 1}};
    memcpy(rgb, palette[c % VXL_MAX_CHANNELS], 3 * sizeof(float));
}

/* What of the frame multi-channel drawing cannot go with (one message per conflict). */
static int check_combination(const vxl_frame *f, vxl_err *e)
{
    const char *why = NULL;
    if (f->technique != VXL_TECHNIQUE_RAYCAST) why = "the ray caster (technique 0)";
    else if (f->mode != VXL_MODE_DVR) why = "the DVR mode (MIP, MinIP, average and ISO project one scalar)";
    else if (f->classify != VXL_CLASSIFY_POST)
        why = "post classification (pre-classified and pre-integrated tables are of one scalar)";
    else if (f->gopacity != 0) why = "gradient_opacity 0 (none)";
    else if (f->shading && f->shading_model != VXL_SHADING_PHONG)
        why = "PHONG shading or none (the shadowed and scatter models' illumination volumes are of one scalar)";
    else if (f->labels.on) why = "no labels";
    else if (f->overlays.count) why = "no overlays";
    else if (f->env.on) why = "no World's light";
    if (why) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "drawing channels needs %s", why);
    return VXL_OK;
}

/* Style s (index i) against its channel's mapping g into ch, its preset's
 * colours in the frame's colour space. */
static int resolve_one(vxl_frame_channel *ch, const vxl_channel_style *s, uint32_t i, const vxl_volume_geom *g,
                       uint32_t color_space, vxl_err *e)
{
    if (s->reserved) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "channels[%u].reserved is %u: it must be 0", i, s->reserved);
    if (s->has_color) {
        for (int k = 0; k < 3; k++)
            if (!(s->color[k] >= 0.0f && s->color[k] <= 1.0f))
                return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "channels[%u].color[%d] is %g: each must be in [0, 1]", i,
                                k, (double)s->color[k]);
        memcpy(ch->color, s->color, sizeof ch->color);
    } else {
        vxl_channel_default_color(s->channel, ch->color);
    }
    /* the scalar's own resolution of a table and window, on this channel;
     * no window: the channel's data range, AUTO: the grey ramp */
    vxl_render_params q;
    memset(&q, 0, sizeof q);
    q.preset = s->preset ? s->preset : VXL_PRESET_GRAY;
    q.tf_size = s->tf_size;
    q.tf_rgba = s->tf_rgba;
    q.has_window = 1;
    q.window_low = s->has_window ? s->window_low : (float)g->value_min;
    q.window_high = s->has_window ? s->window_high : (float)g->value_max;
    if (!s->has_window && !(q.window_high > q.window_low)) q.window_high = q.window_low + 1.0f; /* a flat channel */
    q.opacity_scale = s->opacity_scale;
    q.color_space = color_space;
    int rc = vxl_frame_resolve_table(&ch->table, &q, g, "channels", i, e);
    if (rc) return rc;
    ch->channel = s->channel;
    return VXL_OK;
}

int vxl_frame_resolve_channels(vxl_frame *f, const vxl_render_params *pin, const vxl_volume_geom *geoms,
                               uint32_t n_channels, vxl_err *e)
{
    vxl_render_params params;
    int rc = vxl_render_params_read(&params, pin, e);
    if (rc) return rc;
    const vxl_render_params *p = &params;
    if (p->channel_count == 0) return VXL_OK;
    if (p->channel_count > VXL_MAX_CHANNELS)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "channel_count %u exceeds %d", p->channel_count, VXL_MAX_CHANNELS);
    if (!p->channels)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "params.channels is NULL with channel_count %u", p->channel_count);
    if (p->channel_blend >= VXL_CHANNEL_BLEND_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "channel_blend %u is unknown (0 add, 1 max)", p->channel_blend);
    if (n_channels == 0)
        return vxl_fail(e, VXL_ERR_STATE,
                        "params.channels lists %u channels, but the volume has none (it is not multi-channel)",
                        p->channel_count);
    if ((rc = check_combination(f, e))) return rc;
    const uint32_t stride =
        p->channels[0].struct_size ? p->channels[0].struct_size : (uint32_t)sizeof(vxl_channel_style);
    if (stride < sizeof(vxl_channel_style))
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "channels[0].struct_size %u is smaller than vxl_channel_style (%zu)",
                        stride, sizeof(vxl_channel_style));
    const vxl_channel_style *styles[VXL_MAX_CHANNELS];
    uint32_t listed = 0, solo = 0;
    for (uint32_t i = 0; i < p->channel_count; i++) {
        const vxl_channel_style *s = (const vxl_channel_style *)((const char *)p->channels + (size_t)i * stride);
        if (s->channel >= n_channels)
            return vxl_fail(e, VXL_ERR_STATE, "channels[%u] names channel %u: the volume has channels 0..%u", i,
                            s->channel, n_channels - 1);
        if (listed & (1u << s->channel))
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "channels[%u]: channel %u is listed twice", i, s->channel);
        if (s->hidden > 1 || s->solo > 1)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "channels[%u]: hidden and solo are 0 or 1 (%u, %u)", i,
                            s->hidden, s->solo);
        listed |= 1u << s->channel;
        solo |= s->solo;
        styles[i] = s;
    }
    f->channels.on = 1;
    f->channels.listed = p->channel_count;
    f->channels.blend = p->channel_blend;
    for (uint32_t i = 0; i < p->channel_count && !rc; i++) {
        const vxl_channel_style *s = styles[i];
        if (s->hidden || (solo && !s->solo)) continue;
        vxl_frame_channel *ch = &f->channels.ch[f->channels.count++]; /* counted first: vxl_frame_free frees it */
        rc = resolve_one(ch, s, i, &geoms[s->channel], f->color_space, e);
    }
    if (rc) vxl_frame_channels_free(f);
    return rc;
}

void vxl_frame_channels_free(vxl_frame *f)
{
    for (uint32_t k = 0; k < VXL_MAX_CHANNELS; k++) {
        free(f->channels.ch[k].table.tf_copy);
        f->channels.ch[k].table.tf_copy = NULL;
    }
    f->channels.count = 0;
    f->channels.on = 0;
}
