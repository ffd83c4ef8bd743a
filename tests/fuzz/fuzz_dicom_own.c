/* fuzz_dicom_own.c - libFuzzer target: arbitrary bytes as a .dcm file
 * through the DICOM reader on our own Part 10 parser
 * (csrc/io/dicom_dataset_own.cpp, the parser Windows' voxlight-read-dicom.exe
 * runs), in-process, under ASan+UBSan; the Makefile links this target with
 * that backend instead of dcmtk's (see Makefile 'fuzz'). Its seeds are
 * fuzz_dicom's. */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return vxl_fuzz_read(data, size, "dcm", vxl_dicom_read); }
