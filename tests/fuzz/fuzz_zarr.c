/* fuzz_zarr.c - libFuzzer target for the OME-Zarr reader (csrc/io/zarr*.c,
 * json.c), called in-process (the library runs it in voxlight-read-zarr).
 * The first byte picks what the rest is:
 *   0..3  group metadata v2 (.zattrs) / v3 (zarr.json), array metadata v2
 *         (.zarray) / v3 (zarr.json), parsed from memory;
 *   4     one stored chunk: bytes 1..6 give the codec, dtype, byte order and
 *         chunk shape (1..8 per axis), the rest is the chunk, decoded;
 *   5     a whole Zarr v2 store: .zattrs NUL .zarray NUL chunk 0.0.0, written
 *         to a folder and read by vxl_zarr_read under the fuzz limits, then
 *         opened as a brick source (zarr_source.c: its level choice, value
 *         range and chunk-by-chunk index) and every small level read.
 * Seeds: tests/fuzz/zarr_seeds.py. */
#include <sys/stat.h>

#include "fuzz_common.h"
#include "zarr.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void write_file(const char *path, const uint8_t *p, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) abort();
    if (n && fwrite(p, 1, n, f) != n) abort();
    fclose(f);
}

/* The store as a brick source: open (index pass), then every level whose
 * voxels are few enough to read whole here. */
static void stream_store(const char *root)
{
    vxl_brick_source *s = NULL;
    vxl_zarr_source_info info;
    vxl_err e = {0};
    int rc = vxl_zarr_open_source(root, &vxl_fuzz_options, &s, &info, &e);
    if ((rc == VXL_OK) != (s != NULL) || (rc && !e.msg[0])) abort();
    for (uint32_t k = 0; s && k < s->n_levels; k++) {
        const uint32_t *d = s->level_dims[k], lo[3] = {0, 0, 0};
        const uint64_t n = (uint64_t)d[0] * d[1] * d[2];
        if (n > (1u << 20)) continue;
        void *buf = malloc((size_t)n * (s->texture_bits / 8));
        if (!buf) abort();
        if (s->ops->read(s, k, lo, d, buf, &e) && !e.msg[0]) abort();
        free(buf);
    }
    vxl_brick_source_free(s);
}

static void whole_store(const uint8_t *data, size_t size)
{
    /* the store folder sits in vxl_fuzz_write's temporary folder */
    const char *file = vxl_fuzz_write(data, 0, "zarr-input");
    char root[160], p[200];
    snprintf(root, sizeof root, "%.*s/store", (int)(strrchr(file, '/') - file), file);
    mkdir(root, 0755);
    snprintf(p, sizeof p, "%s/0", root);
    mkdir(p, 0755);
    const uint8_t *a = data, *end = data + size;
    const uint8_t *b = memchr(a, 0, size);
    const uint8_t *c = b ? memchr(b + 1, 0, (size_t)(end - b - 1)) : NULL;
    snprintf(p, sizeof p, "%s/.zattrs", root);
    write_file(p, a, (size_t)((b ? b : end) - a));
    snprintf(p, sizeof p, "%s/0/.zarray", root);
    write_file(p, b ? b + 1 : a, b ? (size_t)((c ? c : end) - b - 1) : 0);
    snprintf(p, sizeof p, "%s/0/0.0.0", root);
    write_file(p, c ? c + 1 : a, c ? (size_t)(end - c - 1) : 0);
    vxl_volume *v = NULL;
    vxl_err e = {0};
    int rc = vxl_zarr_read(root, &vxl_fuzz_options, &v, &e);
    if ((rc == VXL_OK) != (v != NULL) || (rc && !e.msg[0])) abort();
    vxl_volume_destroy(v);
    stream_store(root);
    snprintf(p, sizeof p, "%s/0/0.0.0", root);
    unlink(p);
    snprintf(p, sizeof p, "%s/0/.zarray", root);
    unlink(p);
    snprintf(p, sizeof p, "%s/0", root);
    rmdir(p);
    snprintf(p, sizeof p, "%s/.zattrs", root);
    unlink(p);
    rmdir(root);
}

static void one_chunk(const uint8_t *data, size_t size)
{
    static const uint32_t dtypes[8] = {VXL_DTYPE_U8, VXL_DTYPE_I8, VXL_DTYPE_U16, VXL_DTYPE_I16,
                                       VXL_DTYPE_U32, VXL_DTYPE_I32, VXL_DTYPE_F32, VXL_DTYPE_F64};
    if (size < 6) return;
    vxl_zarr_array a;
    memset(&a, 0, sizeof a);
    a.codec = data[0] % 4;
    a.dtype = dtypes[data[1] % 8];
    a.big_endian = data[2] & 1;
    a.ndim = 3;
    for (int i = 0; i < 3; i++) a.shape[i] = a.chunks[i] = (uint64_t)(data[3 + i] % 8) + 1;
    const uint64_t nbytes = vxl_zarr_chunk_bytes(&a);
    void *out = malloc((size_t)nbytes);
    if (!out) abort();
    vxl_err e = {0};
    static vxl_zarr_codecs *codecs; /* one table for the run: libzstd/libblosc opened once */
    if (!codecs && !(codecs = vxl_zarr_codecs_new())) abort();
    if (vxl_zarr_decode(&a, codecs, data + 6, size - 6, out, nbytes, "chunk", &e) && !e.msg[0]) abort();
    free(out);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    const int mode = data[0] % 6;
    data++;
    size--;
    vxl_err e = {0};
    if (mode < 2) {
        vxl_zarr_store *s = calloc(1, sizeof *s);
        if (!s) abort();
        if (vxl_zarr_parse_group((const char *)data, size, mode == 1, "group", s, &e) && !e.msg[0]) abort();
        free(s);
    } else if (mode < 4) {
        vxl_zarr_array a;
        memset(&a, 0, sizeof a);
        if (vxl_zarr_parse_array((const char *)data, size, mode == 3, "array", &a, &e) && !e.msg[0]) abort();
    } else if (mode == 4) {
        one_chunk(data, size);
    } else {
        whole_store(data, size);
    }
    return 0;
}
