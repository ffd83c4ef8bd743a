/* channel_meta.c - channel names and colours as OME writes them
 * (channel_meta.h). */
#include "channel_meta.h"

#include <string.h>

int vxl_channel_meta_name(vxl_channel_meta *m, const char *name)
{
    memset(m->name, 0, sizeof m->name);
    for (const char *c = name; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f) return VXL_META_REFUSED;
    size_t n = strlen(name);
    const int cut = n >= sizeof m->name;
    if (cut) {
        n = sizeof m->name - 1;
        while (n > 0 && ((unsigned char)name[n] & 0xc0) == 0x80) n--; /* not inside a UTF-8 sequence */
    }
    memcpy(m->name, name, n);
    return cut ? VXL_META_CUT : VXL_META_TAKEN;
}

static int hex_digit(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

int vxl_channel_meta_hex(vxl_channel_meta *m, const char *hex)
{
    if (hex[0] == '#') hex++;
    if (strlen(hex) != 6) return VXL_META_REFUSED;
    int rgb[3];
    for (int k = 0; k < 3; k++) {
        const int hi = hex_digit(hex[2 * k]), lo = hex_digit(hex[2 * k + 1]);
        if (hi < 0 || lo < 0) return VXL_META_REFUSED;
        rgb[k] = hi * 16 + lo;
    }
    for (int k = 0; k < 3; k++) m->color_srgb[k] = (float)rgb[k] / 255.0f;
    m->has_color = 1;
    return VXL_META_TAKEN;
}

void vxl_channel_meta_rgba32(vxl_channel_meta *m, int64_t value)
{
    const uint32_t u = (uint32_t)value; /* the signed integer's bits: 0xRRGGBBAA */
    for (int k = 0; k < 3; k++) m->color_srgb[k] = (float)((u >> (24 - 8 * k)) & 0xffu) / 255.0f;
    m->has_color = 1;
}
