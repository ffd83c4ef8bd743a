/* fuzz_vdb.c - libFuzzer target: arbitrary bytes as a .vdb file through
 * vxl_volume_load (OpenImageIO's OpenVDB reader, csrc/vdb.cpp), under
 * ASan+UBSan (see Makefile 'fuzz', ./build.sh fuzz). Seeds are written by
 * tests/fuzz/vdb_seeds.py (pyopenvdb). */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return vxl_fuzz_load(data, size, "vdb"); }
