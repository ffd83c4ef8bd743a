/* fuzz_vdb.c - libFuzzer target: arbitrary bytes as a .vdb file through
 * the in-process OpenVDB read (OpenImageIO's OpenVDB reader, csrc/vdb.cpp)
 * and the volume build the library runs on its result, under ASan+UBSan
 * (see Makefile 'fuzz', ./build.sh fuzz). The library itself reads .vdb
 * files in a helper process (csrc/vdb_spawn.c); this target calls what the
 * helper runs, because libFuzzer only sees coverage in its own process. So
 * libopenvdb's assertions still abort here, and the target stays out of
 * tests/fuzz/run.sh's default list (tests/fuzz/upstream/README.md). Seeds
 * are written by tests/fuzz/vdb_seeds.py (pyopenvdb). */
#include <stdlib.h>

#include "fuzz_common.h"
#include "vdb_stream.h"
#include "volume.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = vxl_fuzz_write(data, size, "vdb");
    vxl_vdb_grid g;
    vxl_err e = {0};
    int rc = vxl_vdb_read_dense(path, &vxl_fuzz_options, &g, &e);
    if (rc != VXL_OK && (g.voxels || !e.msg[0])) abort();
    vxl_volume *v = NULL;
    if (rc == VXL_OK) {
        if (!g.voxels) abort();
        rc = vxl_volume_build(g.voxels, VXL_DTYPE_F32, g.dims, g.spacing, g.affine, 0.0, 0.0, &vxl_fuzz_options, &v,
                              NULL);
        free(g.voxels);
        vxl_fuzz_check(rc, v);
    }
    return 0;
}
