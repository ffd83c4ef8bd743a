/* environment_map.c - the World's map reduced to direction cells
 * (environment_map.h). Every map pixel (or sub-pixel, for small maps) is
 * splatted into the cell of its world direction with its solid angle,
 * cos(elevation) du dv: a small bright sun in a large map lands in its cell
 * whole instead of being missed by point samples. */
#include "environment_map.h"

#include <math.h>
#include <string.h>

/* Sub-samples per axis reach at least this many over the sphere, so each
 * of the 8 x 4 cells gets 16 x 16 of them even from a 1x1 map. */
#define MIN_COLUMNS 128u
#define MIN_ROWS 64u

static int cell_of(double z, double azimuth)
{
    int band = (int)floor((z + 1.0) * 0.5 * VXL_ENV_BANDS);
    band = band < 0 ? 0 : band >= VXL_ENV_BANDS ? VXL_ENV_BANDS - 1 : band;
    double a = azimuth / (2.0 * M_PI);
    a -= floor(a); /* [0, 1) from +X, counter-clockwise seen from above */
    int sector = (int)(a * VXL_ENV_SECTORS);
    sector = sector >= VXL_ENV_SECTORS ? VXL_ENV_SECTORS - 1 : sector;
    return band * VXL_ENV_SECTORS + sector;
}

void vxl_environment_cell_direction(int k, double out[3])
{
    const int band = k / VXL_ENV_SECTORS, sector = k % VXL_ENV_SECTORS;
    const double z = -1.0 + (band + 0.5) * 2.0 / VXL_ENV_BANDS, r = sqrt(1.0 - z * z);
    const double azimuth = (sector + 0.5) * 2.0 * M_PI / VXL_ENV_SECTORS;
    out[0] = r * cos(azimuth);
    out[1] = r * sin(azimuth);
    out[2] = z;
}

void vxl_environment_reduce(const float *rgb, uint32_t width, uint32_t height, float strength, float rotation_deg,
                            float out[VXL_ENV_CELLS][3])
{
    double sum[VXL_ENV_CELLS][3], weight[VXL_ENV_CELLS];
    memset(sum, 0, sizeof sum);
    memset(weight, 0, sizeof weight);
    const uint32_t sx = (MIN_COLUMNS + width - 1) / width, sy = (MIN_ROWS + height - 1) / height;
    const double cols = (double)width * sx, rows = (double)height * sy;
    /* the map is read at m = Rz(rotation) d: world azimuth = map azimuth - rotation */
    const double turn = rotation_deg * (M_PI / 180.0);
    for (uint32_t j = 0; j < height * sy; j++) {
        const double elevation = M_PI * ((j + 0.5) / rows - 0.5);
        const double z = sin(elevation), w = cos(elevation);
        const float *row = rgb + (size_t)(j / sy) * width * 3;
        for (uint32_t i = 0; i < width * sx; i++) {
            const double azimuth = M_PI * (1.0 - 2.0 * (i + 0.5) / cols) - turn;
            const int k = cell_of(z, azimuth);
            const float *px = row + (size_t)(i / sx) * 3;
            for (int c = 0; c < 3; c++) sum[k][c] += w * px[c];
            weight[k] += w;
        }
    }
    for (int k = 0; k < VXL_ENV_CELLS; k++)
        for (int c = 0; c < 3; c++) {
            double v = weight[k] > 0 ? sum[k][c] / weight[k] * strength : 0.0;
            out[k][c] = (float)(v < VXL_ENV_MAX_RADIANCE ? v : VXL_ENV_MAX_RADIANCE);
        }
}
