# Makefile - driven by build.sh. `make` builds build/libvoxlight.so, build/voxlight
# and the C tests; `make BUILD=build-asan SAN=1` builds the same under ASan+UBSan.
BUILD ?= build
SAN ?= 0

CC ?= cc
CXX ?= g++
# The library's C (its objects, libvoxlight.so, the CLI) is compiled by
# LIB_CC: build.sh names zig's clang targeting glibc 2.28, the oldest glibc
# official Blender runs on (a compiler of this Debian links its own newer
# glibc's symbol versions); tests, helpers and benchmarks use CC. Without
# LIB_CC on the command line a build folder keeps the compiler it was last
# built with (its stamp below), so a later `make build/tests/x` matches.
ifeq ($(origin LIB_CC),undefined)
LIB_CC := $(or $(shell cat $(BUILD)/obj/lib_cc.txt 2>/dev/null),$(CC))
endif
WARN := -Wall -Wextra -Werror
OPT := -O2 -g
ifeq ($(SAN),1)
OPT := -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
endif
# csrc/ holds one folder per pipeline stage (docs/architecture.md); the
# layer order is checked by tools/check_includes.py. Sources are found by
# wildcard over the folders, objects stay flat in $(BUILD)/obj/ (file names
# are unique across csrc/), and each folder is on the include path after
# csrc/include, so `#include "error.h"` names no folder.
CSRC_DIRS := $(filter-out csrc/include,$(patsubst %/,%,$(sort $(dir $(wildcard csrc/*/*.c csrc/*/*.cpp csrc/*/*.h)))))
CSRC_INC := $(addprefix -I,$(CSRC_DIRS))
vpath %.c $(CSRC_DIRS)
vpath %.cpp $(CSRC_DIRS)
# openjpeg.h (Debian's libopenjp2-7-dev) for the types of io/dicom_j2k.c's
# table: OpenJPEG itself is opened at run time, never linked. After every
# other folder, as the system's own headers are.
OPENJPEG_INC := $(patsubst -I%,-idirafter %,$(shell pkg-config --cflags-only-I libopenjp2))
CFLAGS := -std=c11 -D_GNU_SOURCE $(WARN) $(OPT) -fPIC -fvisibility=hidden -Icsrc/include $(CSRC_INC) -I$(BUILD)/gen \
	$(OPENJPEG_INC)
CXXFLAGS := -std=c++17 $(WARN) $(OPT) -fPIC -fvisibility=hidden -Icsrc/include $(CSRC_INC) $(shell pkg-config --cflags OpenImageIO)
OIIO_LIBS := $(shell pkg-config --libs OpenImageIO)
# dcmtk (DICOM, csrc/io/dicom.cpp): Debian 12's dcmtk.pc names sndfile, which is
# not installed, so the three libraries dcmdata needs are named directly.
DCMTK_LIBS := -ldcmjpeg -ldcmjpls -ldcmdata -loflog -lofstd

# libvoxlight.so is C and links only the C runtime: the readers
# that need OpenImageIO or dcmtk are built into helper processes next to it
# (csrc/io/reader_stream.h), one per library, so a missing library breaks only
# its own formats: voxlight-read-oiio (TIFF/PNG stacks, OpenVDB) and
# voxlight-read-dicom (DICOM). csrc/*/helper_*.c are the helpers' own files.
OIIO_CXX := csrc/io/image_stack.cpp csrc/io/vdb.cpp csrc/io/environment_exr.cpp
# The DICOM reader's rooms, and the two backends of its data set seam
# (csrc/io/dicom_dataset.hpp), one linked per helper: dcmtk's parser and
# codecs in voxlight-read-dicom (Linux), our own parser in
# voxlight-read-dicom.exe (Windows, where dcmtk has no build) and in the
# test helper voxlight-read-dicom-own, which the DICOM tests compare with
# the dcmtk one file for file.
DICOM_CXX := $(filter-out csrc/io/dicom_dataset_%.cpp,$(wildcard csrc/io/dicom*.cpp))
DICOM_DCMTK_CXX := csrc/io/dicom_dataset_dcmtk.cpp
DICOM_OWN_CXX := csrc/io/dicom_dataset_own.cpp
# the DICOM codecs in our own C, and JPEG 2000 through OpenJPEG opened at
# run time (the helper links them; so do their tests and the fuzz build)
DICOM_CODECS := dicom_rle dicom_jpeg_lossless dicom_j2k
HELPER_C := $(wildcard csrc/*/helper_*.c)
# csrc/cli/*.c: the command-line tool's own files, linked into it alone.
CLI_C := $(wildcard csrc/cli/*.c)
# OME-Zarr (csrc/io/zarr.h): the same objects are in the library (the brick
# source streams chunks, zarr_source.c) and in the helper voxlight-read-zarr
# (whole reads); libzstd and libblosc are dlopen'ed on the first chunk that
# needs one (zarr_codecs.c), never linked, so neither links them.
ZARR_C := csrc/io/json.c csrc/io/zarr_store.c csrc/io/zarr_chunk.c csrc/io/zarr_read.c csrc/io/zarr_codecs.c
# csrc/platform/*_win32.c are the Windows build's (make windows).
LIB_C := $(filter-out $(CLI_C) $(HELPER_C) %_win32.c,$(wildcard csrc/*/*.c))
LIBS := -ldl -lpthread -lm
# shaders/lib: included code; compute/: compute programs; render/: the ray
# caster's stages. A shader's name is its path under shaders/ (csrc/gl/shader_source.h).
SHADERS := $(wildcard shaders/lib/*.glsl shaders/compute/*.comp shaders/render/*.vert shaders/render/*.frag)
OBJ := $(patsubst %.c,$(BUILD)/obj/%.o,$(notdir $(LIB_C))) $(BUILD)/obj/shaders_embedded.o
# What the helpers' readers use of the core (volume building, errors, file
# helpers), linked into each helper, which needs no libvoxlight.so.
# The platform room's files for this OS (csrc/platform/), for whatever links
# library objects without the library.
PLATFORM := dynlib dynlib_posix threads_posix files files_posix process_posix clock_posix os_posix
HELPER_CORE_NAMES := helper_main volume colour_volume channel_volume channel_meta ome_xml brick_source error loader_util zlib_api
HELPER_CORE := $(patsubst %,$(BUILD)/obj/%.o,$(HELPER_CORE_NAMES) helper_self_posix $(PLATFORM))
HELPERS := $(BUILD)/voxlight-read-oiio $(BUILD)/voxlight-read-dicom $(BUILD)/voxlight-read-dicom-own \
	$(BUILD)/voxlight-read-zarr $(BUILD)/voxlight-write-vdb
# One-off measurement programs behind docs/filters_on_scans.md, built with
# everything else so they keep compiling (run by hand; commands in the doc).
STUDIES := $(BUILD)/filter-scan-study $(BUILD)/cubic-probe-study $(BUILD)/voxlight-slicingbench $(BUILD)/voxlight-modesbench \
           $(BUILD)/voxlight-labelsbench $(BUILD)/voxlight-streambench $(BUILD)/voxlight-overlaysbench \
           $(BUILD)/voxlight-channelsbench
TESTS_SRC := $(wildcard tests/test_*.c)
TESTS := $(TESTS_SRC:tests/%.c=$(BUILD)/tests/%)

all: $(BUILD)/libvoxlight.so $(BUILD)/voxlight $(BUILD)/tests/render_scene $(BUILD)/tests/child_program $(HELPERS) $(BUILD)/voxlight-bench $(BUILD)/voxlight-skipbench $(BUILD)/voxlight-storagebench $(BUILD)/voxlight-lightbench $(BUILD)/voxlight-sceneshadowbench $(BUILD)/voxlight-envbench $(BUILD)/voxlight-pathbench $(STUDIES) $(TESTS)

# Objects are rebuilt when LIB_CC changes (the stamp holds the last one).
LIB_CC_STAMP := $(BUILD)/obj/lib_cc.txt
$(LIB_CC_STAMP): FORCE | $(BUILD)/obj
	@echo '$(LIB_CC)' | cmp -s - $@ || echo '$(LIB_CC)' > $@
FORCE:
.PHONY: FORCE

$(BUILD)/obj/%.o: %.c $(wildcard csrc/*/*.h) $(LIB_CC_STAMP) | $(BUILD)/obj
	$(LIB_CC) $(CFLAGS) -c $< -o $@

$(BUILD)/obj/%.o: %.cpp $(wildcard csrc/*/*.h csrc/*/*.hpp) | $(BUILD)/obj
	$(CXX) $(CXXFLAGS) -c $< -o $@

# Shaders are embedded at build time so an installed library needs no shader path.
$(BUILD)/embed_files: tools/embed_files.c | $(BUILD)/obj
	$(CC) -std=c11 $(WARN) -O1 $< -o $@

$(BUILD)/gen/shaders_embedded.c: $(BUILD)/embed_files $(SHADERS) | $(BUILD)/gen
	$(BUILD)/embed_files $@ shaders $(SHADERS)

$(BUILD)/obj/shaders_embedded.o: $(BUILD)/gen/shaders_embedded.c $(LIB_CC_STAMP)
	$(LIB_CC) $(CFLAGS) -c $< -o $@

$(BUILD)/libvoxlight.so: $(OBJ)
	$(LIB_CC) -shared $(OPT) -Wl,-soname,libvoxlight.so -Wl,--no-undefined -o $@ $^ $(LIBS)

# Which library file and Debian package each helper needs, for the message a
# user gets when one is missing (csrc/io/remote_readers.c): the SONAME of the
# .so this build links and `dpkg -S` of its real path ("" when dpkg cannot
# tell; the message then names the file alone).
%/gen/reader_packages.h: Makefile
	@mkdir -p $(@D)
	@{ echo '/* generated by the Makefile from the libraries this build links */'; \
	  for spec in OIIO:libOpenImageIO.so DCMTK:libdcmdata.so BLOSC:libblosc.so ZSTD:libzstd.so; do \
	    id=$${spec%%:*}; lib=$${spec#*:}; \
	    real=$$(readlink -f "$$($(CXX) -print-file-name=$$lib)"); \
	    so=$$(objdump -p "$$real" 2>/dev/null | awk '/SONAME/ {print $$2; exit}'); \
	    pkg=$$(dpkg -S "$$real" 2>/dev/null | head -n 1 | cut -d: -f1); \
	    echo "#define VXL_$${id}_SONAME \"$${so:-$$lib}\""; \
	    echo "#define VXL_$${id}_PACKAGE \"$$pkg\""; \
	  done; } > $@.tmp && mv $@.tmp $@

$(BUILD)/obj/remote_readers.o: $(BUILD)/gen/reader_packages.h

# The CLI: the public API from libvoxlight, plus its own copy of the
# platform room (UTF-8 arguments, files, the clock, opening zlib for its
# MatCap PNG), which the library keeps to itself.
$(BUILD)/voxlight: $(CLI_C) $(wildcard csrc/cli/*.h) $(BUILD)/libvoxlight.so $(PLATFORM:%=$(BUILD)/obj/%.o) $(LIB_CC_STAMP)
	$(LIB_CC) $(CFLAGS) $(CLI_C) $(PLATFORM:%=$(BUILD)/obj/%.o) -o $@ -L$(BUILD) -lvoxlight -ldl -lpthread -lm \
		-Wl,-rpath,'$$ORIGIN'

# The reader helpers (csrc/io/reader_stream.h): the C++ readers, the core
# objects they use and their library; started by libvoxlight.so.
$(BUILD)/voxlight-read-oiio: $(BUILD)/obj/helper_oiio.o $(patsubst %.cpp,$(BUILD)/obj/%.o,$(notdir $(OIIO_CXX))) $(HELPER_CORE)
	$(CXX) $(OPT) -o $@ $^ $(OIIO_LIBS) -lz -lm

# The OpenVDB writer (csrc/io/vdb_write.h): classified grids in on standard
# input, a .vdb file out; the add-on starts it to make a Blender Volume.
# libopenvdb (Debian's libopenvdb-dev) is linked here alone.
# OpenVDB's grid registry is template statics shared with libopenvdb: its
# types must keep default visibility here (hidden, initialize() crashes).
$(BUILD)/obj/vdb_write.o: CXXFLAGS += -fvisibility=default
$(BUILD)/voxlight-write-vdb: $(BUILD)/obj/helper_write_vdb.o $(BUILD)/obj/vdb_write.o
	$(CXX) $(OPT) -o $@ $^ -lopenvdb -ltbb $(shell pkg-config --libs Imath 2>/dev/null) -lm

# The Zarr helper is our C alone (its codecs are opened at run time), so it
# is built as the library is, for glibc 2.28.
$(BUILD)/voxlight-read-zarr: $(BUILD)/obj/helper_zarr.o $(patsubst %.c,$(BUILD)/obj/%.o,$(notdir $(ZARR_C))) \
		$(BUILD)/obj/zarr_detect.o $(HELPER_CORE) $(LIB_CC_STAMP)
	$(LIB_CC) $(OPT) -o $@ $(filter-out $(LIB_CC_STAMP),$^) -ldl -lpthread -lm

DICOM_HELPER_OBJ := $(BUILD)/obj/helper_dicom.o $(patsubst %.cpp,$(BUILD)/obj/%.o,$(notdir $(DICOM_CXX))) \
	$(DICOM_CODECS:%=$(BUILD)/obj/%.o) $(HELPER_CORE)
$(BUILD)/voxlight-read-dicom: $(DICOM_HELPER_OBJ) $(BUILD)/obj/dicom_dataset_dcmtk.o
	$(CXX) $(OPT) -o $@ $^ $(DCMTK_LIBS) -lz -lm
# the same reader on our own parser: no dcmtk (zlib is opened at run time)
$(BUILD)/voxlight-read-dicom-own: $(DICOM_HELPER_OBJ) $(BUILD)/obj/dicom_dataset_own.o
	$(CXX) $(OPT) -o $@ $^ -ldl -lpthread -lm

$(BUILD)/voxlight-bench: bench/bench.c $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/voxlight-skipbench: bench/skip_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/filter-scan-study: bench/filter_scan_study.c $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/cubic-probe-study: bench/cubic_probe_study.c $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/voxlight-slicingbench: bench/slicing_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/voxlight-storagebench: bench/storage_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/voxlight-lightbench: bench/lighting_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

# frame time against the number of labels (docs/labels.md)
$(BUILD)/voxlight-labelsbench: bench/labels_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

# open, first and refined frame, F12, bytes read and peak RSS of one file (docs/streaming.md)
$(BUILD)/voxlight-streambench: bench/stream_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

# frame time against the number of overlays (docs/overlays.md)
$(BUILD)/voxlight-overlaysbench: bench/overlays_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

# multi-channel volumes: frame time against channels, against overlays of the same data (docs/channels.md)
$(BUILD)/voxlight-channelsbench: bench/channels_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

# the render modes' run time against error (docs/modes.md, docs/benchmark.md)
$(BUILD)/voxlight-modesbench: bench/modes_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

# the World's light: its cost over a cached shadowed frame (docs/lighting.md)
$(BUILD)/voxlight-envbench: bench/environment_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

# the PATH model: time to the first frame and error against samples (docs/lighting.md)
$(BUILD)/voxlight-pathbench: bench/path_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

$(BUILD)/voxlight-sceneshadowbench: bench/scene_shadow_study.c bench/bench_util.h $(BUILD)/libvoxlight.so
	$(CC) $(CFLAGS) $< -o $@ -L$(BUILD) -lvoxlight -lm -Wl,-rpath,'$$ORIGIN'

# test_brick_cache calls the cache's internals (csrc/io/brick_cache.h), so it
# links their objects and those its checks compare against, as well as the library.
BRICK_CACHE_TEST_OBJ := $(patsubst %,$(BUILD)/obj/%.o,brick_cache brick_cache_read brick_cache_write \
	brick_cache_format brick_source brick_levels bricks volume colour_volume channel_volume error paging lod brick_loader loader_util zlib_api \
	$(PLATFORM) crc32)
$(BUILD)/tests/test_brick_cache: tests/test_brick_cache.c tests/harness.h $(wildcard tests/*.h) $(BRICK_CACHE_TEST_OBJ) \
		$(BUILD)/libvoxlight.so | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< $(BRICK_CACHE_TEST_OBJ) -o $@ -L$(BUILD) -lvoxlight -lz -lm -lpthread -Wl,-rpath,'$$ORIGIN/..'

# test_environment checks the World map's reduction and the Radiance reader
# (internals) beside rendering through the library.
ENVIRONMENT_TEST_OBJ := $(patsubst %,$(BUILD)/obj/%.o,environment_map hdr_read error)
$(BUILD)/tests/test_environment: tests/test_environment.c tests/harness.h $(wildcard tests/*.h) $(ENVIRONMENT_TEST_OBJ) \
		$(BUILD)/libvoxlight.so $(PLATFORM:%=$(BUILD)/obj/%.o) | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< $(ENVIRONMENT_TEST_OBJ) $(PLATFORM:%=$(BUILD)/obj/%.o) -o $@ -L$(BUILD) -lvoxlight -lm \
		-ldl -lpthread -Wl,-rpath,'$$ORIGIN/..'

# test_gl_thread checks the GL thread's shared lock (internal), so it links
# the thread and context objects; the backends come with context.o.
GL_THREAD_TEST_OBJ := $(patsubst %,$(BUILD)/obj/%.o,gl_thread context backends_posix backend_osmesa backend_egl error $(PLATFORM))
$(BUILD)/tests/test_gl_thread: tests/test_gl_thread.c tests/harness.h $(GL_THREAD_TEST_OBJ) | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< $(GL_THREAD_TEST_OBJ) -o $@ -ldl -lpthread

# test_platform checks the platform room's seams (the same file is built for
# Windows below).
$(BUILD)/tests/test_platform: tests/test_platform.c tests/harness.h $(PLATFORM:%=$(BUILD)/obj/%.o) \
		$(BUILD)/tests/child_program | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< $(PLATFORM:%=$(BUILD)/obj/%.o) -o $@ -ldl -lpthread

# render_scene renders one fixed scene for the Linux/Windows comparison
# (tests/cli/test_windows_render.py; its Windows twin is built below).
$(BUILD)/tests/render_scene: tests/render_scene.c $(BUILD)/libvoxlight.so | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< -o $@ -L$(BUILD) -lvoxlight -Wl,-rpath,'$$ORIGIN/..'

$(BUILD)/tests/child_program: tests/child_program.c | $(BUILD)/tests
	$(CC) -std=c11 $(WARN) -O1 $< -o $@

# ---- Windows x64 (make windows WIN_CC="zig cc -target x86_64-windows-gnu"):
# the platform room's Windows files and the tests that need only them, run
# under Wine by ./build.sh test.
WIN_BUILD := $(BUILD)/windows-x64
# the import-library maker of the same toolchain (build.sh names zig's)
WIN_DLLTOOL ?= x86_64-w64-mingw32-dlltool
WIN_PLATFORM_C := $(addprefix csrc/platform/,dynlib.c dynlib_win32.c threads_win32.c files.c files_win32.c \
	clock_win32.c os_win32.c utf16_win32.c process_win32.c)
WIN_CFLAGS := -std=c11 $(WARN) -O2 -g0 -Icsrc/platform -Icsrc/core -Itests
# zlib for Windows: Debian's libz-mingw-w64 build, shipped beside
# voxlight.dll (which opens it from its own folder, os.h) and beside the
# test programs that use the library's zlib table.
WIN_ZLIB := /usr/x86_64-w64-mingw32/lib/zlib1.dll
WIN_ZLIB_DLLS := $(WIN_BUILD)/zlib1.dll $(WIN_BUILD)/tests/zlib1.dll
$(WIN_ZLIB_DLLS): $(WIN_ZLIB)
	@mkdir -p $(@D)
	cp $< $@
# An import library for the test programs that write gzip files with zlib
# (the library itself opens zlib1.dll at run time): made from the DLL's
# export table, as the package ships none.
$(WIN_BUILD)/libz.dll.a: $(WIN_ZLIB)
	@mkdir -p $(@D)
	@{ echo 'LIBRARY zlib1.dll'; echo 'EXPORTS'; \
	  objdump -p $< | sed -n '/\[Ordinal\/Name Pointer\] Table/,/^$$/p' | sed -nE 's/^\s*\[\s*[0-9]+\] (\w+)$$/    \1/p'; \
	} > $(WIN_BUILD)/zlib1.def
	$(WIN_DLLTOOL) -d $(WIN_BUILD)/zlib1.def -l $@ -m i386:x86-64

# The C tests of the public API that build for Windows as they are (the
# platform room standing in for POSIX calls); the rest reach into POSIX
# (fork, truncate, pwrite, symlinks), the Linux backends, or Python (test_zarr
# writes its stores with tests/zarr_write.py: tests/cli/test_windows_cli.py
# reads such stores with the Windows build).
WIN_API_TESTS := test_accuracy test_api test_budget test_classification test_cut test_gradients test_kernels \
	test_labels test_modes test_overlays test_paging test_reference_light test_render test_scene_shadows test_shadows \
	test_skipping test_slice_plane test_slices test_streaming test_stripes
windows: $(WIN_BUILD)/tests/test_platform.exe $(WIN_BUILD)/tests/child_program.exe $(WIN_BUILD)/tests/test_crc32.exe \
	$(WIN_BUILD)/tests/test_gz_reader.exe $(WIN_BUILD)/tests/test_dicom_codecs.exe $(WIN_BUILD)/voxlight.dll $(WIN_BUILD)/voxlight.exe $(WIN_BUILD)/render_scene.exe \
	$(WIN_ZLIB_DLLS) $(WIN_API_TESTS:%=$(WIN_BUILD)/tests/%.exe) $(WIN_BUILD)/tests/voxlight.dll \
	$(WIN_BUILD)/voxlight-read-zarr.exe $(WIN_BUILD)/voxlight-read-dicom.exe

# The OME-Zarr helper is our C alone, so Windows has it too (its blosc and
# zstd codecs are opened at run time, where a system has them); the
# OpenImageIO and dcmtk helpers need C++ libraries with no Windows build
# here, and the library refuses their formats on Windows by name.
WIN_ZARR_HELPER_C := $(wildcard csrc/*/helper_zarr.c) $(ZARR_C) $(wildcard csrc/*/zarr_detect.c) \
	$(foreach n,$(HELPER_CORE_NAMES),$(wildcard csrc/*/$(n).c)) csrc/platform/helper_self_win32.c $(WIN_PLATFORM_C)
$(WIN_BUILD)/voxlight-read-zarr.exe: $(WIN_ZARR_HELPER_C) $(wildcard csrc/*/*.h)
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_LIB_CFLAGS) $(WIN_ZARR_HELPER_C) -o $@ -lshell32

# The DICOM helper: the reader's C++ on our own parser (no dcmtk), compiled
# by zig's clang++ with its libc++ linked in statically, so the .exe needs
# only Windows' own DLLs (and zlib1.dll beside it, opened at run time for
# deflated files); its C objects are compiled as the Zarr helper's are.
WIN_CXX ?= $(subst ziglang cc ,ziglang c++ ,$(WIN_CC))
WIN_DICOM_HELPER_C := $(wildcard csrc/*/helper_dicom.c) $(DICOM_CODECS:%=csrc/io/%.c) \
	$(foreach n,$(HELPER_CORE_NAMES),$(wildcard csrc/*/$(n).c)) csrc/platform/helper_self_win32.c $(WIN_PLATFORM_C)
WIN_DICOM_CXX := $(DICOM_CXX) $(DICOM_OWN_CXX)
WIN_DICOM_OBJ := $(patsubst %,$(WIN_BUILD)/dicom_obj/%.o,$(notdir $(WIN_DICOM_HELPER_C) $(WIN_DICOM_CXX)))
$(WIN_BUILD)/dicom_obj/%.c.o: %.c $(wildcard csrc/*/*.h)
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_LIB_CFLAGS) -c $< -o $@
# zlib.h's types for zlib_api.h, from a folder holding zlib's two headers
# alone: with all of /usr/include on its path, libc++ would take glibc's
# mbstate_t over MinGW's. _GNU_SOURCE: M_PI, as g++ defines it on Linux.
WIN_ZLIB_INC := $(WIN_BUILD)/zlib_include
$(WIN_ZLIB_INC)/zlib.h: /usr/include/zlib.h /usr/include/zconf.h
	@mkdir -p $(@D)
	cp /usr/include/zlib.h /usr/include/zconf.h $(@D)/
$(WIN_BUILD)/dicom_obj/%.cpp.o: %.cpp $(wildcard csrc/*/*.h csrc/*/*.hpp) $(WIN_ZLIB_INC)/zlib.h
	@mkdir -p $(@D)
	$(WIN_CXX) -std=c++17 -D_GNU_SOURCE $(WARN) -O2 -g0 -Icsrc/include $(CSRC_INC) -idirafter $(WIN_ZLIB_INC) \
		-c $< -o $@
$(WIN_BUILD)/voxlight-read-dicom.exe: $(WIN_DICOM_OBJ)
	$(WIN_CXX) -static $^ -o $@ -lshell32

$(WIN_API_TESTS:%=$(WIN_BUILD)/tests/%.exe): $(WIN_BUILD)/tests/%.exe: tests/%.c $(wildcard tests/*.h) $(WIN_PLATFORM_C) \
		$(wildcard csrc/*/*.h) $(WIN_BUILD)/voxlight.dll $(WIN_BUILD)/libz.dll.a
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_LIB_CFLAGS) -Itests $< $(WIN_PLATFORM_C) -o $@ -L$(WIN_BUILD) -lvoxlight $(WIN_BUILD)/libz.dll.a -lshell32
# beside the test programs, where Windows looks first
$(WIN_BUILD)/tests/voxlight.dll: $(WIN_BUILD)/voxlight.dll
	cp $< $@

# The CLI, beside voxlight.dll as on Linux (the same files: see $(BUILD)/voxlight).
$(WIN_BUILD)/voxlight.exe: $(CLI_C) $(WIN_PLATFORM_C) $(wildcard csrc/*/*.h) $(WIN_BUILD)/voxlight.dll
	$(WIN_CC) $(WIN_LIB_CFLAGS) $(CLI_C) $(WIN_PLATFORM_C) -o $@ -L$(WIN_BUILD) -lvoxlight -lshell32

# beside voxlight.dll, where Windows looks for it first
$(WIN_BUILD)/render_scene.exe: tests/render_scene.c $(WIN_BUILD)/voxlight.dll
	$(WIN_CC) -std=c11 $(WARN) -O2 -g0 -Icsrc/include -Itests $< -o $@ -L$(WIN_BUILD) -lvoxlight

# voxlight.dll: the library's C for Windows (the *_win32.c files in place of
# the POSIX ones, WGL in place of OSMesa and EGL); it exports what the
# public headers mark VXL_API (a .def made from them: the headers carry no
# Windows-only markup), and links only Windows' own gdi32, user32 and shell32.
WIN_LIB_C := $(filter-out $(CLI_C) $(HELPER_C) %_posix.c %/backend_osmesa.c %/backend_egl.c,$(wildcard csrc/*/*.c))
WIN_LIB_CFLAGS := -std=c11 -D_GNU_SOURCE $(WARN) -O2 -g0 -Icsrc/include $(CSRC_INC) -I$(BUILD)/gen \
	-idirafter /usr/include -idirafter /usr/include/$(shell $(CC) -print-multiarch) $(OPENJPEG_INC)
$(WIN_BUILD)/voxlight.def: $(wildcard csrc/include/*.h)
	@mkdir -p $(@D)
	@{ echo 'LIBRARY voxlight.dll'; echo 'EXPORTS'; \
	  sed -nE 's/^VXL_API[^(]*[ *](vxl_[a-z0-9_]+)\(.*/    \1/p' csrc/include/*.h | sort -u; } > $@
$(WIN_BUILD)/voxlight.dll: $(WIN_LIB_C) $(wildcard csrc/*/*.h) $(BUILD)/gen/shaders_embedded.c $(WIN_BUILD)/voxlight.def
	$(WIN_CC) $(WIN_LIB_CFLAGS) -shared $(WIN_LIB_C) $(BUILD)/gen/shaders_embedded.c $(WIN_BUILD)/voxlight.def \
		-o $@ -Wl,--out-implib,$(WIN_BUILD)/libvoxlight.dll.a -lgdi32 -luser32 -lshell32
.PHONY: windows

$(WIN_BUILD)/tests/test_platform.exe: tests/test_platform.c tests/harness.h $(WIN_PLATFORM_C) $(wildcard csrc/platform/*.h)
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_CFLAGS) $< $(WIN_PLATFORM_C) -o $@ -lshell32

$(WIN_BUILD)/tests/child_program.exe: tests/child_program.c
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_CFLAGS) $< -o $@

$(WIN_BUILD)/tests/test_gz_reader.exe: tests/test_gz_reader.c tests/harness.h tests/utf8_temp.h $(WIN_PLATFORM_C) \
		csrc/io/gz_reader.c csrc/io/zlib_api.c csrc/core/error.c csrc/core/crc32.c $(wildcard csrc/*/*.h)
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_LIB_CFLAGS) -Itests $< $(filter %.c,$(filter-out $<,$^)) -o $@ -lshell32

$(WIN_BUILD)/tests/test_dicom_codecs.exe: tests/test_dicom_codecs.c tests/harness.h $(DICOM_CODECS:%=csrc/io/%.c) \
		csrc/core/error.c $(WIN_PLATFORM_C) $(wildcard csrc/*/*.h)
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_LIB_CFLAGS) -Itests $< $(DICOM_CODECS:%=csrc/io/%.c) csrc/core/error.c $(WIN_PLATFORM_C) -o $@ -lshell32

$(WIN_BUILD)/tests/test_crc32.exe: tests/test_crc32.c tests/harness.h csrc/core/crc32.c csrc/core/crc32_tables.h
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_CFLAGS) $< csrc/core/crc32.c -o $@

# test_gz_reader reads gzip and plain files through the library's internal
# reader (the same file is built for Windows above).
GZ_TEST_OBJ := $(patsubst %,$(BUILD)/obj/%.o,gz_reader zlib_api error crc32 $(PLATFORM))
$(BUILD)/tests/test_gz_reader: tests/test_gz_reader.c tests/harness.h tests/utf8_temp.h $(GZ_TEST_OBJ) | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< $(GZ_TEST_OBJ) -o $@ -ldl -lpthread

# test_dicom_codecs checks the DICOM decoders written in our C on frames
# made byte by byte or kept from dcmtk's encoder (the same file is built for
# Windows above).
DICOM_CODECS_TEST_OBJ := $(patsubst %,$(BUILD)/obj/%.o,$(DICOM_CODECS) error $(PLATFORM))
$(BUILD)/tests/test_dicom_codecs: tests/test_dicom_codecs.c tests/harness.h $(DICOM_CODECS_TEST_OBJ) | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< $(DICOM_CODECS_TEST_OBJ) -o $@ -ldl -lpthread

# test_dicom_j2k checks io/dicom_j2k.c through the system's OpenJPEG on
# images Debian's opj_compress writes at test time (Linux only: the encoder
# is a Debian program).
$(BUILD)/tests/test_dicom_j2k: tests/test_dicom_j2k.c tests/harness.h $(DICOM_CODECS_TEST_OBJ) | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< $(DICOM_CODECS_TEST_OBJ) -o $@ -ldl -lpthread -lm

# test_crc32 checks the library's internal CRC-32 against zlib's values.
$(BUILD)/tests/test_crc32: tests/test_crc32.c tests/harness.h $(BUILD)/obj/crc32.o | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< $(BUILD)/obj/crc32.o -o $@

# The tests use the public API, and the platform room for what differs
# between OSes (test_util.h), so the same files build for Windows below.
$(BUILD)/tests/%: tests/%.c tests/harness.h $(wildcard tests/*.h tests/fuzz/*.h) $(BUILD)/libvoxlight.so \
		$(PLATFORM:%=$(BUILD)/obj/%.o) | $(BUILD)/tests
	$(CC) $(CFLAGS) -Itests $< $(PLATFORM:%=$(BUILD)/obj/%.o) -o $@ -L$(BUILD) -lvoxlight -lz -lm -ldl -lpthread \
		-Wl,-rpath,'$$ORIGIN/..'

$(BUILD)/obj $(BUILD)/gen $(BUILD)/tests:
	mkdir -p $@

# ---- fuzzing: `make fuzz` builds one libFuzzer binary per loader
# in build/fuzz/ with Debian's clang under ASan+UBSan, the loaders compiled
# in directly, plus the seed writer; ./build.sh fuzz / test run them.
FUZZ_BUILD := build/fuzz
FUZZ_SAN := -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
FUZZ_CFLAGS := -std=c11 -D_GNU_SOURCE $(WARN) $(FUZZ_SAN) -fsanitize=fuzzer-no-link -Icsrc/include $(CSRC_INC) \
	-I$(FUZZ_BUILD)/gen $(OPENJPEG_INC)
FUZZ_CXXFLAGS := -std=c++17 $(WARN) $(FUZZ_SAN) -fsanitize=fuzzer-no-link -Icsrc/include $(CSRC_INC) \
	$(shell pkg-config --cflags OpenImageIO)
# the core's loaders and dispatch (the helper-run readers are called
# in-process by their targets: libFuzzer sees coverage in its own process only)
FUZZ_LIB_C := volume.c colour_volume.c channel_volume.c channel_meta.c ome_xml.c volume_load.c error.c nifti.c nrrd.c metaimage.c loader_util.c dicom_detect.c \
	reader_spawn.c remote_readers.c label_table.c zarr_detect.c $(notdir $(ZARR_C)) zarr_source.c brick_source.c
# the brick cache of .nii.gz files and the TIFF directory walk: opened by the loaders, read by
# fuzz_brick_cache and fuzz_tiff_layout; the Radiance reader of World maps, read by fuzz_hdr
FUZZ_LIB_C := $(sort $(FUZZ_LIB_C) brick_cache.c brick_cache_read.c brick_cache_write.c brick_cache_format.c \
	brick_levels.c raw_source.c stream_load.c tiff_layout.c zlib_api.c gz_reader.c crc32.c hdr_read.c \
	$(DICOM_CODECS:%=%.c) $(PLATFORM:%=%.c))
FUZZ_LIB_CXX := image_stack.cpp vdb.cpp $(notdir $(DICOM_CXX))
# the data set seam's backend: dcmtk's for every target, our own parser's
# for fuzz_dicom_own (the same reader on the parser Windows uses)
FUZZ_DCMTK_OBJ := $(FUZZ_BUILD)/obj/dicom_dataset_dcmtk.o
FUZZ_OWN_OBJ := $(FUZZ_BUILD)/obj/dicom_dataset_own.o
FUZZ_OBJ := $(FUZZ_LIB_C:%.c=$(FUZZ_BUILD)/obj/%.o) $(FUZZ_LIB_CXX:%.cpp=$(FUZZ_BUILD)/obj/%.o)
FUZZ_TARGETS := $(patsubst tests/fuzz/fuzz_%.c,$(FUZZ_BUILD)/fuzz_%,$(wildcard tests/fuzz/fuzz_*.c))

fuzz: $(FUZZ_TARGETS) $(FUZZ_BUILD)/make_seeds

$(FUZZ_BUILD)/obj/%.o: %.c $(wildcard csrc/*/*.h) | $(FUZZ_BUILD)/obj
	clang $(FUZZ_CFLAGS) -c $< -o $@

$(FUZZ_BUILD)/obj/remote_readers.o: $(FUZZ_BUILD)/gen/reader_packages.h

$(FUZZ_BUILD)/obj/%.o: %.cpp $(wildcard csrc/*/*.h csrc/*/*.hpp) | $(FUZZ_BUILD)/obj
	clang++ $(FUZZ_CXXFLAGS) -c $< -o $@

$(FUZZ_BUILD)/obj/fuzz_%.o: tests/fuzz/fuzz_%.c tests/fuzz/fuzz_common.h csrc/include/voxlight.h csrc/io/helper_main.h | $(FUZZ_BUILD)/obj
	clang $(FUZZ_CFLAGS) -c $< -o $@

$(FUZZ_BUILD)/fuzz_dicom_own: $(FUZZ_BUILD)/obj/fuzz_dicom_own.o $(FUZZ_OBJ) $(FUZZ_OWN_OBJ)
	clang++ $(FUZZ_SAN) -fsanitize=fuzzer $^ -o $@ $(LIBS) $(OIIO_LIBS)

$(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/obj/fuzz_%.o $(FUZZ_OBJ) $(FUZZ_DCMTK_OBJ)
	clang++ $(FUZZ_SAN) -fsanitize=fuzzer $^ -o $@ $(LIBS) $(OIIO_LIBS) $(DCMTK_LIBS)

$(FUZZ_BUILD)/make_seeds: tests/fuzz/make_seeds.c tests/fuzz/writers.h tests/fuzz/dicom_writer.h tests/nifti_writer.h \
		tests/hdr_writer.h | $(FUZZ_BUILD)/obj
	$(CC) -std=c11 -D_GNU_SOURCE $(WARN) -O1 -Itests $< -o $@ -lz -lm

$(FUZZ_BUILD)/obj:
	mkdir -p $@

clean:
	rm -rf build build-asan

.PHONY: all clean fuzz
