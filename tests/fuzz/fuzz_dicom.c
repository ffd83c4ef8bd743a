/* fuzz_dicom.c - libFuzzer target: arbitrary bytes as a .dcm file through
 * the DICOM reader (csrc/io/dicom.cpp, which the library runs in the
 * voxlight-read-dicom helper), in-process (dcmtk parses it; the series is
 * the file's own, alone in its folder), under ASan+UBSan (see Makefile
 * 'fuzz', ./build.sh fuzz). */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return vxl_fuzz_read(data, size, "dcm", vxl_dicom_read); }
