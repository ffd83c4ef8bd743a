/* srgb.h - the sRGB transfer function (IEC 61966-2-1), for the library's
 * display-referred colours (its presets, a colour volume's RGB) where the
 * caller works in scene-linear colour (VXL_COLOR_SPACE_LINEAR), and the
 * CLI's PNG of a scene-linear image. */
#ifndef VXL_SRGB_H
#define VXL_SRGB_H

#include <math.h>

/* An sRGB-encoded value in [0, 1] (clamped; NaN gives 0) -> linear. */
static inline double vxl_srgb_to_linear(double c)
{
    c = c > 0 ? (c < 1 ? c : 1) : 0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* Linear (clamped to [0, 1]; NaN gives 0) -> sRGB-encoded. */
static inline double vxl_linear_to_srgb(double c)
{
    c = c > 0 ? (c < 1 ? c : 1) : 0;
    return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1 / 2.4) - 0.055;
}

#endif
