/* cli_channels.c - the multi-channel options and info lines (cli_channels.h). */
#include "cli_channels.h"

#include <stdlib.h>
#include <string.h>

void vxl_cli_channels_init(vxl_cli_channels *c) { memset(c, 0, sizeof *c); }

/* A channel index 0..VXL_MAX_CHANNELS-1 at s, up to the first of `stops`
 * (or the end); *rest points past it. */
static int channel_index(const char *s, const char *stops, uint32_t *out, const char **rest)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (s[0] < '0' || s[0] > '9' || v < 0 || v >= VXL_MAX_CHANNELS || (*end && !strchr(stops, *end))) return -1;
    *out = (uint32_t)v;
    *rest = end;
    return 0;
}

static int parse_list(const char *val, vxl_cli_channels *c)
{
    if (!strcmp(val, "all")) {
        c->all = 1;
        return 0;
    }
    const char *s = val;
    do {
        uint32_t k;
        if (channel_index(s, ",", &k, &s)) return -1;
        c->mask |= 1u << k;
    } while (*s++ == ',');
    return 0;
}

/* "I:R,G,B" with each in [0, 1] */
static int parse_color(const char *val, vxl_cli_channels *c)
{
    uint32_t k;
    const char *s;
    float rgb[3];
    char tail;
    if (channel_index(val, ":", &k, &s) || *s != ':' ||
        sscanf(s + 1, "%f,%f,%f%c", &rgb[0], &rgb[1], &rgb[2], &tail) != 3)
        return -1;
    for (int j = 0; j < 3; j++)
        if (!(rgb[j] >= 0.0f && rgb[j] <= 1.0f)) return -1;
    memcpy(c->color[k], rgb, sizeof rgb);
    c->color_mask |= 1u << k;
    return 0;
}

/* "I:LO:HI" with LO < HI */
static int parse_window(const char *val, vxl_cli_channels *c)
{
    uint32_t k;
    const char *s;
    float lo, hi;
    char tail;
    if (channel_index(val, ":", &k, &s) || *s != ':' || sscanf(s + 1, "%f:%f%c", &lo, &hi, &tail) != 2 ||
        !(lo < hi))
        return -1;
    c->window[k][0] = lo;
    c->window[k][1] = hi;
    c->window_mask |= 1u << k;
    return 0;
}

int vxl_cli_channels_option(int argc, char **argv, int *i, vxl_cli_channels *c, vxl_load_options *lo, char *err,
                            size_t err_size)
{
    static const char *const load_opts[] = {"--channel", "--channel-axis"};
    static const char *const render_opts[] = {"--channels", "--channel-color", "--channel-window", "--channel-blend"};
    const char *o = argv[*i];
    int which = -1;
    for (int k = 0; k < 2; k++)
        if (!strcmp(o, load_opts[k])) which = k;
    for (int k = 0; c && k < 4; k++)
        if (!strcmp(o, render_opts[k])) which = 2 + k;
    if (which < 0) return 0;
    if (*i + 1 >= argc) {
        snprintf(err, err_size, "%s needs a value", o);
        return -1;
    }
    const char *val = argv[++*i];
    const char *rest;
    uint32_t k;
    switch (which) {
    case 0:
        if (channel_index(val, "", &k, &rest)) break;
        lo->scalar_channel = k;
        if (c) c->scalar_set = 1;
        return 1;
    case 1:
        if (vxl_channels_mode_from_name(val, &lo->channels) != VXL_OK) break;
        return 1;
    case 2:
        if (parse_list(val, c)) break;
        c->drawn = 1;
        return 1;
    case 3:
        if (parse_color(val, c)) break;
        return 1;
    case 4:
        if (parse_window(val, c)) break;
        return 1;
    default:
        if (vxl_channel_blend_from_name(val, &c->blend) != VXL_OK) break;
        return 1;
    }
    static const char *const forms[6] = {"N, a channel 0..7",   "auto, on or off",
                                         "all or I,J,... (0..7)", "I:R,G,B with each 0..1",
                                         "I:LO:HI with LO < HI", "add or max"};
    snprintf(err, err_size, "bad %s '%s': %s", o, val, forms[which]);
    return -1;
}

int vxl_cli_channels_apply(vxl_cli_channels *c, const vxl_load_options *lo, const vxl_volume *v,
                           vxl_render_params *p, char *err, size_t err_size)
{
    vxl_volume_info in;
    memset(&in, 0, sizeof in);
    in.struct_size = sizeof in;
    vxl_volume_get_info(v, &in);
    if (c->scalar_set && !in.channel_count && lo->scalar_channel) {
        snprintf(err, err_size, "--channel %u: the volume has no channels (see voxlight info)", lo->scalar_channel);
        return -1;
    }
    const uint32_t options = c->color_mask | c->window_mask;
    if (!c->drawn) {
        if (options || c->blend) {
            snprintf(err, err_size, "--channel-color, --channel-window and --channel-blend need --channels");
            return -1;
        }
        return 0;
    }
    if (!in.channel_count) {
        snprintf(err, err_size, "--channels: the volume has no channels (see voxlight info)");
        return -1;
    }
    const uint32_t have = (1u << in.channel_count) - 1, mask = c->all ? have : c->mask;
    if (mask & ~have) {
        snprintf(err, err_size, "--channels: the volume has channels 0..%u", in.channel_count - 1);
        return -1;
    }
    if (options & ~mask) {
        snprintf(err, err_size, "--channel-color / --channel-window name a channel --channels does not draw");
        return -1;
    }
    uint32_t n = 0;
    for (uint32_t k = 0; k < in.channel_count; k++) {
        if (!(mask & (1u << k))) continue;
        vxl_channel_style *s = &c->styles[n++];
        memset(s, 0, sizeof *s);
        s->struct_size = sizeof *s;
        s->channel = k;
        s->has_color = (c->color_mask >> k) & 1;
        memcpy(s->color, c->color[k], sizeof s->color);
        s->has_window = (c->window_mask >> k) & 1;
        s->window_low = c->window[k][0];
        s->window_high = c->window[k][1];
    }
    p->channel_count = n;
    p->channel_blend = c->blend;
    p->channels = c->styles;
    return 0;
}

void vxl_cli_channels_print_info(const vxl_volume_info *in, FILE *out)
{
    if (!in->channel_count) return;
    fprintf(out, "channels:    %u (the scalar is channel %u, --channel N; %.1f MiB as 16 bits a channel; "
                 "--channels draws them)\n",
            in->channel_count, in->scalar_channel, in->channel_bytes / 1048576.0);
    for (uint32_t k = 0; k < in->channel_count && k < VXL_MAX_CHANNELS; k++) {
        fprintf(out, "  channel %u: %g .. %g", k, in->channel_min[k], in->channel_max[k]);
        /* what the file says of it: the colour as the file's sRGB hex, as
         * OME writes it (--channel-color takes linear values) */
        if (in->channel_names[k][0]) fprintf(out, "  \"%s\"", in->channel_names[k]);
        if (in->channel_color_known[k])
            fprintf(out, "  colour #%02X%02X%02X (sRGB)", (unsigned)(in->channel_colors[k][0] * 255.0f + 0.5f),
                    (unsigned)(in->channel_colors[k][1] * 255.0f + 0.5f),
                    (unsigned)(in->channel_colors[k][2] * 255.0f + 0.5f));
        if (in->channel_window_known[k])
            fprintf(out, "  window %g .. %g", in->channel_window_low[k], in->channel_window_high[k]);
        if (!in->channel_active[k]) fputs("  hidden in the file", out);
        fputc('\n', out);
    }
}
