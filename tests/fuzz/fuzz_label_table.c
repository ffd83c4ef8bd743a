/* fuzz_label_table.c - libFuzzer target: arbitrary bytes as a label lookup
 * table (or an MRIcron .lut/.txt pair; the first byte picks which, see
 * label_table_samples.h) through vxl_label_table_load, under ASan+UBSan.
 * A breach of the contract aborts, which libFuzzer reports. */
#include <stdlib.h>

#include "label_table_input.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char lt_dir[64];

static void lt_cleanup(void)
{
    char p[128];
    uint8_t none = 0;
    lt_write_input(lt_dir, &none, 1, p, sizeof p); /* removes the last input's files */
    unlink(p);
    rmdir(lt_dir);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!lt_dir[0]) {
        snprintf(lt_dir, sizeof lt_dir, "/dev/shm/vxl_fuzz_lt_XXXXXX"); /* tmpfs where there is one */
        if (!mkdtemp(lt_dir)) {
            snprintf(lt_dir, sizeof lt_dir, "/tmp/vxl_fuzz_lt_XXXXXX");
            if (!mkdtemp(lt_dir)) abort();
        }
        atexit(lt_cleanup);
    }
    char path[128];
    if (lt_write_input(lt_dir, data, size, path, sizeof path)) abort();
    int rc;
    if (lt_check_load(path, &rc)) abort();
    return 0;
}
