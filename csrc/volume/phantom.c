/* phantom.c - analytic test volumes with analytic gradients, the ground
 * truth of the accuracy tests and the benchmark. Coordinates: voxel i maps
 * to u = -1 + 2 i / (n - 1) on each axis. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "phantom_large.h"
#include "volume.h"
#include "voxlight_dev.h"

#define ML_FM 6.0
#define ML_ALPHA 0.25

static const char *const names[VXL_PHANTOM_COUNT] = {NULL,         "marschner-lobb", "sphere",      "ramp",
                                                     "noisy-blob", "sparse-balls",   "dense-balls",
                                                     "large-sparse", "two-blobs"};

#define LATTICE 8
#define BALL_SIGMA 0.06

/* Whether lattice site (i,j,k) holds a ball: every site for the dense twin,
 * a fixed hash-chosen 5% for the sparse one. */
static int site_active(uint32_t kind, int i, int j, int k)
{
    if (kind == VXL_PHANTOM_DENSE_BALLS) return 1;
    uint32_t h = (uint32_t)(i * 73856093) ^ (uint32_t)(j * 19349663) ^ (uint32_t)(k * 83492791);
    h = (h ^ (h >> 13)) * 0x5bd1e995u;
    return (h ^ (h >> 15)) % 100 < 5;
}

/* Sum of the Gaussian balls near u (each reaches ~4 sigma < 1 site). */
static double balls(uint32_t kind, const double u[3], double g[3])
{
    double cell = 2.0 / LATTICE, v = 0;
    int c[3];
    g[0] = g[1] = g[2] = 0;
    for (int a = 0; a < 3; a++) c[a] = (int)floor((u[a] + 1) / cell);
    for (int k = c[2] - 1; k <= c[2] + 1; k++)
        for (int j = c[1] - 1; j <= c[1] + 1; j++)
            for (int i = c[0] - 1; i <= c[0] + 1; i++) {
                if (i < 0 || j < 0 || k < 0 || i >= LATTICE || j >= LATTICE || k >= LATTICE) continue;
                if (!site_active(kind, i, j, k)) continue;
                double d[3] = {u[0] - (-1 + (i + 0.5) * cell), u[1] - (-1 + (j + 0.5) * cell), u[2] - (-1 + (k + 0.5) * cell)};
                double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                if (r2 > 16 * BALL_SIGMA * BALL_SIGMA) continue;
                double e = exp(-r2 / (2 * BALL_SIGMA * BALL_SIGMA));
                v += e;
                for (int a = 0; a < 3; a++) g[a] -= d[a] / (BALL_SIGMA * BALL_SIGMA) * e;
            }
    return v;
}

const char *vxl_phantom_name(uint32_t kind) { return kind < VXL_PHANTOM_COUNT ? names[kind] : NULL; }

static int resolve(const vxl_phantom_desc *d, uint32_t dims[3], vxl_err *e)
{
    if (!d) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "phantom description is NULL");
    if (d->kind == 0 || d->kind >= VXL_PHANTOM_COUNT)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "unknown phantom kind %u", d->kind);
    const uint32_t large[3] = VXL_LARGE_SPARSE_DIMS;
    for (int a = 0; a < 3; a++) {
        dims[a] = d->dims[a] ? d->dims[a] : d->kind == VXL_PHANTOM_LARGE_SPARSE ? large[a] : 64;
        if (dims[a] < 2) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "phantoms need at least 2 voxels per axis");
    }
    return VXL_OK;
}

