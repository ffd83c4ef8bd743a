/* fuzz_nifti.c - libFuzzer target: arbitrary bytes as a .nii file through
 * vxl_volume_load, under ASan+UBSan (see Makefile 'fuzz', ./build.sh fuzz). */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return vxl_fuzz_load(data, size, "nii"); }
