// dicom_palette.cpp - PALETTE COLOR images (PS3.3 C.7.6.3.1.5-6): each
// stored value indexes three lookup tables, red, green and blue. The
// pixels room reads the indices as it reads grey ones, and this room
// turns them into their colours, RGB, which load as a colour volume as the
// other colour images do.
//
// A table's descriptor is (entries, first mapped value, bits per entry):
// 0 entries means 65536; indices below the first mapped value take the
// first entry, indices past the last take the last. 16-bit entries are one
// word each; 8-bit entries come packed two to a word (as pydicom and
// dcmtk's dcmimage read them) or, in files that spend a word on each, one
// to a word: the data's length tells which. Segmented tables are refused
// by name.
#include "dicom_series.hpp"

#include <algorithm>
#include <cmath>

extern "C" {
#include "error.h"
#include "voxlight.h"
}

namespace vxl_dicom {

bool is_palette(const Image &im) { return im.samples == 1 && im.photometric == "PALETTE COLOR"; }

namespace {

// One value of a descriptor, whose VR is US or SS (the first mapped value
// follows the pixels' signedness).
bool descriptor_value(const Dataset &ds, Tag t, unsigned long pos, long &out)
{
    unsigned u = 0;
    if (ds.us(ds.root(), t, pos, u)) {
        out = long(u);
        return true;
    }
    int v = 0;
    if (ds.ss(ds.root(), t, pos, v)) {
        out = v;
        return true;
    }
    return false;
}

int read_table(const Dataset &ds, const Image &im, Tag desc_tag, Tag data_tag, Tag segmented_tag, const char *name,
               std::vector<uint16_t> &out, long &first, vxl_err *e)
{
    const char *p = im.path.c_str();
    if (ds.has(ds.root(), segmented_tag))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': a segmented PALETTE COLOR lookup table is not supported", p);
    long entries = 0, bits = 0;
    if (!descriptor_value(ds, desc_tag, 0, entries) || !descriptor_value(ds, desc_tag, 1, first) ||
        !descriptor_value(ds, desc_tag, 2, bits))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': PALETTE COLOR without a %s lookup table descriptor", p, name);
    if (entries <= 0) entries += 65536; // 0 (or a US value read as SS) means 65536
    if (bits != 8 && bits != 16)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the %s palette has %ld bits per entry (8 or 16)", p, name, bits);
    // OW (or US) words in the machine's order
    std::vector<uint16_t> words;
    if (!ds.words(ds.root(), data_tag, words))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': PALETTE COLOR without the %s lookup table data", p, name);
    const size_t nwords = words.size(), n = size_t(entries);
    out.resize(n);
    if (bits == 16 || nwords >= n) { // a word each (8-bit entries in its low byte)
        if (nwords < n)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the %s palette holds %zu words for %zu entries", p, name,
                            nwords, n);
        for (size_t i = 0; i < n; i++) out[i] = bits == 16 ? words[i] : uint16_t((words[i] & 0xffu) * 257u);
    } else { // two 8-bit entries a word, the first in the low byte
        if (2 * nwords < n)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the %s palette holds %zu bytes for %zu 8-bit entries", p, name,
                            2 * nwords, n);
        for (size_t i = 0; i < n; i++) {
            const unsigned byte = (words[i / 2] >> (8 * (i & 1))) & 0xffu;
            out[i] = uint16_t(byte * 257u); // to 16 bits: 255 -> 65535
        }
    }
    return VXL_OK;
}

} // namespace

int read_palette(const Dataset &ds, const Image &im, Palette &pal, vxl_err *e)
{
    using namespace tags;
    long first[3] = {0, 0, 0};
    int rc = read_table(ds, im, RedPaletteDescriptor, RedPaletteData, SegmentedRedPaletteData, "red", pal.rgb[0],
                        first[0], e);
    if (!rc)
        rc = read_table(ds, im, GreenPaletteDescriptor, GreenPaletteData, SegmentedGreenPaletteData, "green",
                        pal.rgb[1], first[1], e);
    if (!rc)
        rc = read_table(ds, im, BluePaletteDescriptor, BluePaletteData, SegmentedBluePaletteData, "blue", pal.rgb[2],
                        first[2], e);
    if (rc) return rc;
    if (first[1] != first[0] || first[2] != first[0] || pal.rgb[1].size() != pal.rgb[0].size() ||
        pal.rgb[2].size() != pal.rgb[0].size())
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the red, green and blue palettes disagree in size or first value",
                        im.path.c_str());
    pal.first = first[0];
    return VXL_OK;
}

namespace {

template <typename T> void indices_to_rgb(const Palette &pal, size_t n, T *px)
{
    // the output keeps the container's type: 8-bit indices give 8-bit colour
    const double scale = sizeof(T) == 1 ? 255.0 / 65535.0 : 1.0;
    const long last = long(pal.rgb[0].size()) - 1;
    // from the last pixel down: pixel i's colour lands at 3i..3i+2, over
    // indices already turned, never over one still to read
    for (size_t i = n; i-- > 0;) {
        const size_t k = size_t(std::min(last, std::max(0L, long(px[i]) - pal.first)));
        for (int c = 2; c >= 0; c--) px[3 * i + size_t(c)] = T(std::lround(pal.rgb[c][k] * scale));
    }
}

} // namespace

void rgb_of_palette(const Image &s, const Palette &pal, void *frame)
{
    const size_t n = size_t(s.rows) * s.cols;
    if (s.bits_alloc == 8) indices_to_rgb(pal, n, static_cast<uint8_t *>(frame));
    else indices_to_rgb(pal, n, static_cast<uint16_t *>(frame));
}

} // namespace vxl_dicom
