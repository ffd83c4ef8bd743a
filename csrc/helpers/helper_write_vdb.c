/* helper_write_vdb.c - voxlight-write-vdb OUT.vdb: reads the classified
 * grids from standard input (the stream of vdb_write.h) and writes them as
 * an OpenVDB file. A process of its own, like the reader helpers, because
 * libopenvdb is C++ and the library links only the C runtime; the add-on
 * starts it when it converts a volume to a Blender Volume. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vdb_write.h"

/* Cells we accept: 2^31 keeps every int index of OpenVDB's Coord and the
 * stream's 16 bytes per cell under 32 GiB. */
#define MAX_CELLS ((uint64_t)1 << 31)

static int fail(const char *msg)
{
    fprintf(stderr, "voxlight-write-vdb: %s\n", msg);
    return 1;
}

static int read_all(void *p, size_t size, size_t n) { return fread(p, size, n, stdin) == n; }

int main(int argc, char **argv)
{
    if (argc != 2) return fail("usage: voxlight-write-vdb OUT.vdb < stream (see csrc/io/vdb_write.h)");
    char magic[8];
    uint32_t dims[3];
    double m[16];
    if (!read_all(magic, 1, sizeof magic) || memcmp(magic, VXL_VDB_STREAM_MAGIC, sizeof magic) != 0)
        return fail("the input does not start with " VXL_VDB_STREAM_MAGIC);
    if (!read_all(dims, sizeof dims[0], 3) || !read_all(m, sizeof m[0], 16)) return fail("the header is cut short");
    uint64_t n = (uint64_t)dims[0] * dims[1] * dims[2];
    if (n == 0 || n > MAX_CELLS) return fail("the grid's cell count is 0 or over 2^31");
    for (int k = 0; k < 16; k++)
        if (!isfinite(m[k])) return fail("the index-to-world matrix is not finite");
    float *density = malloc(n * sizeof *density), *rgb = malloc(3 * n * sizeof *rgb);
    if (!density || !rgb) {
        free(density);
        free(rgb);
        return fail("out of memory for the grids");
    }
    int rc = 0;
    char extra;
    if (!read_all(density, sizeof *density, n) || !read_all(rgb, sizeof *rgb, 3 * n)) rc = fail("the grids are cut short");
    else if (fread(&extra, 1, 1, stdin) != 0) rc = fail("bytes follow the grids");
    else {
        char err[512] = "";
        if (vxl_vdb_write(argv[1], dims, m, density, rgb, err, sizeof err)) rc = fail(err);
    }
    free(density);
    free(rgb);
    return rc;
}
