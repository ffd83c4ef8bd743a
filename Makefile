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
LIBS := -ldl -lpthread -lz -lm $(shell pkg-config --libs OpenImageIO)

LIB_C := $(filter-out csrc/cli.c,$(wildcard csrc/*.c))
LIB_CXX := $(wildcard csrc/*.cpp)
SHADERS := $(wildcard shaders/*.glsl shaders/*.vert shaders/*.frag shaders/*.comp)
OBJ := $(LIB_C:csrc/%.c=$(BUILD)/obj/%.o) $(LIB_CXX:csrc/%.cpp=$(BUILD)/obj/%.o) $(BUILD)/obj/shaders_embedded.o
TESTS_SRC := $(wildcard tests/test_*.c)
TESTS := $(TESTS_SRC:tests/%.c=$(BUILD)/tests/%)

all: $(BUILD)/libvoxlight.so $(BUILD)/voxlight $(BUILD)/voxlight-bench $(BUILD)/voxlight-skipbench $(TESTS)

$(BUILD)/obj/%.o: csrc/%.c $(wildcard csrc/*.h csrc/include/*.h) | $(BUILD)/obj
	$(CC) $(CFLAGS) -c $< -o $@

$(BUILD)/obj/%.o: csrc/%.cpp csrc/include/voxlight.h | $(BUILD)/obj
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

$(BUILD)/voxlight-bench: bench/bench.c $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/voxlight-skipbench: bench/skip_study.c $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/tests/%: tests/%.c tests/harness.h $(wildcard tests/*.h) $(BUILD)/libvoxlight.so | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< -o $@ -L$(BUILD) -lvoxlight -lz -lm -lpthread -Wl,-rpath,'$$ORIGIN/..'

$(BUILD)/obj $(BUILD)/gen $(BUILD)/tests:
	mkdir -p $@

clean:
	rm -rf build build-asan

.PHONY: all clean
