/* classified_grid.c - vxl_classified_grid: the classified volume as a
 * participating medium on a regular grid, on the CPU, for renderers that
 * take density and colour grids (Blender's Volume objects, through the
 * voxlight-write-vdb helper). The mapping from the transfer function to
 * extinction per world unit is docs/physical_model.md's; every equation
 * here is the ray caster's (raycast.frag, classify.glsl), evaluated at the
 * reference step of one voxel. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "frame.h"
#include "mat4.h"
#include "srgb.h"
#include "threads.h"
#include "volume.h"
#include "voxlight.h"

/* An opacity of 1 is an infinite extinction; a grid needs a finite one. A
 * voxel of path keeping 2^-24 of the light (float's epsilon, less than any
 * renderer's early termination leaves) is as opaque as the ray caster's. */
#define MIN_VOXEL_TRANSMITTANCE (1.0 / 16777216.0)

/* The normalised value at voxel-space point p: trilinear between voxel
 * centres with clamp-to-edge, as GL_LINEAR reads the volume texture. */
static double sample_value(const vxl_volume *v, const double p[3])
{
    size_t base[3], next[3];
    double w[3];
    for (int a = 0; a < 3; a++) {
        double hi = v->dims[a] - 1.0, q = p[a] < 0 ? 0 : p[a] > hi ? hi : p[a], f = floor(q);
        base[a] = (size_t)f;
        next[a] = base[a] + 1 < v->dims[a] ? base[a] + 1 : base[a];
        w[a] = q - f;
    }
    size_t sx = 1, sy = v->dims[0], sz = (size_t)v->dims[0] * v->dims[1];
    double acc = 0;
    for (int i = 0; i < 8; i++) {
        size_t x = i & 1 ? next[0] : base[0], y = i & 2 ? next[1] : base[1], z = i & 4 ? next[2] : base[2];
        double wt = (i & 1 ? w[0] : 1 - w[0]) * (i & 2 ? w[1] : 1 - w[1]) * (i & 4 ? w[2] : 1 - w[2]);
        if (wt > 0) acc += wt * vxl_volume_texel(v, x * sx + y * sy + z * sz);
    }
    return acc;
}

/* The gradient magnitude in normalised value per voxel: central
 * differences of trilinear samples sample_distance voxels apart (the
 * CENTRAL filter; the other filters differ from it by their smoothing). */
static double gradient_magnitude(const vxl_volume *v, const vxl_frame *f, const double p[3])
{
    double d = f->sample_distance, sum = 0;
    for (int a = 0; a < 3; a++) {
        double lo[3] = {p[0], p[1], p[2]}, hi[3] = {p[0], p[1], p[2]};
        lo[a] -= d;
        hi[a] += d;
        double g = (sample_value(v, hi) - sample_value(v, lo)) / (2 * d);
        sum += g * g;
    }
    return sqrt(sum);
}

/* Opacity of one voxel of path at voxel point p (the gradient-opacity
 * factor applied as raycast.frag applies it at a step of one voxel); col
 * receives the straight colour. */
static double voxel_opacity(const vxl_volume *v, const vxl_frame *f, const double p[3], double col[4])
{
    double vn = sample_value(v, p);
    if (f->gopacity == VXL_GOPACITY_ISO) {
        vxl_frame_classify(f, f->iso_pos, col);
        double d = fabs(f->iso_pos - vn), r = f->iso_thickness, m = gradient_magnitude(v, f, p);
        return m > 0 ? (d <= r * m ? col[3] * (1 - d / (r * m)) : 0) : (d == 0 ? col[3] : 0);
    }
    vxl_frame_classify(f, vn, col);
    if (col[3] <= 0 || f->gopacity != VXL_GOPACITY_BOUNDARY) return col[3];
    return col[3] * pow(fmin(gradient_magnitude(v, f, p) / f->gradient_ref, 1.0), f->gradient_exp);
}

/* What the frame asks that a grid of extinction and colour cannot hold. */
static int check_frame(const vxl_frame *f)
{
    if (f->mode != VXL_MODE_DVR)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT,
                        "a classified grid needs the DVR mode: the '%s' mode is a projection or a surface, not a medium",
                        vxl_mode_name(f->mode));
    if (f->labels.on)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "a classified grid does not bake label maps: render without labels");
    if (f->cut.cutter_count)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT,
                        "a classified grid bakes clip planes and the crop box, not cutter meshes: remove the cutters");
    return VXL_OK;
}

/* Index space of the grid -> voxel space: cell centres spread evenly over
 * the volume's box [-0.5, dim - 0.5]. */
static void cell_to_voxel(const uint32_t vdims[3], const uint32_t gdims[3], double m[16])
{
    memset(m, 0, 16 * sizeof *m);
    for (int a = 0; a < 3; a++) {
        double s = (double)vdims[a] / gdims[a];
        m[5 * a] = s;
        m[12 + a] = 0.5 * s - 0.5;
    }
    m[15] = 1;
}

/* The cells of slices [z0, z1), one job of fill_cells. */
typedef struct slab_job {
    const vxl_volume *vol;
    const vxl_frame *f;
    const double *c2v;
    const uint32_t *dims;
    double voxel_length;
    float *density, *rgb;
    uint32_t z0, z1;
    double max_density; /* out */
} slab_job;

