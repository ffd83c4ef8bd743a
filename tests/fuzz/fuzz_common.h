/* fuzz_common.h - the body every libFuzzer target shares: write the input
 * to a file with the format's extension and load it through the public
 * vxl_volume_load (so dispatch is exercised too) with a small memory budget,
 * then check the API contract: success gives a volume, failure gives NULL
 * and a non-empty message. Anything else aborts, which libFuzzer reports. */
#ifndef VXL_FUZZ_COMMON_H
#define VXL_FUZZ_COMMON_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "helper_main.h"
#include "voxlight.h"

static char vxl_fuzz_dir[64];
static char vxl_fuzz_path[128];

static void vxl_fuzz_cleanup(void)
{
    if (vxl_fuzz_path[0]) unlink(vxl_fuzz_path);
    if (vxl_fuzz_dir[0]) rmdir(vxl_fuzz_dir);
}

/* The limits every target loads under. */
static const vxl_load_options vxl_fuzz_options = {
    .struct_size = sizeof(vxl_load_options), .max_dim = 4096, .memory_budget_bytes = 16u << 20};

/* Writes the input to the target's file (input.EXT) and returns its path. */
static inline const char *vxl_fuzz_write(const uint8_t *data, size_t size, const char *ext)
{
    if (!vxl_fuzz_dir[0] && !vxl_fuzz_path[0]) {
        /* VOXLIGHT_FUZZ_DIR: a folder the caller made and names the same way
         * on every run (tests/fuzz/run.sh ci passes "."). The loaders compare
         * the path's characters, and libFuzzer learns from what they compare,
         * so a random folder name would make two runs of one seed differ. */
        const char *fixed = getenv("VOXLIGHT_FUZZ_DIR");
        if (fixed && *fixed) {
            snprintf(vxl_fuzz_path, sizeof vxl_fuzz_path, "%s/input.%s", fixed, ext);
            atexit(vxl_fuzz_cleanup);
        }
    }
    if (!vxl_fuzz_dir[0] && !vxl_fuzz_path[0]) {
        /* a file per input: tmpfs (/dev/shm) where there is one, since a
         * disk-backed /tmp can cost milliseconds per write */
        snprintf(vxl_fuzz_dir, sizeof vxl_fuzz_dir, "/dev/shm/vxl_fuzz_XXXXXX");
        if (!mkdtemp(vxl_fuzz_dir)) {
            snprintf(vxl_fuzz_dir, sizeof vxl_fuzz_dir, "/tmp/vxl_fuzz_XXXXXX");
            if (!mkdtemp(vxl_fuzz_dir)) abort();
        }
        snprintf(vxl_fuzz_path, sizeof vxl_fuzz_path, "%s/input.%s", vxl_fuzz_dir, ext);
        atexit(vxl_fuzz_cleanup);
    }
    FILE *f = fopen(vxl_fuzz_path, "wb");
    if (!f) abort();
    if (size && fwrite(data, 1, size, f) != size) abort();
    fclose(f);
    return vxl_fuzz_path;
}

/* Checks the API contract of a load result; aborts (a libFuzzer finding) on
 * a breach, then frees the volume. */
static inline void vxl_fuzz_check(int rc, vxl_volume *v)
{
    if (rc == VXL_OK && !v) abort();
    if (rc != VXL_OK && (v || !vxl_last_error()[0])) abort();
    if (v) {
        vxl_volume_info info = {.struct_size = sizeof info};
        if (vxl_volume_get_info(v, &info) != VXL_OK) abort();
        if (info.dims[0] * (uint64_t)info.dims[1] * info.dims[2] == 0) abort();
    }
    vxl_volume_destroy(v);
}

static inline int vxl_fuzz_load(const uint8_t *data, size_t size, const char *ext)
{
    const char *path = vxl_fuzz_write(data, size, ext);
    vxl_volume *v = NULL;
    vxl_fuzz_check(vxl_volume_load(path, &vxl_fuzz_options, &v), v);
    return 0;
}

/* The same through a reader that the library runs in a helper process
 * (csrc/io/helper_main.h), called in-process here: libFuzzer sees coverage
 * only in its own process. */
typedef int (*vxl_fuzz_reader)(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e);

static inline int vxl_fuzz_read(const uint8_t *data, size_t size, const char *ext, vxl_fuzz_reader read)
{
    const char *path = vxl_fuzz_write(data, size, ext);
    vxl_volume *v = NULL;
    vxl_fuzz_check(read(path, &vxl_fuzz_options, &v, NULL), v);
    return 0;
}

#endif
