/* phantom_large.c - the large sparse phantom: analytic field and a fast
 * generator that touches only the voxels within 4 sigma of a ball. */
#include "phantom_large.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const int lattice[3] = {12, 8, 2};
static const double sigma[3] = {0.012, 0.02, 0.06}; /* in u; ~15x15x12 voxels at 2500x1500x400 */

static int site_on(int i, int j, int k)
{
    uint32_t h = (uint32_t)(i * 73856093) ^ (uint32_t)(j * 19349663) ^ (uint32_t)(k * 83492791);
    h = (h ^ (h >> 13)) * 0x5bd1e995u;
    return (h ^ (h >> 15)) % 100 < 30;
}

static void site_centre(int i, int j, int k, double c[3])
{
    const int s[3] = {i, j, k};
    for (int a = 0; a < 3; a++) c[a] = -1 + (s[a] + 0.5) * 2.0 / lattice[a];
}

/* One ball's value at u (0 beyond 4 sigma, where it is below 3.4e-4). */
static double ball(const double c[3], const double u[3], double g[3])
{
    double r2 = 0, d[3];
    for (int a = 0; a < 3; a++) {
        d[a] = (u[a] - c[a]) / sigma[a];
        r2 += d[a] * d[a];
    }
    if (r2 > 16) return 0;
    double e = exp(-r2 / 2);
    if (g)
        for (int a = 0; a < 3; a++) g[a] -= d[a] / sigma[a] * e;
    return e;
}

double vxl_large_sparse_field(const double u[3], double g[3])
{
    int s[3];
    for (int a = 0; a < 3; a++) {
        s[a] = (int)floor((u[a] + 1) * lattice[a] / 2);
        s[a] = s[a] < 0 ? 0 : s[a] >= lattice[a] ? lattice[a] - 1 : s[a];
    }
    g[0] = g[1] = g[2] = 0;
    if (!site_on(s[0], s[1], s[2])) return 0; /* balls never reach out of their cell */
    double c[3];
    site_centre(s[0], s[1], s[2], c);
    return ball(c, u, g);
}

int vxl_large_sparse_create(const uint32_t dims[3], const double affine[16], vxl_volume **out)
{
    *out = NULL;
    int rc = vxl_volume_check_limits(dims, 1, NULL, NULL);
    if (rc) return rc;
    vxl_volume *v = calloc(1, sizeof *v);
    size_t n = (size_t)dims[0] * dims[1] * dims[2];
    uint8_t *t = v ? calloc(n, 1) : NULL;
    if (!t) {
        free(v);
        return vxl_fail(NULL, VXL_ERR_NO_MEMORY, "out of memory for the %ux%ux%u phantom", dims[0], dims[1], dims[2]);
    }
    uint8_t peak = 0;
    for (int k = 0; k < lattice[2]; k++)
        for (int j = 0; j < lattice[1]; j++)
            for (int i = 0; i < lattice[0]; i++) {
                if (!site_on(i, j, k)) continue;
                double c[3];
                site_centre(i, j, k, c);
                uint32_t lo[3], hi[3]; /* voxels within 4 sigma */
                for (int a = 0; a < 3; a++) {
                    double s = (dims[a] - 1) / 2.0, l = floor((c[a] - 4 * sigma[a] + 1) * s), h = ceil((c[a] + 4 * sigma[a] + 1) * s);
                    lo[a] = l < 0 ? 0 : (uint32_t)l;
                    hi[a] = h > dims[a] - 1 ? dims[a] - 1 : (uint32_t)h;
                }
                for (uint32_t z = lo[2]; z <= hi[2]; z++)
                    for (uint32_t y = lo[1]; y <= hi[1]; y++)
                        for (uint32_t x = lo[0]; x <= hi[0]; x++) {
                            const double u[3] = {-1 + 2.0 * x / (dims[0] - 1), -1 + 2.0 * y / (dims[1] - 1),
                                                 -1 + 2.0 * z / (dims[2] - 1)};
                            uint8_t q = (uint8_t)lround(ball(c, u, NULL) * 255);
                            t[x + (size_t)dims[0] * (y + (size_t)dims[1] * z)] = q;
                            peak = q > peak ? q : peak;
                        }
            }
    memcpy(v->dims, dims, sizeof v->dims);
    v->src_dtype = VXL_DTYPE_U8;
    v->texture_bits = 8;
    v->texels = t;
    v->storage_bytes = n;
    v->tex_lo = 0; /* stored k/255 is the field value */
    v->tex_hi = 1;
    v->value_min = 0;
    v->value_max = peak / 255.0;
    for (int a = 0; a < 3; a++) v->spacing[a] = affine[5 * a];
    memcpy(v->affine, affine, sizeof v->affine);
    *out = v;
    return VXL_OK;
}
