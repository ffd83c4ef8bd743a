// vdb.cpp - OpenVDB (.vdb) float grids through OpenImageIO's OpenVDB reader.
//
// OpenImageIO presents each float/vec3 grid of a .vdb file as a tiled volume
// image (one subimage per grid, 8^3 tiles = VDB leaves, the data window in
// index space). We load one scalar grid: "density" (what Blender's fluid
// and most tools write), else the first single-channel grid OpenImageIO
// lists (it reads float and vec3 grids only; vec3 ones are skipped). Its
// active-voxel bounding box (header metadata
// openvdb:file_bbox_min/max) becomes the dense volume's dims, voxel (0,0,0)
// being index bbox_min; inactive voxels inside the box get the grid's
// background value, as OpenVDB's own dense copy does. The affine is the
// grid's index-to-world transform (openvdb:indextoworld, OpenVDB's row-vector
// matrix, whose row-major storage is our column-major layout) times a
// translation to bbox_min; the units are the file's world units (Blender
// writes scene units), not converted to mm. OpenVDB puts voxel centres at
// integer index coordinates, as we do.
//
// This is the in-process read; only the helper process voxlight-read-oiio
// runs it (helper_oiio.c, reader_stream.h), the library never does.
//
// Hostile input: the box comes from the header and passes the memory budget
// before any voxel is allocated; the voxels are read one tile at a time and
// copied into the box, so a box that disagrees with the data window or an
// odd tile size is an error, never an out-of-bounds write. What we cannot
// guard: OpenImageIO's open() has OpenVDB read every grid of the file (the
// sparse tree, before the dense budget check), and Debian's OpenVDB aborts
// on some malformed files there (tests/fuzz/upstream/README.md): the reason
// this runs in its own process.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

extern "C" {
#include "helper_main.h"
#include "loader_util.h"
}

namespace {

// One dense scalar grid as read by OpenImageIO's OpenVDB reader.
struct vxl_vdb_grid {
    uint32_t dims[3];
    double spacing[3];
    double affine[16];
    float *voxels; // malloc'd dims product floats; free() it
};

std::string grid_name(const OIIO::ImageSpec &spec)
{
    return spec.get_string_attribute("openvdb:name", spec.get_string_attribute("oiio:subimagename"));
}

bool scalar_grid(const OIIO::ImageSpec &spec) { return spec.nchannels == 1 && spec.tile_width > 0; }

// Picks the subimage: "density", else the first scalar grid, and leaves in
// positioned on it.
int select_grid(OIIO::ImageInput &in, const char *path, vxl_err *e)
{
    int first_scalar = -1, density = -1;
    std::string names;
    for (int s = 0; s < 4096 && in.seek_subimage(s, 0); s++) {
        const OIIO::ImageSpec &spec = in.spec();
        std::string n = grid_name(spec);
        names += (names.empty() ? "" : ", ") + n;
        if (!scalar_grid(spec)) continue;
        if (first_scalar < 0) first_scalar = s;
        if (density < 0 && n == "density") density = s;
    }
    (void)in.geterror(); // seeking past the last grid is not an error
    int pick = density >= 0 ? density : first_scalar;
    if (pick < 0)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s' has no scalar float grid (grids: %s)", path,
                        names.empty() ? "none" : names.c_str());
    if (!in.seek_subimage(pick, 0)) {
        std::string msg = in.geterror();
        vxl_one_line(&msg[0]);
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot open grid %d: %s", path, pick, msg.c_str());
    }
    return VXL_OK;
}

bool int3_attribute(const OIIO::ImageSpec &spec, const char *name, long long out[3])
{
    const OIIO::ParamValue *p = spec.find_attribute(name);
    if (!p || p->type().basetype != OIIO::TypeDesc::INT || p->type().basevalues() != 3 || p->nvalues() != 1)
        return false;
    const int *v = static_cast<const int *>(p->data());
    for (int a = 0; a < 3; a++) out[a] = v[a];
    return true;
}

