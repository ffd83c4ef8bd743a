# Makefile - driven by build.sh. `make` builds build/libvoxlight.so, build/voxlight
# and the C tests; `make BUILD=build-asan SAN=1` builds the same under ASan+UBSan.
BUILD ?= build
SAN ?= 0

CC ?= cc
CXX ?= g++
WARN := -Wall -Wextra -Werror
OPT := -O2 -g
ifeq ($(SAN),1)
OPT := -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
endif
CFLAGS := -std=c11 -D_GNU_SOURCE $(WARN) $(OPT) -fPIC -fvisibility=hidden -Icsrc/include -Icsrc
CXXFLAGS := -std=c++17 $(WARN) $(OPT) -fPIC -fvisibility=hidden -Icsrc/include $(shell pkg-config --cflags OpenImageIO)
# dcmtk (DICOM, csrc/dicom.cpp): Debian 12's dcmtk.pc names sndfile, which is
# not installed, so the three libraries dcmdata needs are named directly.
DCMTK_LIBS := -ldcmdata -loflog -lofstd
LIBS := -ldl -lpthread -lz -lm $(shell pkg-config --libs OpenImageIO) $(DCMTK_LIBS)

LIB_C := $(filter-out csrc/cli.c csrc/vdb_helper_main.c,$(wildcard csrc/*.c))
LIB_CXX := $(wildcard csrc/*.cpp)
SHADERS := $(wildcard shaders/*.glsl shaders/*.vert shaders/*.frag shaders/*.comp)
OBJ := $(LIB_C:csrc/%.c=$(BUILD)/obj/%.o) $(LIB_CXX:csrc/%.cpp=$(BUILD)/obj/%.o) $(BUILD)/obj/shaders_embedded.o
TESTS_SRC := $(wildcard tests/test_*.c)
TESTS := $(TESTS_SRC:tests/%.c=$(BUILD)/tests/%)

all: $(BUILD)/libvoxlight.so $(BUILD)/voxlight $(BUILD)/voxlight-vdb-read $(BUILD)/voxlight-bench $(BUILD)/voxlight-skipbench $(BUILD)/voxlight-storagebench $(TESTS)

$(BUILD)/obj/%.o: csrc/%.c $(wildcard csrc/*.h csrc/include/*.h) | $(BUILD)/obj
	$(CC) $(CFLAGS) -c $< -o $@

$(BUILD)/obj/%.o: csrc/%.cpp $(wildcard csrc/*.h csrc/include/*.h) | $(BUILD)/obj
	$(CXX) $(CXXFLAGS) -c $< -o $@

# Shaders are embedded at build time so an installed library needs no shader path.
$(BUILD)/embed_files: tools/embed_files.c | $(BUILD)/obj
	$(CC) -std=c11 $(WARN) -O1 $< -o $@

$(BUILD)/gen/shaders_embedded.c: $(BUILD)/embed_files $(SHADERS) | $(BUILD)/gen
	$(BUILD)/embed_files $@ $(SHADERS)

$(BUILD)/obj/shaders_embedded.o: $(BUILD)/gen/shaders_embedded.c
	$(CC) $(CFLAGS) -c $< -o $@

$(BUILD)/libvoxlight.so: $(OBJ)
	$(CXX) -shared $(OPT) -Wl,-soname,libvoxlight.so -Wl,--no-undefined -o $@ $^ $(LIBS)

$(BUILD)/voxlight: csrc/cli.c $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

# The process that reads .vdb files for the library (csrc/vdb_spawn.c): the
# library's objects linked in, so it needs no libvoxlight.so at run time.
$(BUILD)/voxlight-vdb-read: $(BUILD)/obj/vdb_helper_main.o $(OBJ)
	$(CXX) $(OPT) -o $@ $^ $(LIBS)

$(BUILD)/voxlight-bench: bench/bench.c $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/voxlight-skipbench: bench/skip_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/voxlight-storagebench: bench/storage_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/tests/%: tests/%.c tests/harness.h $(wildcard tests/*.h tests/fuzz/*.h) $(BUILD)/libvoxlight.so | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< -o $@ -L$(BUILD) -lvoxlight -lz -lm -lpthread -Wl,-rpath,'$$ORIGIN/..'

$(BUILD)/obj $(BUILD)/gen $(BUILD)/tests:
	mkdir -p $@

# ---- fuzzing (issue 7): `make fuzz` builds one libFuzzer binary per loader
# in build/fuzz/ with Debian's clang under ASan+UBSan, the loaders compiled
# in directly, plus the seed writer; ./build.sh fuzz / test run them.
FUZZ_BUILD := build/fuzz
FUZZ_SAN := -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
FUZZ_CFLAGS := -std=c11 -D_GNU_SOURCE $(WARN) $(FUZZ_SAN) -fsanitize=fuzzer-no-link -Icsrc/include -Icsrc
FUZZ_CXXFLAGS := -std=c++17 $(WARN) $(FUZZ_SAN) -fsanitize=fuzzer-no-link -Icsrc/include -Icsrc \
	$(shell pkg-config --cflags OpenImageIO)
FUZZ_LIB_C := volume.c error.c nifti.c nrrd.c metaimage.c loader_util.c vdb_spawn.c
FUZZ_LIB_CXX := image_stack.cpp vdb.cpp dicom.cpp
FUZZ_OBJ := $(FUZZ_LIB_C:%.c=$(FUZZ_BUILD)/obj/%.o) $(FUZZ_LIB_CXX:%.cpp=$(FUZZ_BUILD)/obj/%.o)
FUZZ_TARGETS := $(patsubst tests/fuzz/fuzz_%.c,$(FUZZ_BUILD)/fuzz_%,$(wildcard tests/fuzz/fuzz_*.c))

fuzz: $(FUZZ_TARGETS) $(FUZZ_BUILD)/make_seeds

$(FUZZ_BUILD)/obj/%.o: csrc/%.c $(wildcard csrc/*.h csrc/include/*.h) | $(FUZZ_BUILD)/obj
	clang $(FUZZ_CFLAGS) -c $< -o $@

$(FUZZ_BUILD)/obj/%.o: csrc/%.cpp $(wildcard csrc/*.h csrc/include/*.h) | $(FUZZ_BUILD)/obj
	clang++ $(FUZZ_CXXFLAGS) -c $< -o $@

$(FUZZ_BUILD)/obj/fuzz_%.o: tests/fuzz/fuzz_%.c tests/fuzz/fuzz_common.h csrc/include/voxlight.h | $(FUZZ_BUILD)/obj
	clang $(FUZZ_CFLAGS) -c $< -o $@

$(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/obj/fuzz_%.o $(FUZZ_OBJ)
	clang++ $(FUZZ_SAN) -fsanitize=fuzzer $^ -o $@ $(LIBS)

$(FUZZ_BUILD)/make_seeds: tests/fuzz/make_seeds.c tests/fuzz/writers.h tests/fuzz/dicom_writer.h tests/nifti_writer.h | $(FUZZ_BUILD)/obj
	$(CC) -std=c11 -D_GNU_SOURCE $(WARN) -O1 -Itests $< -o $@ -lz

$(FUZZ_BUILD)/obj:
	mkdir -p $@

clean:
	rm -rf build build-asan

.PHONY: all clean fuzz
