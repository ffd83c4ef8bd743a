// dicom_pixels.cpp - one DICOM file's frames as pixels: grey, or RGB for
// colour and PALETTE COLOR (samples of a pixel together, YCbCr turned into
// RGB, whatever the encoding's layout). A file is read
// once whatever number of its frames are wanted (a multi-frame file of 1000
// frames is one read, not 1000).
//
// Who decodes what (docs/dicom.md gives the reasons):
//   uncompressed (implicit/explicit little endian, explicit big endian,
//     deflated): the data set seam's parser (dicom_dataset.hpp) hands the
//     values over in native order;
//   RLE Lossless, grey JPEG Lossless process 14 and SV1: our C
//     (dicom_rle.c, dicom_jpeg_lossless.c), given each frame's fragments
//     joined;
//   JPEG 2000 and HTJ2K: OpenJPEG, opened on the first frame (dicom_j2k.c),
//     given the same;
//   JPEG Baseline and Extended, JPEG-LS, colour lossless JPEG: the
//     backend's own codecs where it has them (dcmtk's dcmjpeg and dcmjpls),
//     else refused by name with the command that decompresses them.
#include "dicom_series.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

extern "C" {
#include "dicom_j2k.h"
#include "dicom_jpeg_lossless.h"
#include "dicom_rle.h"
#include "error.h"
}