static void *fill_slab(void *arg)
{
    slab_job *j = arg;
    const uint32_t *dims = j->dims;
    double max_sigma = -log(MIN_VOXEL_TRANSMITTANCE);
    const int linear = j->f->color_space == VXL_COLOR_SPACE_LINEAR;
    for (uint32_t z = j->z0; z < j->z1; z++)
        for (uint32_t y = 0; y < dims[1]; y++)
            for (uint32_t x = 0; x < dims[0]; x++) {
                size_t i = ((size_t)z * dims[1] + y) * dims[0] + x;
                double q[4] = {x, y, z, 1}, pv[4], col[4] = {0, 0, 0, 0}, sigma = 0;
                vxl_mat4_transform(j->c2v, q, pv);
                if (!j->f->cut.any || vxl_frame_cut_keeps(&j->f->cut, pv)) {
                    double a = voxel_opacity(j->vol, j->f, pv, col);
                    sigma = a <= 0 ? 0 : fmin(-log1p(-fmin(a, 1.0)), max_sigma);
                }
                double d = sigma / j->voxel_length;
                if (d > j->max_density) j->max_density = d;
                if (j->density) j->density[i] = (float)d;
                /* a medium's albedo is linear: display-referred colours are decoded */
                if (j->rgb)
                    for (int k = 0; k < 3; k++)
                        j->rgb[3 * i + k] = (float)(linear ? fmax(col[k], 0.0) : vxl_srgb_to_linear(col[k]));
            }
    return NULL;
}

/* Every cell, slabs of slices spread over the processors (each cell is
 * independent); a worker that cannot start leaves its slab to this
 * thread. Returns the largest density. */
static double fill_cells(const vxl_volume *vol, const vxl_frame *f, const double c2v[16], const uint32_t dims[3],
                         double voxel_length, float *density, float *rgb)
{
    enum { MAX_WORKERS = 16 };
    unsigned n = vxl_cpu_count();
    n = n > MAX_WORKERS ? MAX_WORKERS : n;
    n = n > dims[2] ? dims[2] : n;
    slab_job jobs[MAX_WORKERS];
    vxl_thread threads[MAX_WORKERS];
    int started[MAX_WORKERS] = {0};
    for (unsigned k = 0; k < n; k++) {
        jobs[k] = (slab_job){.vol = vol, .f = f, .c2v = c2v, .dims = dims, .voxel_length = voxel_length,
                             .density = density, .rgb = rgb,
                             .z0 = (uint32_t)((uint64_t)dims[2] * k / n),
                             .z1 = (uint32_t)((uint64_t)dims[2] * (k + 1) / n)};
        if (k > 0) started[k] = vxl_thread_start(&threads[k], fill_slab, &jobs[k]) == 0;
    }
    double max_density = 0;
    for (unsigned k = 0; k < n; k++) {
        if (k == 0 || !started[k]) fill_slab(&jobs[k]);
        else vxl_thread_join(threads[k]);
    }
    for (unsigned k = 0; k < n; k++) max_density = fmax(max_density, jobs[k].max_density);
    return max_density;
}

static int read_grid_params(const vxl_grid_params *g, const vxl_volume *vol, uint32_t dims[3])
{
    vxl_grid_params q = {0};
    if (g) {
        if (g->struct_size != 0 && g->struct_size < sizeof q)
            return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "vxl_grid_params.struct_size %u is smaller than %u",
                            g->struct_size, (unsigned)sizeof q);
        q = *g;
    }
    uint64_t cells = 1;
    for (int a = 0; a < 3; a++) {
        dims[a] = q.dims[a] ? q.dims[a] : vol->dims[a];
        cells *= dims[a];
    }
    /* the helper's stream and the callers' buffers count cells in 32 bits per axis and 64 in all */
    if (cells > ((uint64_t)1 << 40))
        return vxl_fail(NULL, VXL_ERR_LIMIT, "a grid of %u x %u x %u cells is over 2^40 cells", dims[0], dims[1],
                        dims[2]);
    return VXL_OK;
}

int vxl_classified_grid(const vxl_volume *vol, const vxl_render_params *p, const vxl_grid_params *g,
                        vxl_grid_info *info, float *density, float *rgb)
{
    if (!vol || !info) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "volume or info is NULL");
    if (info->struct_size != 0 && info->struct_size < sizeof *info)
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "vxl_grid_info.struct_size %u is smaller than %u",
                        info->struct_size, (unsigned)sizeof *info);
    if (!vol->texels)
        return vxl_fail(NULL, VXL_ERR_STATE,
                        "a streamed volume has no voxels in memory to classify: load it with streaming off");
    uint32_t dims[3];
    int rc = read_grid_params(g, vol, dims);
    if (rc) return rc;
    vxl_volume_geom geom = vxl_volume_geom_of(vol);
    vxl_frame f;
    rc = vxl_frame_resolve(&f, p, &geom, NULL);
    if (rc) return rc;
    rc = check_frame(&f);
    if (rc) {
        vxl_frame_free(&f);
        return rc;
    }
    double c2v[16], c2w[16];
    cell_to_voxel(vol->dims, dims, c2v);
    vxl_mat4_mul(c2w, f.model, c2v);
    /* One voxel of path is this long in world units: the volume's mean
     * voxel edge (exact for cubic voxels; docs/physical_model.md). */
    const double *m = f.model;
    double det = m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
                 m[8] * (m[1] * m[6] - m[5] * m[2]);
    double voxel_length = cbrt(fabs(det));
    if (!(voxel_length > 0) || !isfinite(voxel_length)) {
        vxl_frame_free(&f);
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "the model matrix has no volume (determinant %g)", det);
    }
    double max_density = 0;
    if (density || rgb) max_density = fill_cells(vol, &f, c2v, dims, voxel_length, density, rgb);
    vxl_frame_free(&f);
    vxl_grid_info out = {.struct_size = sizeof out, .voxel_length = voxel_length, .max_density = max_density};
    memcpy(out.dims, dims, sizeof out.dims);
    memcpy(out.index_to_world, c2w, sizeof c2w);
    *info = out;
    return VXL_OK;
}
