/* cli_colour.c - the colour volume options and info line (cli_colour.h). */
#include "cli_colour.h"

#include <stdlib.h>
#include <string.h>

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
    const int colour = p && !strcmp(o, "--color-source");
    if (!colour && strcmp(o, "--opacity-source")) return 0;
    if (*i + 1 >= argc) {
        snprintf(err, err_size, "%s needs a value", o);
        return -1;
    }
    const char *val = argv[++*i];
    if (!colour) return opacity_source(val, lo, err, err_size);
    if (vxl_color_source_from_name(val, &p->color_source) == VXL_OK) return 1;
    char names[64];
    names_of(vxl_color_source_name, names, sizeof names);
    snprintf(err, err_size, "unknown --color-source '%s' (%s)", val, names);
    return -1;
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
