/* fuzz_tiff.c - libFuzzer target: arbitrary bytes as a .tif file through the
 * image stack reader (csrc/io/image_stack.cpp, which the library runs in the
 * voxlight-read-oiio helper), in-process, under ASan+UBSan (see Makefile
 * 'fuzz', ./build.sh fuzz). */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return vxl_fuzz_read(data, size, "tif", vxl_image_stack_read); }
