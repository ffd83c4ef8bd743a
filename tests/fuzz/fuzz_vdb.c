/* fuzz_vdb.c - libFuzzer target: arbitrary bytes as a .vdb file through
 * the OpenVDB reader (OpenImageIO's OpenVDB reader and the volume build,
 * csrc/io/vdb.cpp), in-process, under ASan+UBSan (see Makefile 'fuzz',
 * ./build.sh fuzz). The library reads .vdb files in the voxlight-read-oiio
 * helper process (csrc/io/reader_stream.h); this target calls what the helper
 * runs, because libFuzzer only sees coverage in its own process. So
 * libopenvdb's assertions still abort here, and tests/fuzz/run.sh fuzzes
 * this target in fork mode (tests/fuzz/upstream/README.md). Seeds are
 * written by tests/fuzz/vdb_seeds.py (pyopenvdb). */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return vxl_fuzz_read(data, size, "vdb", vxl_vdb_read); }
