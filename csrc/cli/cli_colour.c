/* cli_colour.c - the colour volume options and info line (cli_colour.h). */
#include "cli_colour.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "srgb.h"

/* "a|b|c" of a name function, for messages. */
static void names_of(const char *(*name)(uint32_t), char *out, size_t size)
{
    out[0] = '\0';
    for (uint32_t v = 0; name(v); v++) {
        size_t n = strlen(out);
        snprintf(out + n, size - n, "%s%s", v ? "|" : "", name(v));
    }
}

static int opacity_source(const char *val, vxl_load_options *lo, char *err, size_t err_size)
{
    if (!strncmp(val, "channel:", 8)) {
        char *end;
        long c = strtol(val + 8, &end, 10);
        if (val[8] < '0' || val[8] > '9' || *end || c < 0 || c > 3) {
            snprintf(err, err_size, "bad --opacity-source '%s': channel:N with N 0..3 (0 red, 1 green, 2 blue, 3 alpha)",
                     val);
            return -1;
        }
        lo->opacity_source = VXL_OPACITY_SOURCE_CHANNEL;
        lo->opacity_channel = (uint32_t)c;
        return 1;
    }
    uint32_t s;
    if (vxl_opacity_source_from_name(val, &s) != VXL_OK || s == VXL_OPACITY_SOURCE_CHANNEL) {
        snprintf(err, err_size, "bad --opacity-source '%s': luminance, alpha or channel:N", val);
        return -1;
    }
    lo->opacity_source = s;
    return 1;
}

int vxl_cli_colour_option(int argc, char **argv, int *i, vxl_render_params *p, vxl_load_options *lo, char *err,
                          size_t err_size)
{
    const char *o = argv[*i];
    const int colour = p && !strcmp(o, "--color-source"), space = p && !strcmp(o, "--color-space");
    if (!colour && !space && strcmp(o, "--opacity-source")) return 0;
    if (*i + 1 >= argc) {
        snprintf(err, err_size, "%s needs a value", o);
        return -1;
    }
    const char *val = argv[++*i];
    if (space) {
        if (!strcmp(val, "display") || !strcmp(val, "linear")) {
            p->color_space = !strcmp(val, "linear") ? VXL_COLOR_SPACE_LINEAR : VXL_COLOR_SPACE_DISPLAY;
            return 1;
        }
        snprintf(err, err_size, "unknown --color-space '%s' (display|linear)", val);
        return -1;
    }
    if (!colour) return opacity_source(val, lo, err, err_size);
    if (vxl_color_source_from_name(val, &p->color_source) == VXL_OK) return 1;
    char names[64];
    names_of(vxl_color_source_name, names, sizeof names);
    snprintf(err, err_size, "unknown --color-source '%s' (%s)", val, names);
    return -1;
}

void vxl_cli_colour_for_output(const vxl_render_params *p, const char *output, float *rgba, size_t pixels)
{
    size_t n = strlen(output);
    if (p->color_space != VXL_COLOR_SPACE_LINEAR || (n >= 4 && !strcmp(output + n - 4, ".exr"))) return;
    for (size_t i = 0; i < pixels; i++) {
        float *px = rgba + 4 * i;
        for (int c = 0; c < 3; c++)
            px[c] = px[3] > 0 ? (float)(vxl_linear_to_srgb(px[c] / px[3]) * px[3]) : 0.0f;
    }
}

void vxl_cli_colour_print_info(const vxl_volume_info *in, FILE *out)
{
    static const char *const kinds[5] = {"?", "grey", "?", "RGB", "RGBA"};
    const uint32_t c = in->components <= 4 ? in->components : 0;
    if (c < 3) {
        fprintf(out, "components:  %u (%s)\n", in->components, kinds[c]);
        return;
    }
    const char *src = in->opacity_source == VXL_OPACITY_SOURCE_LUMINANCE ? "luminance"
                      : in->opacity_source == VXL_OPACITY_SOURCE_ALPHA   ? "alpha"
                                                                         : "one channel (the notes say which)";
    fprintf(out, "components:  %u (%s: colour from the data, %.1f MiB as RGB8; opacity and gradients from %s)\n", c,
            kinds[c], in->color_bytes / 1048576.0, src);
}
