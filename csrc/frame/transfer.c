/* transfer.c - built-in transfer functions (the presets; their names are in
 * names.c). */
#include "transfer.h"

#include <math.h>
#include <string.h>

#include "error.h"
#include "voxlight.h"

static double smoothstep(double a, double b, double x)
{
    double t = (x - a) / (b - a);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

static void set(float *p, double r, double g, double b, double a)
{
    p[0] = (float)r;
    p[1] = (float)g;
    p[2] = (float)b;
    p[3] = (float)a;
}

int vxl_preset_table(uint32_t preset, float *rgba)
{
    for (int i = 0; i < VXL_PRESET_TABLE_SIZE; i++) {
        double x = i / (double)(VXL_PRESET_TABLE_SIZE - 1);
        float *p = rgba + 4 * i;
        switch (preset) {
        case VXL_PRESET_GRAY: set(p, x, x, x, 0.1 * x); break;
        case VXL_PRESET_BONE: /* ivory surfaces, soft ramp so thin bone still shows */
            set(p, 0.85 + 0.15 * x, 0.8 + 0.2 * x, 0.7 + 0.3 * x, 0.6 * smoothstep(0.1, 0.5, x));
            break;
        case VXL_PRESET_HOT: /* black-red-yellow-white heat map */
            set(p, fmin(1, 3 * x), fmin(1, fmax(0, 3 * x - 1)), fmin(1, fmax(0, 3 * x - 2)),
                0.3 * smoothstep(0.05, 0.6, x));
            break;
        case VXL_PRESET_MRI: /* skin in warm tone fading to white matter */
            set(p, 0.8 + 0.2 * x, 0.65 + 0.3 * x, 0.55 + 0.4 * x, 0.25 * smoothstep(0.15, 0.45, x));
            break;
        case VXL_PRESET_CT: /* soft tissue faint red, bone opaque ivory */
            set(p, 0.9, 0.5 + 0.45 * smoothstep(0.3, 0.5, x), 0.4 + 0.5 * smoothstep(0.3, 0.5, x),
                0.02 * smoothstep(0.12, 0.2, x) + 0.7 * smoothstep(0.3, 0.45, x));
            break;
        default: return 0;
        }
    }
    return 1;
}

uint32_t vxl_preset_resolve(uint32_t preset, double value_min, double value_max)
{
    (void)value_max;
    if (preset != VXL_PRESET_AUTO) return preset;
    return value_min <= -500 ? VXL_PRESET_CT : VXL_PRESET_MRI;
}

void vxl_preset_window(uint32_t preset, double mn, double mx, double *lo, double *hi)
{
    if (preset == VXL_PRESET_CT) {
        /* Hounsfield: air to dense bone */
        *lo = -1000;
        *hi = 2000;
        return;
    }
    *lo = mn;
    *hi = mx;
}
