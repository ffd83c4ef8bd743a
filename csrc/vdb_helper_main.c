/* vdb_helper_main.c - voxlight-vdb-read FILE MAX_DIM BUDGET_BYTES: the
 * helper process that reads one .vdb in-process (vdb.cpp) and streams the
 * grid to libvoxlight over stdout (vdb_stream.h). libvoxlight starts it for
 * every .vdb load (vdb_spawn.c); if OpenVDB aborts in here, only this
 * process dies. Not meant to be run by hand. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "vdb_stream.h"

static int write_all(int fd, const void *buf, size_t n)
{
    const char *p = buf;
    while (n) {
        ssize_t w = write(fd, p, n > (1u << 30) ? (1u << 30) : n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return -1;
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

static int parse_u64(const char *s, unsigned long long *out)
{
    char *end;
    errno = 0;
    *out = strtoull(s, &end, 10);
    return s[0] >= '0' && s[0] <= '9' && !*end && errno == 0;
}

int main(int argc, char **argv)
{
    unsigned long long max_dim, budget;
    if (argc != 4 || !parse_u64(argv[2], &max_dim) || max_dim > UINT32_MAX || !parse_u64(argv[3], &budget)) {
        fputs("usage: " VXL_VDB_HELPER_NAME " FILE MAX_DIM BUDGET_BYTES (started by libvoxlight)\n", stderr);
        return 2;
    }
    /* The stream keeps stdout's pipe to itself: whatever OpenVDB or
     * OpenImageIO print goes to stderr instead of into the voxels. */
    int out = fcntl(1, F_DUPFD_CLOEXEC, 3);
    if (out < 0 || dup2(2, 1) < 0) {
        perror(VXL_VDB_HELPER_NAME);
        return 3;
    }
    vxl_load_options opt = {.struct_size = sizeof opt, .max_dim = (uint32_t)max_dim, .memory_budget_bytes = budget};
    vxl_vdb_grid g;
    vxl_err e = {0};
    vxl_vdb_header h;
    memset(&h, 0, sizeof h);
    memcpy(h.magic, VXL_VDB_MAGIC, sizeof VXL_VDB_MAGIC);
    h.status = (uint32_t)vxl_vdb_read_dense(argv[1], &opt, &g, &e);
    h.dtype = VXL_DTYPE_F32;
    if (h.status != VXL_OK) {
        h.msg_len = (uint32_t)strnlen(e.msg, sizeof e.msg);
        return write_all(out, &h, sizeof h) || write_all(out, e.msg, h.msg_len) ? 3 : 1;
    }
    memcpy(h.dims, g.dims, sizeof h.dims);
    memcpy(h.spacing, g.spacing, sizeof h.spacing);
    memcpy(h.affine, g.affine, sizeof h.affine);
    h.nbytes = (uint64_t)g.dims[0] * g.dims[1] * g.dims[2] * sizeof(float);
    int rc = write_all(out, &h, sizeof h) || write_all(out, g.voxels, h.nbytes) ? 3 : 0;
    free(g.voxels);
    return rc;
}
