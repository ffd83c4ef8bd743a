/* test_zarr.c - the OME-Zarr reader (csrc/io/zarr*.c, run in the helper
 * voxlight-read-zarr) through the public vxl_volume_load.
 *
 * The stores are written by tests/zarr_write.py (numpy, zlib/gzip, and
 * libzstd/libblosc through ctypes), independently of the C reader, with a
 * manifest of cases: the volume each load must return (its values, x
 * fastest, as float64; its dims, spacing, translation and frame count) or
 * the error code and text it must fail with. Values are compared texel by
 * texel (loader_test_util.h), so a transposed axis, a wrong chunk key, a
 * byte-order slip or a missing fill shows as wrong values. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "loader_test_util.h"
#include "volume.h"
#include "voxlight.h"

static char g_dir[64];

static int code_of(const char *name)
{
    static const struct { const char *name; int code; } map[] = {
        {"INVALID_ARGUMENT", VXL_ERR_INVALID_ARGUMENT}, {"IO", VXL_ERR_IO}, {"FORMAT", VXL_ERR_FORMAT},
        {"LIMIT", VXL_ERR_LIMIT}, {"NO_MEMORY", VXL_ERR_NO_MEMORY}};
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (!strcmp(name, map[i].name)) return map[i].code;
    return -1;
}

/* Splits a tab-separated line in place; returns the field count. */
static int fields(char *line, char **f, int max)
{
    int n = 0;
    char *save = NULL;
    for (char *t = strtok_r(line, "\t\n", &save); t && n < max; t = strtok_r(NULL, "\t\n", &save)) f[n++] = t;
    return n;
}

static double *read_expected(const char *path, uint64_t count)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    double *v = malloc(count * sizeof *v);
    size_t got = v ? fread(v, sizeof *v, count, f) : 0;
    fclose(f);
    if (got != count) {
        free(v);
        return NULL;
    }
    return v; /* little-endian float64, as this host */
}

/* One OK line: the load succeeds and every value, the geometry and the
 * frame count are those the writer recorded. */
static int check_ok(vxl_test_ctx *T_, char **f, const vxl_load_options *opt)
{
    vxl_volume *v = NULL;
    int rc = vxl_volume_load(f[1], opt, &v);
    CHECKF(rc == VXL_OK, "%s: %s", f[1], vxl_last_error());
    if (rc) return 0;
    vxl_volume_info info = {.struct_size = sizeof info};
    vxl_volume_get_info(v, &info);
    const uint32_t dims[3] = {(uint32_t)atoi(f[5]), (uint32_t)atoi(f[6]), (uint32_t)atoi(f[7])};
    int ok = 1;
    for (int a = 0; a < 3; a++) {
        ok &= info.dims[a] == dims[a];
        ok &= fabs(info.affine[a * 4 + a] - atof(f[8 + a])) < 1e-12; /* scale on the diagonal, mm */
        ok &= fabs(info.affine[12 + a] - atof(f[11 + a])) < 1e-12;   /* translation, mm */
    }
    ok &= info.frame_count == (uint32_t)atoi(f[14]) && info.frame == (uint32_t)atoi(f[2]);
    CHECKF(ok, "%s: dims %ux%ux%u frames %u, geometry or frame count differ from the manifest", f[1], info.dims[0],
           info.dims[1], info.dims[2], info.frame_count);
    const uint64_t n = (uint64_t)dims[0] * dims[1] * dims[2];
    double *exp = ok ? read_expected(f[4], n) : NULL;
    CHECKF(!ok || exp, "%s: cannot read %s", f[1], f[4]);
    uint64_t bad = 0, first = 0;
    for (uint64_t i = 0; exp && i < n; i++) {
        const double want = exp[i], got = voxel(v, i);
        /* 8/16-bit integers are stored exactly; wider types as float32 in [0, 1] */
        const double tol = v->texture_bits == 32 ? 1e-6 * (v->tex_hi - v->tex_lo) + 1e-6 * fabs(want) : 1e-6;
        if (!(fabs(got - want) <= tol) && !bad++) first = i;
    }
    CHECKF(!bad, "%s: %llu of %llu values differ, first at %llu: %g, expected %g", f[1], (unsigned long long)bad,
           (unsigned long long)n, (unsigned long long)first, exp ? voxel(v, first) : 0.0, exp ? exp[first] : 0.0);
    free(exp);
    vxl_volume_destroy(v);
    return ok && !bad;
}

static int check_err(vxl_test_ctx *T_, char **f, const vxl_load_options *opt)
{
    vxl_volume *v = NULL;
    int rc = vxl_volume_load(f[1], opt, &v);
    const int want = code_of(f[4]);
    CHECKF(rc == want && !v, "%s: rc %d (want %d) %s", f[1], rc, want, vxl_last_error());
    CHECKF(strstr(vxl_last_error(), f[5]) != NULL, "%s: message '%s' lacks '%s'", f[1], vxl_last_error(), f[5]);
    vxl_volume_destroy(v);
    return rc == want && strstr(vxl_last_error(), f[5]);
}

TEST(generated_stores_read_exactly_and_bad_ones_fail_clearly)
{
    char cmd[256], manifest[128];
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/zarr_write.py %s", g_dir);
    REQUIRE(system(cmd) == 0);
    snprintf(manifest, sizeof manifest, "%s/manifest.tsv", g_dir);
    FILE *m = fopen(manifest, "r");
    REQUIRE(m);
    char line[8192];
    int oks = 0, errs = 0, passed = 0;
    while (fgets(line, sizeof line, m)) {
        char *f[16];
        int n = fields(line, f, 16);
        /* the whole read (the streamed source: test_zarr_source.c) */
        vxl_load_options opt = {.struct_size = sizeof opt, .streaming = VXL_STREAMING_OFF};
        if (n >= 4) {
            opt.frame = (uint32_t)atoi(f[2]);
            opt.memory_budget_bytes = strtoull(f[3], NULL, 10);
        }
        if (n == 15 && !strcmp(f[0], "OK")) {
            oks++;
            passed += check_ok(T_, f, &opt);
        } else if (n == 6 && !strcmp(f[0], "ERR")) {
            errs++;
            passed += check_err(T_, f, &opt);
        } else {
            CHECKF(0, "bad manifest line (%d fields)", n);
        }
    }
    fclose(m);
    fprintf(stderr, "  %d volumes and %d errors checked, %d as expected\n", oks, errs, passed);
    /* every codec x version x dtype case, the t/c/level choices, fill, the auto level */
    CHECK(oks >= 34);
    CHECK(errs >= 20);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_zarr_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(generated_stores_read_exactly_and_bad_ones_fail_clearly);
    remove_tree(g_dir);
    return TEST_SUMMARY();
}