bool index_to_world(const OIIO::ImageSpec &spec, double m[16])
{
    const OIIO::ParamValue *p = spec.find_attribute("openvdb:indextoworld");
    if (!p || p->type().basetype != OIIO::TypeDesc::DOUBLE || p->type().basevalues() != 16 || p->nvalues() != 1)
        return false;
    std::memcpy(m, p->data(), 16 * sizeof(double));
    return true;
}

// Column-major affine of voxel -> world: indextoworld x translate(bbox_min).
// Returns 0 when it is not finite or not invertible.
int grid_affine(const double itw[16], const long long bmin[3], double A[16], double spacing[3])
{
    double dir[3][3], origin[3];
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++) dir[c][r] = itw[c * 4 + r];
    if (itw[3] != 0 || itw[7] != 0 || itw[11] != 0 || itw[15] != 1) return 0; // not affine (e.g. a frustum)
    for (int r = 0; r < 3; r++) {
        origin[r] = itw[12 + r];
        for (int c = 0; c < 3; c++) origin[r] += dir[c][r] * static_cast<double>(bmin[c]);
    }
    for (int c = 0; c < 3; c++) spacing[c] = std::sqrt(dir[c][0] * dir[c][0] + dir[c][1] * dir[c][1] + dir[c][2] * dir[c][2]);
    return vxl_affine_from(dir, origin, A);
}

// Copies the tiles covering [lo, lo+dims) into dense (x fastest).
int read_box(OIIO::ImageInput &in, const char *path, const long long lo[3], const uint32_t dims[3], float *dense,
             vxl_err *e)
{
    const OIIO::ImageSpec spec = in.spec();
    const long long tw = spec.tile_width, th = spec.tile_height, td = spec.tile_depth ? spec.tile_depth : 1;
    if (tw < 1 || th < 1 || td < 1 || tw * th * td > (1 << 24))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unsupported tile size %lldx%lldx%lld", path, tw, th, td);
    const long long org[3] = {spec.x, spec.y, spec.z}, ext[3] = {spec.width, spec.height, spec.depth};
    const long long tile[3] = {tw, th, td};
    long long t0[3], t1[3];
    for (int a = 0; a < 3; a++) {
        long long hi = lo[a] + dims[a] - 1;
        if (lo[a] < org[a] || hi >= org[a] + ext[a])
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': active box [%lld, %lld] on axis %d lies outside the data "
                            "window [%lld, %lld]", path, lo[a], hi, a, org[a], org[a] + ext[a] - 1);
        t0[a] = org[a] + (lo[a] - org[a]) / tile[a] * tile[a];
        t1[a] = org[a] + (hi - org[a]) / tile[a] * tile[a];
    }
    std::vector<float> buf(static_cast<size_t>(tw * th * td));
    const int sub = in.current_subimage();
    for (long long tz = t0[2]; tz <= t1[2]; tz += td)
        for (long long ty = t0[1]; ty <= t1[1]; ty += th)
            for (long long tx = t0[0]; tx <= t1[0]; tx += tw) {
                // one tile (clipped to the data window) into buf, laid out tw x th x td
                const long long te[3] = {std::min(tx + tw, org[0] + ext[0]), std::min(ty + th, org[1] + ext[1]),
                                         std::min(tz + td, org[2] + ext[2])};
                const OIIO::stride_t fs = sizeof(float);
                if (!in.read_tiles(sub, 0, int(tx), int(te[0]), int(ty), int(te[1]), int(tz), int(te[2]), 0, 1,
                                   OIIO::TypeFloat, buf.data(), fs, fs * tw, fs * tw * th)) {
                    std::string msg = in.geterror();
                    vxl_one_line(&msg[0]);
                    return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read the tile at %lld,%lld,%lld: %s", path, tx,
                                    ty, tz, msg.empty() ? "unknown error" : msg.c_str());
                }
                // intersection of this tile with the box, in index space
                const long long base[3] = {tx, ty, tz};
                long long a0[3], a1[3];
                for (int a = 0; a < 3; a++) {
                    a0[a] = base[a] > lo[a] ? base[a] : lo[a];
                    long long end = base[a] + tile[a], bend = lo[a] + dims[a];
                    a1[a] = end < bend ? end : bend;
                }
                for (long long z = a0[2]; z < a1[2]; z++)
                    for (long long y = a0[1]; y < a1[1]; y++) {
                        const float *src = buf.data() + ((z - tz) * th + (y - ty)) * tw + (a0[0] - tx);
                        float *dst = dense + ((static_cast<size_t>(z - lo[2]) * dims[1] + static_cast<size_t>(y - lo[1])) *
                                                  dims[0] + static_cast<size_t>(a0[0] - lo[0]));
                        std::memcpy(dst, src, static_cast<size_t>(a1[0] - a0[0]) * sizeof(float));
                    }
            }
    return VXL_OK;
}

