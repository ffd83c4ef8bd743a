/* fuzz_ome_xml.c - libFuzzer target: arbitrary bytes as an OME-TIFF's
 * ImageDescription through csrc/io/ome_xml.c (which the OME-TIFF reader and
 * the TIFF directory walk use), under ASan+UBSan (see Makefile 'fuzz',
 * tests/fuzz/run.sh). Checks its promises: a usable answer has a valid
 * DimensionOrder and positive sizes, terminated names of text, colours in
 * [0, 1], and every plane's page inside the product of the sizes. */
#include "fuzz_common.h"

#include "ome_xml.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1); /* the reader's description is a terminated string */
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    vxl_ome_pixels p;
    if (vxl_ome_xml_parse(text, strlen(text), &p)) {
        if (strncmp(p.order, "XY", 2) || !strchr(p.order, 'Z') || !strchr(p.order, 'C') || !strchr(p.order, 'T') ||
            !memchr(p.notes, 0, sizeof p.notes))
            abort();
        for (int k = 0; k < 3; k++)
            if (!p.size[k] || p.size[k] > (1ull << 32)) abort();
        for (uint32_t c = 0; c < VXL_MAX_CHANNELS; c++) {
            const vxl_channel_meta *m = &p.meta[c];
            if (!memchr(m->name, 0, sizeof m->name) || m->has_color > 1) abort();
            for (const char *s = m->name; *s; s++)
                if ((unsigned char)*s < 0x20 || *s == 0x7f) abort();
            for (int k = 0; k < 3; k++)
                if (!(m->color_srgb[k] >= 0.0f && m->color_srgb[k] <= 1.0f)) abort();
        }
        /* the last plane is the last page, when the sizes' product is small */
        if (p.size[0] < 4096 && p.size[1] < 4096 && p.size[2] < 4096 &&
            vxl_ome_page(&p, p.size[0] - 1, p.size[1] - 1, p.size[2] - 1) != p.size[0] * p.size[1] * p.size[2] - 1)
            abort();
    }
    free(text);
    return 0;
}