namespace vxl_dicom {

namespace {

enum class Codec { native, rle, jpeg_lossless, j2k, backend, none };

Codec codec_of(const Image &im)
{
    using namespace syntax;
    const std::string &x = im.syntax;
    if (!im.encapsulated) return Codec::native;
    if (x == Rle) return Codec::rle;
    // our lossless JPEG decoder is grey only
    if ((x == JpegLossless14 || x == JpegLosslessSV1) && im.samples == 1) return Codec::jpeg_lossless;
    if (x == J2kLossless || x == J2k || x == Htj2kLossless || x == Htj2kRpclLossless || x == Htj2k) return Codec::j2k;
    if (Dataset::has_codec(x, im.samples)) return Codec::backend;
    return Codec::none;
}

// What decompresses a syntax only the dcmtk backend decodes, for the
// message where this build has no codec for it.
const char *decompress_with(const std::string &x)
{
    using namespace syntax;
    if (x == JpegLsLossless || x == JpegLsNearLossless) return "dcmtk's dcmdjpls or gdcmconv --raw";
    if (x == JpegBaseline || x == JpegExtended || x == JpegLossless14 || x == JpegLosslessSV1)
        return "dcmtk's dcmdjpeg or gdcmconv --raw";
    return nullptr;
}

// Stored value of pixel i as a signed or unsigned integer of bits_stored.
template <typename T> void unpack(const T *src, size_t n, unsigned bits, bool is_signed, T *dst)
{
    using U = typename std::make_unsigned<T>::type;
    const unsigned width = sizeof(T) * 8;
    const U mask = bits >= width ? U(~U(0)) : U((U(1) << bits) - 1);
    for (size_t i = 0; i < n; i++) {
        U u = U(U(src[i]) & mask);
        if (is_signed && bits < width && (u >> (bits - 1)) & 1u) u = U(u | U(~mask)); // sign-extend
        dst[i] = T(u);
    }
}

void unpack_frame(const Image &s, const void *src, size_t n, void *dst)
{
    const bool sgn = s.pixel_rep == 1;
    if (s.bits_alloc == 8) {
        if (sgn) unpack(static_cast<const int8_t *>(src), n, s.bits_stored, true, static_cast<int8_t *>(dst));
        else unpack(static_cast<const uint8_t *>(src), n, s.bits_stored, false, static_cast<uint8_t *>(dst));
    } else if (s.bits_alloc == 32) {
        if (sgn) unpack(static_cast<const int32_t *>(src), n, s.bits_stored, true, static_cast<int32_t *>(dst));
        else unpack(static_cast<const uint32_t *>(src), n, s.bits_stored, false, static_cast<uint32_t *>(dst));
    } else {
        if (sgn) unpack(static_cast<const int16_t *>(src), n, s.bits_stored, true, static_cast<int16_t *>(dst));
        else unpack(static_cast<const uint16_t *>(src), n, s.bits_stored, false, static_cast<uint16_t *>(dst));
    }
}

// How a decoded colour frame lies in memory: the samples of a pixel
// together, planes (all of the first sample, then ...), or uncompressed
// YBR_FULL_422's Y0 Y1 Cb Cr for every two pixels of a row.
enum class Layout { interleaved, planar, ybr422 };

// Full-range YCbCr, which must be turned into RGB: YBR_FULL and
// YBR_FULL_422 (the photometric interpretation, or the colour model a
// dcmtk codec reports it decoded into).
bool is_ybr_full(const std::string &model) { return model.compare(0, 8, "YBR_FULL") == 0; }

// A colour frame of n pixels as RGB with the samples of a pixel together
// into dst, the container's type kept; ybr: the samples are full-range
// YCbCr (PS3.3 C.7.6.3.1.2), turned into RGB (rounded, clamped to the
// stored bits); RGB is copied exactly.
template <typename T> void colour_to_rgb(const T *src, size_t n, Layout layout, bool ybr, unsigned bits, T *dst)
{
    const double half = double(1u << (bits - 1)), top = double((1ull << bits) - 1);
    for (size_t i = 0; i < n; i++) {
        T a, b, c;
        if (layout == Layout::interleaved) { a = src[3 * i]; b = src[3 * i + 1]; c = src[3 * i + 2]; }
        else if (layout == Layout::planar) { a = src[i]; b = src[n + i]; c = src[2 * n + i]; }
        else { a = src[4 * (i / 2) + (i & 1)]; b = src[4 * (i / 2) + 2]; c = src[4 * (i / 2) + 3]; }
        if (ybr) {
            const double y = a, cb = b - half, cr = c - half;
            const double rgb[3] = {y + 1.402 * cr, y - 0.344136 * cb - 0.714136 * cr, y + 1.772 * cb};
            for (int k = 0; k < 3; k++) dst[3 * i + k] = T(std::lround(std::min(top, std::max(0.0, rgb[k]))));
        } else {
            dst[3 * i] = a;
            dst[3 * i + 1] = b;
            dst[3 * i + 2] = c;
        }
    }
}

void rgb_of_colour(const Image &s, const void *src, Layout layout, bool ybr, void *dst)
{
    const size_t n = size_t(s.rows) * s.cols;
    if (s.bits_alloc == 8)
        colour_to_rgb(static_cast<const uint8_t *>(src), n, layout, ybr, s.bits_stored, static_cast<uint8_t *>(dst));
    else
        colour_to_rgb(static_cast<const uint16_t *>(src), n, layout, ybr, s.bits_stored, static_cast<uint16_t *>(dst));
}

// The layout an uncompressed colour frame has.
Layout native_layout(const Image &s)
{
    if (s.photometric == "YBR_FULL_422") return Layout::ybr422;
    return s.planar == 1 ? Layout::planar : Layout::interleaved;
}

// Frame f's fragments joined (PS3.5 A.4): by the basic offset table when it
// has one; else one fragment per frame when the counts agree; else, for
// JPEG, a frame starts at each fragment that opens with an SOI marker.
int frame_bytes(const Image &s, const Fragments &fr, unsigned f, std::vector<uint8_t> &out, vxl_err *e)
{
    const char *p = s.path.c_str();
    const size_t n = fr.items.size(), frames = size_t(s.file_frames);
    size_t first = 0, end = n;
    if (frames == 1) {
        // every fragment
    } else if (!fr.bot.empty()) {
        if (fr.bot.size() != frames)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': basic offset table has %zu entries for %zu frames", p,
                            fr.bot.size(), frames);
        const uint64_t lo = fr.bot[f], hi = f + 1 < frames ? fr.bot[f + 1] : UINT64_MAX;
        first = n;
        for (size_t i = 0; i < n; i++) if (fr.at[i] == lo) { first = i; break; }
        if (first == n || !(hi > lo))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': basic offset table entry %u (%llu) is not at a fragment", p, f,
                            (unsigned long long)lo);
        end = first + 1;
        while (end < n && fr.at[end] < hi) end++;
    } else if (n == frames) {
        first = f;
        end = f + 1;
    } else if (s.syntax != syntax::Rle) {
        size_t seen = 0;
        first = n;
        for (size_t i = 0; i < n; i++) {
            const bool soi = fr.items[i].second >= 2 && fr.items[i].first[0] == 0xFF && fr.items[i].first[1] == 0xD8;
            if (!soi) continue;
            if (seen == f) first = i;
            else if (seen == size_t(f) + 1) { end = i; break; }
            seen++;
        }
        if (first == n)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': frame %u of %zu not found among %zu fragments", p, f + 1,
                            frames, n);
    } else {
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %zu RLE fragments for %zu frames (one per frame is required)", p,
                        n, frames);
    }
    out.clear();
    for (size_t i = first; i < end; i++) out.insert(out.end(), fr.items[i].first, fr.items[i].first + fr.items[i].second);
    return VXL_OK;
}

} // namespace

unsigned components_of(const Image &im) { return is_colour(im) || is_palette(im) ? 3 : 1; }

bool is_colour(const Image &im)
{
    if (im.samples != 3) return false;
    const std::string &p = im.photometric;
    return p == "RGB" || p == "YBR_FULL" || p == "YBR_FULL_422" || p == "YBR_ICT" || p == "YBR_RCT";
}

std::string decodable(const Image &im)
{
    if (codec_of(im) != Codec::none) return "";
    if (const char *tool = decompress_with(im.syntax))
        return format("'%s': %s%s is not decoded on this system (no codec for it in this build): decompress the "
                      "series first, e.g. with %s", im.path.c_str(), im.samples == 1 ? "" : "colour ",
                      im.xfer.c_str(), tool);
    return format("'%s': compressed transfer syntax '%s' is not supported (decompress first, e.g. gdcmconv --raw)",
                  im.path.c_str(), im.xfer.c_str());
}

