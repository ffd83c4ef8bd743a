// vdb_write.cpp - vxl_vdb_write: dense density and colour grids into a
// sparse OpenVDB file (vdb_write.h). Only the helper voxlight-write-vdb
// links this; OpenVDB's exceptions end here as a message.
#include <openvdb/openvdb.h>

#include <cstdio>
#include <exception>

extern "C" {
#include "vdb_write.h"
}

int vxl_vdb_write(const char *path, const uint32_t dims[3], const double m[16], const float *density,
                  const float *rgb, char *err, size_t err_size)
{
    try {
        openvdb::initialize();
        // OpenVDB's matrices act on row vectors: its row-major storage is
        // our column-major layout, so the 16 values go in as they are.
        openvdb::math::Mat4d mat(m);
        auto xform = openvdb::math::Transform::createLinearTransform(mat);
        auto dgrid = openvdb::FloatGrid::create(0.0f);
        auto cgrid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        dgrid->setName("density");
        dgrid->setGridClass(openvdb::GRID_FOG_VOLUME);
        cgrid->setName("color");
        dgrid->setTransform(xform);
        cgrid->setTransform(xform->copy());
        auto da = dgrid->getAccessor();
        auto ca = cgrid->getAccessor();
        size_t i = 0;
        for (uint32_t z = 0; z < dims[2]; z++)
            for (uint32_t y = 0; y < dims[1]; y++)
                for (uint32_t x = 0; x < dims[0]; x++, i++) {
                    if (!(density[i] > 0)) continue;
                    openvdb::Coord c((int)x, (int)y, (int)z);
                    da.setValue(c, density[i]);
                    ca.setValue(c, openvdb::Vec3s(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]));
                }
        openvdb::GridPtrVec grids{dgrid, cgrid};
        openvdb::io::File file(path);
        file.write(grids);
        file.close();
        return 0;
    } catch (const std::exception &e) {
        std::snprintf(err, err_size, "OpenVDB could not write %s: %s", path, e.what());
        return 1;
    }
}
