/* fuzz_tiff_layout.c - libFuzzer target: arbitrary bytes as a .tif file
 * through the in-process TIFF directory walk (csrc/io/tiff_layout.c, issue
 * 21) and, when it says the pages can be read by offset, through the raw
 * source's open and a read of every level (csrc/io/raw_source.c), under
 * ASan+UBSan (see Makefile 'fuzz', tests/fuzz/run.sh). Checks the walk's
 * promises: an error has a message; a streamable answer has sizes within
 * the limits and every page within the file. */
#include "fuzz_common.h"

#include "brick_source.h"
#include "stream_load.h"
#include "tiff_layout.h"
#include "volume.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = vxl_fuzz_write(data, size, "tif");
    vxl_load_options opt = vxl_fuzz_options;
    opt.streaming = VXL_STREAMING_ON;
    vxl_tiff_layout t;
    vxl_err e = {0};
    int rc = vxl_tiff_layout_probe(path, &opt, &t, &e);
    if (rc != VXL_OK && (!e.msg[0] || t.page_offsets)) abort();
    if (rc == VXL_OK && t.page_offsets) {
        const uint64_t es = vxl_dtype_size(t.dtype), page = (uint64_t)t.dims[0] * t.dims[1] * es;
        if (!es || t.dims[2] < 2) abort();
        for (int a = 0; a < 3; a++)
            if (!t.dims[a] || t.dims[a] > opt.max_dim) abort();
        for (uint32_t z = 0; z < t.dims[2]; z++)
            if (t.page_offsets[z] > t.file_size || page > t.file_size - t.page_offsets[z]) abort();
        vxl_raw_layout l;
        vxl_volume *v = NULL;
        rc = vxl_tiff_raw_layout(path, &t, &opt, &l, &e);
        if (rc == VXL_OK) rc = vxl_stream_load(&l, &opt, &v, &e);
        if (rc == VXL_OK && v && v->source) { /* every level read whole: the addressing of every path */
            vxl_brick_source *src = v->source;
            for (uint32_t k = 0; k < src->n_levels; k++) {
                const uint32_t *d = src->level_dims[k], zero[3] = {0, 0, 0};
                void *buf = malloc((size_t)d[0] * d[1] * d[2] * (src->texture_bits / 8));
                if (!buf) abort();
                vxl_err re = {0};
                if (src->ops->read(src, k, zero, d, buf, &re) != VXL_OK) abort();
                free(buf);
            }
        }
        vxl_fuzz_check(rc, v);
    }
    vxl_tiff_layout_free(&t);
    return 0;
}