int read_frames(const std::vector<const Image *> &which, const std::vector<void *> &dst, vxl_err *e)
{
    const Image &s = *which[0];
    const Codec codec = codec_of(s);
    Dataset ds;
    int rc = ds.open(s.path, e);
    if (rc) return rc;
    const char *p = s.path.c_str();
    if (!ds.has(ds.root(), tags::PixelData)) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': no PixelData", p);
    const bool colour = is_colour(s);
    Palette palette;
    if (is_palette(s)) {
        rc = read_palette(ds, s, palette, e);
        if (rc) return rc;
    }
    const size_t n = size_t(s.rows) * s.cols, bytes = n * (s.bits_alloc / 8);
    // a frame as stored uncompressed (YBR_FULL_422: two samples a pixel) and as decoded
    const size_t stored = colour ? (native_layout(s) == Layout::ybr422 ? 2 : 3) * bytes : bytes;
    const size_t decoded = colour ? 3 * bytes : bytes;
    const bool ybr = is_ybr_full(s.photometric); // YBR_ICT/RCT: the J2K decoder returns RGB
    // dcmtk's codecs want room for an even number of bytes (a 3x3 RGB frame
    // of 27 needs 28)
    const size_t room = (decoded + 1) & ~size_t(1);
    std::vector<uint8_t> raw(codec == Codec::native ? 0 : room), joined;
    Fragments fr;
    if (codec == Codec::rle || codec == Codec::jpeg_lossless || codec == Codec::j2k) {
        rc = ds.fragments(fr, e);
        if (rc) return rc;
    }
    const uint8_t *all = nullptr;
    if (codec == Codec::native) {
        const size_t need = stored * size_t(s.file_frames), have = ds.pixel_length();
        if (have < need)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': truncated PixelData: %zu bytes for %ld frame(s) of %ux%u "
                            "pixels of %u bits, got %zu", p, need, s.file_frames, s.cols, s.rows, s.bits_alloc, have);
        size_t len = 0;
        rc = ds.pixels(s.bits_alloc, all, len, e);
        if (rc) return rc;
    }
    // in frame order, so that a backend's codec resumes its fragment walk
    // from the previous frame instead of starting over
    std::vector<size_t> order(which.size());
    for (size_t i = 0; i < order.size(); i++) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return which[a]->frame < which[b]->frame; });
    uint32_t start_fragment = 0;
    unsigned previous = 0;
    for (size_t i : order) {
        const unsigned f = which[i]->frame;
        if (codec == Codec::native) {
            const uint8_t *frame = all + size_t(f) * stored;
            if (colour) rgb_of_colour(s, frame, native_layout(s), ybr, dst[i]);
            else unpack_frame(s, frame, n, dst[i]);
            if (is_palette(s)) rgb_of_palette(s, palette, dst[i]);
            continue;
        }
        Layout layout = Layout::interleaved;
        bool frame_ybr = ybr;
        if (codec == Codec::backend) {
            std::string model; // what the codec produced: RGB, or YCbCr it left as it was
            if (f == 0 || f != previous + 1) start_fragment = 0; // 0: the codec finds the frame itself
            previous = f;
            rc = ds.decode_frame(f, start_fragment, raw.data(), room, model, e);
            if (rc) return rc;
            frame_ybr = is_ybr_full(model);
        } else {
            rc = frame_bytes(s, fr, f, joined, e);
            if (rc) return rc;
            vxl_err codec_err = {};
            const uint8_t *b = joined.data();
            const size_t len = joined.size();
            const unsigned bytes_per = s.bits_alloc / 8;
            const unsigned spp = colour ? 3 : 1;
            if (codec == Codec::rle) {
                rc = vxl_dicom_rle_decode_samples(b, len, s.rows, s.cols, bytes_per, spp, raw.data(), &codec_err);
                layout = Layout::planar; // RLE keeps colour as planes
            } else if (codec == Codec::j2k) {
                rc = vxl_j2k_decode(b, len, s.rows, s.cols, bytes_per, spp, raw.data(), &codec_err);
                frame_ybr = s.photometric == "YBR_FULL";
            } else {
                rc = vxl_jpeg_lossless_decode(b, len, s.rows, s.cols, bytes_per, raw.data(), &codec_err);
            }
            if (rc) {
                if (s.file_frames > 1) return vxl_fail(e, rc, "'%s': frame %u: %s", p, f + 1, codec_err.msg);
                return vxl_fail(e, rc, "'%s': %s", p, codec_err.msg);
            }
        }
        if (colour) rgb_of_colour(s, raw.data(), layout, frame_ybr, dst[i]);
        else unpack_frame(s, raw.data(), n, dst[i]);
        if (is_palette(s)) rgb_of_palette(s, palette, dst[i]);
    }
    return VXL_OK;
}

} // namespace vxl_dicom