/* World-space value and gradient at u in [-1,1]^3. */
static double field(uint32_t kind, const double u[3], double g[3])
{
    double x = u[0], y = u[1], z = u[2];
    switch (kind) {
    case VXL_PHANTOM_MARSCHNER_LOBB: {
        double r = sqrt(x * x + y * y), k = 1.0 / (2 * (1 + ML_ALPHA));
        double inner = 2 * M_PI * ML_FM * cos(M_PI * r / 2);
        double rho_r = cos(inner);
        /* d rho_r / dr = sin(inner) * 2 pi fM * sin(pi r / 2) * pi / 2 */
        double drho = sin(inner) * 2 * M_PI * ML_FM * sin(M_PI * r / 2) * M_PI / 2;
        double dr_over_r = r > 1e-12 ? drho / r : sin(inner) * 2 * M_PI * ML_FM * M_PI * M_PI / 4;
        g[0] = k * ML_ALPHA * dr_over_r * x;
        g[1] = k * ML_ALPHA * dr_over_r * y;
        g[2] = k * (-M_PI / 2 * cos(M_PI * z / 2));
        return k * (1 - sin(M_PI * z / 2) + ML_ALPHA * (1 + rho_r));
    }
    case VXL_PHANTOM_SPHERE: { /* ellipsoid semi-axes .7 .5 .6: 0.5 - (|q| - 1) * scale, q = u / axes */
        const double ax[3] = {0.7, 0.5, 0.6};
        double q[3] = {x / ax[0], y / ax[1], z / ax[2]};
        double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        for (int a = 0; a < 3; a++) g[a] = n > 1e-12 ? -0.5 * q[a] / (n * ax[a]) : 0;
        return 0.5 - 0.5 * (n - 1);
    }
    case VXL_PHANTOM_RAMP: {
        const double dir[3] = {0.2672612419124244, 0.5345224838248488, 0.8017837257372732};
        for (int a = 0; a < 3; a++) g[a] = 0.25 * dir[a];
        return 0.5 + 0.25 * (dir[0] * x + dir[1] * y + dir[2] * z);
    }
    case VXL_PHANTOM_SPARSE_BALLS:
    case VXL_PHANTOM_DENSE_BALLS:
        return balls(kind, u, g);
    case VXL_PHANTOM_LARGE_SPARSE:
        return vxl_large_sparse_field(u, g);
    case VXL_PHANTOM_TWO_BLOBS: { /* one casts its shadow on the other under a light along x */
        const double cx = 0.45, s2 = 0.04;
        double v = 0;
        g[0] = g[1] = g[2] = 0;
        for (int b = -1; b <= 1; b += 2) {
            double d[3] = {x - b * cx, y, z}, e = exp(-(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / (2 * s2));
            v += e;
            for (int a = 0; a < 3; a++) g[a] -= d[a] / s2 * e;
        }
        return v;
    }
    default: { /* NOISY_BLOB: Gaussian blob, sigma 0.4 */
        double r2 = x * x + y * y + z * z, s2 = 0.16, v = exp(-r2 / (2 * s2));
        g[0] = -x / s2 * v;
        g[1] = -y / s2 * v;
        g[2] = -z / s2 * v;
        return v;
    }
    }
}

int vxl_phantom_eval(const vxl_phantom_desc *d, const double p[3], double *value, double grad[3])
{
    uint32_t dims[3];
    int rc = resolve(d, dims, NULL);
    if (rc) return rc;
    if (!p || !value || !grad) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "point or output is NULL");
    double u[3], g[3];
    for (int a = 0; a < 3; a++) u[a] = -1 + 2 * p[a] / (dims[a] - 1);
    *value = field(d->kind, u, g);
    for (int a = 0; a < 3; a++) grad[a] = g[a] * 2 / (dims[a] - 1); /* chain rule: du/di */
    return VXL_OK;
}

/* Box-Muller on a 64-bit LCG: reproducible noise without global state. */
static double gaussian(uint64_t *s)
{
    double u1, u2;
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    u1 = ((*s >> 11) + 1.0) / 9007199254740993.0;
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    u2 = (*s >> 11) / 9007199254740992.0;
    return sqrt(-2 * log(u1)) * cos(2 * M_PI * u2);
}

int vxl_phantom_create(const vxl_phantom_desc *d, vxl_volume **out)
{
    uint32_t dims[3];
    if (!out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    int rc = resolve(d, dims, NULL);
    if (rc) return rc;
    double affine[16] = {0};
    for (int a = 0; a < 3; a++) {
        affine[a * 4 + a] = 2.0 / (dims[a] - 1);
        affine[12 + a] = -1.0;
    }
    affine[15] = 1;
    if (d->kind == VXL_PHANTOM_LARGE_SPARSE) return vxl_large_sparse_create(dims, affine, out);
    if ((rc = vxl_volume_check_limits(dims, 4, NULL, NULL))) return rc;
    size_t n = (size_t)dims[0] * dims[1] * dims[2];
    float *data = malloc(n * sizeof *data);
    if (!data) return vxl_fail(NULL, VXL_ERR_NO_MEMORY, "out of memory for the phantom");
    double sigma = d->noise_sigma > 0 ? d->noise_sigma : 0.05;
    uint64_t seed = d->seed * 2654435761ull + 12345;
    for (uint32_t k = 0; k < dims[2]; k++)
        for (uint32_t j = 0; j < dims[1]; j++)
            for (uint32_t i = 0; i < dims[0]; i++) {
                double u[3] = {-1 + 2.0 * i / (dims[0] - 1), -1 + 2.0 * j / (dims[1] - 1), -1 + 2.0 * k / (dims[2] - 1)}, g[3];
                double v = field(d->kind, u, g);
                if (d->kind == VXL_PHANTOM_NOISY_BLOB) v += sigma * gaussian(&seed);
                data[i + (size_t)dims[0] * (j + (size_t)dims[1] * k)] = (float)v;
            }
    double spacing[3] = {affine[0], affine[5], affine[10]};
    rc = vxl_volume_build(data, VXL_DTYPE_F32, dims, spacing, affine, 0, 0, NULL, out, NULL);
    free(data);
    return rc;
}

int vxl_phantom_iso_points(const vxl_phantom_desc *d, double iso, double tol, uint32_t seed, float *pts, uint32_t max,
                           uint32_t *n)
{
    uint32_t dims[3];
    int rc = resolve(d, dims, NULL);
    if (rc) return rc;
    if (!pts || !n || !(tol > 0)) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "points, count or tol is invalid");
    uint64_t s = seed * 6364136223846793005ull + 1;
    *n = 0;
    /* bounded rejection sampling: 1000 tries per point wanted */
    for (uint64_t tries = 0; tries < (uint64_t)max * 1000 && *n < max; tries++) {
        double u[3], g[3];
        for (int k = 0; k < 3; k++) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            u[k] = -0.9 + 1.8 * ((s >> 11) / 9007199254740992.0);
        }
        if (fabs(field(d->kind, u, g) - iso) > tol) continue;
        for (int k = 0; k < 3; k++) pts[3 * *n + k] = (float)((u[k] + 1) * (dims[k] - 1) / 2);
        (*n)++;
    }
    return VXL_OK;
}