int read_dense(const char *path, const vxl_load_options *opt, vxl_vdb_grid *g, vxl_err *e)
{
    uint64_t fsize = 0;
    int rc = vxl_regular_file(path, &fsize, e);
    if (rc) return rc;
    auto in = OIIO::ImageInput::create("openvdb");
    if (!in) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': this OpenImageIO has no OpenVDB reader", path);
    in->threads(1);
    OIIO::ImageSpec spec;
    if (!in->open(path, spec)) {
        std::string msg = in->geterror();
        vxl_one_line(&msg[0]);
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read OpenVDB file: %s", path,
                        msg.empty() ? "unknown error" : msg.c_str());
    }
    rc = select_grid(*in, path, e);
    if (rc) return rc;
    spec = in->spec();
    std::string name = grid_name(spec);
    long long bmin[3], bmax[3];
    double itw[16];
    if (!int3_attribute(spec, "openvdb:file_bbox_min", bmin) || !int3_attribute(spec, "openvdb:file_bbox_max", bmax) ||
        !index_to_world(spec, itw))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': grid '%s' has no bounding box or transform in its header", path,
                        name.c_str());
    for (int a = 0; a < 3; a++) {
        if (bmax[a] < bmin[a]) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': grid '%s' is empty", path, name.c_str());
        long long n = bmax[a] - bmin[a] + 1;
        g->dims[a] = n > UINT32_MAX ? UINT32_MAX : static_cast<uint32_t>(n);
    }
    if (!grid_affine(itw, bmin, g->affine, g->spacing))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': grid '%s' has a transform that is not an invertible affine map "
                        "(frustum grids are not supported)", path, name.c_str());
    uint64_t nbytes = 0;
    rc = vxl_plan_voxels(path, g->dims, VXL_DTYPE_F32, opt, &nbytes, e);
    if (rc) return rc;
    std::unique_ptr<float, decltype(&std::free)> dense(static_cast<float *>(std::malloc(nbytes)), &std::free);
    if (!dense) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for %llu bytes of voxels", path,
                                static_cast<unsigned long long>(nbytes));
    rc = read_box(*in, path, bmin, g->dims, dense.get(), e);
    if (rc) return rc;
    in->close();
    g->voxels = dense.release();
    return VXL_OK;
}

// The grid, read densely, as a volume; the affine is the file's own (an
// sform).
int read_volume(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    vxl_vdb_grid g;
    std::memset(&g, 0, sizeof g);
    int rc = read_dense(path, opt, &g, e);
    if (rc) return rc;
    std::unique_ptr<float, decltype(&std::free)> voxels(g.voxels, &std::free);
    vxl_err inner = {};
    rc = vxl_volume_build(voxels.get(), VXL_DTYPE_F32, g.dims, g.spacing, g.affine, 0.0, 0.0, opt, out, &inner);
    if (rc) return vxl_fail_in(e, path, &inner);
    (*out)->affine_source = 2;
    return VXL_OK;
}

} // namespace

extern "C" int vxl_vdb_read(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    if (!out) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = nullptr;
    if (!path || !*path) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path is empty");
    try {
        return read_volume(path, opt, out, e);
    } catch (const std::bad_alloc &) {
        vxl_volume_destroy(*out);
        *out = nullptr;
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory", path);
    } catch (const std::exception &x) {
        vxl_volume_destroy(*out);
        *out = nullptr;
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %s", path, x.what());
    } catch (...) {
        vxl_volume_destroy(*out);
        *out = nullptr;
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unexpected error while reading the OpenVDB file", path);
    }
}
