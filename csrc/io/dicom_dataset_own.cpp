// dicom_dataset_own.cpp - the data set seam (dicom_dataset.hpp) on our own
// Part 10 parser, for where dcmtk has no build (Windows). It reads
//   the meta header (group 0002, explicit VR little endian), then the data
//   set in implicit VR little endian, explicit VR little or big endian, or
//   deflated explicit VR little endian (inflated through zlib_api.h, which
//   opens zlib at run time); a file without the preamble and "DICM" is read
//   as a bare data set when its first element looks like one;
//   undefined lengths: sequences and items closed by their delimiters, and
//   encapsulated PixelData (basic offset table, then fragments);
//   UN elements holding a sequence (their items are implicit VR little
//   endian, PS3.5 6.2.2), and elements of a known tag stored as UN, read as
//   their dictionary VR (as dcmtk's dcmEnableUnknownVRConversion does).
// Every length is checked against its container and the file before
// anything is read or allocated; odd lengths are taken as they are. Values
// longer than kHeaderReadLength stay on disk until asked for, so a folder
// scan reads headers only. Its codecs are our C alone: has_codec is false
// (JPEG Baseline/Extended and JPEG-LS are refused by name by the pixels
// room).
#include "dicom_series.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

extern "C" {
#include "files.h"
#include "zlib_api.h"
}

namespace vxl_dicom {

namespace {

constexpr uint32_t kUndefined = 0xFFFFFFFFu;
constexpr Tag kItem = tag(0xFFFE, 0xE000), kItemEnd = tag(0xFFFE, 0xE00D), kSequenceEnd = tag(0xFFFE, 0xE0DD);
constexpr int kMaxDepth = 32;                        // nested sequences deeper than this: a damaged file
constexpr uint64_t kMaxInflated = uint64_t(1) << 30; // a deflated data set past 1 GiB: refused
constexpr size_t kWindow = 1 << 16;                  // bytes read from disk at a time

// The VR of the tags the reader looks up, for implicit VR data sets and
// for elements an archive rewrote as UN; other tags need none.
struct DictEntry {
    Tag t;
    char vr[3];
};
const DictEntry kDictionary[] = {
    {tags::TransferSyntaxUID, "UI"}, {tags::Modality, "CS"}, {tags::SeriesDescription, "LO"},
    {tags::SliceThickness, "DS"}, {tags::SpacingBetweenSlices, "DS"}, {tags::TriggerTime, "DS"},
    {tags::SeriesInstanceUID, "UI"}, {tags::AcquisitionNumber, "IS"}, {tags::InstanceNumber, "IS"},
    {tags::ImagePositionPatient, "DS"}, {tags::ImageOrientationPatient, "DS"},
    {tags::TemporalPositionIdentifier, "IS"}, {tags::StackID, "SH"}, {tags::FrameContentSequence, "SQ"},
    {tags::PlanePositionSequence, "SQ"}, {tags::PlaneOrientationSequence, "SQ"},
    {tags::TemporalPositionIndex, "UL"}, {tags::SamplesPerPixel, "US"}, {tags::PhotometricInterpretation, "CS"},
    {tags::PlanarConfiguration, "US"}, {tags::NumberOfFrames, "IS"}, {tags::Rows, "US"}, {tags::Columns, "US"},
    {tags::PixelSpacing, "DS"}, {tags::BitsAllocated, "US"}, {tags::BitsStored, "US"},
    {tags::PixelRepresentation, "US"}, {tags::RescaleIntercept, "DS"}, {tags::RescaleSlope, "DS"},
    // descriptors are US or SS (PS3.3 C.7.6.3.1.5): read as US unless stored as SS
    {tags::RedPaletteDescriptor, "US"}, {tags::GreenPaletteDescriptor, "US"}, {tags::BluePaletteDescriptor, "US"},
    {tags::RedPaletteData, "OW"}, {tags::GreenPaletteData, "OW"}, {tags::BluePaletteData, "OW"},
    {tags::SegmentedRedPaletteData, "OW"}, {tags::SegmentedGreenPaletteData, "OW"},
    {tags::SegmentedBluePaletteData, "OW"}, {tags::PixelMeasuresSequence, "SQ"},
    {tags::PixelValueTransformationSequence, "SQ"}, {tags::GridFrameOffsetVector, "DS"},
    {tags::SharedFunctionalGroupsSequence, "SQ"}, {tags::PerFrameFunctionalGroupsSequence, "SQ"},
    {tags::PixelData, "OW"},
};

const char *dictionary_vr(Tag t)
{
    for (const DictEntry &d : kDictionary)
        if (d.t == t) return d.vr;
    return "UN";
}

// VRs whose explicit encoding has a 4-byte length after 2 reserved bytes.
bool long_form(const char *vr)
{
    static const char *const k[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ", "SV", "UC", "UN", "UR", "UT", "UV"};
    for (const char *v : k)
        if (!memcmp(vr, v, 2)) return true;
    return false;
}

bool is_vr(const uint8_t *b) { return b[0] >= 'A' && b[0] <= 'Z' && b[1] >= 'A' && b[1] <= 'Z'; }

// How the elements of an item are encoded.
struct Encoding {
    bool implicit = false, big = false;
};

uint16_t get16(const uint8_t *b, bool big) { return big ? uint16_t(b[0] << 8 | b[1]) : uint16_t(b[1] << 8 | b[0]); }
uint32_t get32(const uint8_t *b, bool big)
{
    return big ? uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | b[3]
               : uint32_t(b[3]) << 24 | uint32_t(b[2]) << 16 | uint32_t(b[1]) << 8 | b[0];
}

// The file's bytes: on disk through a window, or in memory (an inflated
// data set). Every read is checked against the size.
class Source {
public:
    ~Source()
    {
        if (fd_ >= 0) vxl_file_close(fd_);
    }
    bool open_file(const std::string &path)
    {
        fd_ = vxl_file_open_read(path.c_str(), 0);
        vxl_path_info st;
        if (fd_ < 0 || vxl_file_stat(fd_, &st)) return false;
        size_ = st.size;
        return true;
    }
    void use_memory(std::vector<uint8_t> &&bytes)
    {
        mem_ = std::move(bytes);
        in_memory_ = true;
        size_ = mem_.size();
    }
    uint64_t size() const { return size_; }
    bool read(uint64_t at, void *dst, size_t n)
    {
        if (at > size_ || n > size_ - at) return false;
        if (n == 0) return true; // an empty value: nothing to copy (its buffer may be null)
        if (in_memory_) {
            memcpy(dst, mem_.data() + at, n);
            return true;
        }
        if (n > kWindow) { // a large value straight into place, in pieces (a read may return less)
            uint8_t *out = static_cast<uint8_t *>(dst);
            while (n) {
                const int64_t got = vxl_file_pread(fd_, out, std::min<size_t>(n, size_t(1) << 30), at);
                if (got <= 0) return false;
                out += got;
                at += uint64_t(got);
                n -= size_t(got);
            }
            return true;
        }
        if (at < win_at_ || at + n > win_at_ + win_.size()) {
            const size_t want = size_t(std::min<uint64_t>(kWindow, size_ - at));
            win_.resize(want);
            if (vxl_file_pread(fd_, win_.data(), want, at) != int64_t(want)) {
                win_.clear();
                return false;
            }
            win_at_ = at;
        }
        memcpy(dst, win_.data() + (at - win_at_), n);
        return true;
    }

private:
    int fd_ = -1;
    uint64_t size_ = 0;
    bool in_memory_ = false;
    std::vector<uint8_t> mem_, win_;
    uint64_t win_at_ = 0;
};

} // namespace

struct Element {
    Tag t = 0;
    char vr[3] = "UN";
    Encoding enc;            // the encoding it was read in
    uint64_t at = 0;         // its value's offset in the source
    uint32_t length = 0;     // kUndefined: a sequence or encapsulated PixelData
    bool loaded = false;     // value holds the bytes
    std::vector<uint8_t> value;
    bool has_items = false;  // parsed as a sequence
    std::vector<std::unique_ptr<Item>> items;
    std::vector<std::pair<uint64_t, uint32_t>> fragments; // encapsulated PixelData: each item's value
};

struct Item {
    std::vector<Element> elements;
};

struct Dataset::Impl {
    std::string path;
    Source src;
    Item root;
    std::string uid;
    std::string problem; // the first thing that went wrong, for the message
    std::vector<uint8_t> pixel_bytes;

    bool fail(const std::string &why)
    {
        if (problem.empty()) problem = why;
        return false;
    }
    bool read(uint64_t at, void *dst, size_t n)
    {
        return src.read(at, dst, n) || fail(format("cut short at byte %llu", (unsigned long long)at));
    }
    bool parse_items(Element &el, uint64_t &pos, uint64_t end, Encoding enc, int depth);
    bool parse_fragments(Element &el, uint64_t &pos, uint64_t end);
    bool parse(Item &into, uint64_t &pos, uint64_t end, bool until_delimiter, Encoding enc, int depth,
               bool stop_after_meta);
    Element *find(const Item *it, Tag t);
    bool load(Element &el);
    const Element *value_of(const Item *it, Tag t, const char *&vr);
    template <typename T, typename Out>
    bool binary_of(const Item *it, Tag t, const char *want, unsigned long i, Out &out);
};

// Elements of one item from pos up to end (a defined length) or up to the
// item delimiter (until_delimiter), at nesting depth depth.
bool Dataset::Impl::parse(Item &into, uint64_t &pos, uint64_t end, bool until_delimiter, Encoding enc, int depth,
                          bool stop_after_meta)
{
    if (depth > kMaxDepth) return fail("sequences nested too deep");
    while (pos < end) {
        uint8_t h[12];
        if (end - pos < 8) return fail(format("an element header cut short at byte %llu", (unsigned long long)pos));
        if (!read(pos, h, 8)) return false;
        // item tags are always implicit: tag and 4-byte length
        const Tag t = Tag(get16(h, enc.big)) << 16 | get16(h + 2, enc.big);
        if (stop_after_meta && (t >> 16) != 0x0002) return true;
        if (t == kItemEnd) {
            pos += 8;
            if (until_delimiter) return true;
            return fail("an item delimiter outside an item");
        }
        if ((t >> 16) == 0xFFFE) return fail(format("an unexpected (FFFE,%04X) at byte %llu", unsigned(t & 0xffff),
                                                    (unsigned long long)pos));
        Element el;
        el.t = t;
        el.enc = enc;
        uint64_t header = 8;
        if (enc.implicit) {
            memcpy(el.vr, dictionary_vr(t), 3);
            el.length = get32(h + 4, enc.big);
        } else {
            if (!is_vr(h + 4))
                return fail(format("no value representation for (%04X,%04X) at byte %llu", unsigned(t >> 16),
                                   unsigned(t & 0xffff), (unsigned long long)pos));
            el.vr[0] = char(h[4]);
            el.vr[1] = char(h[5]);
            if (long_form(el.vr)) {
                if (end - pos < 12 || !read(pos, h, 12))
                    return fail(format("an element header cut short at byte %llu", (unsigned long long)pos));
                el.length = get32(h + 8, enc.big);
                header = 12;
            } else {
                el.length = get16(h + 6, enc.big);
            }
        }
        pos += header;
        // an archive's UN for a known tag: the dictionary's VR (its value
        // is encoded as in implicit VR little endian)
        const bool was_un = !memcmp(el.vr, "UN", 2);
        if (was_un && strcmp(dictionary_vr(t), "UN")) memcpy(el.vr, dictionary_vr(t), 3);
        el.at = pos;
        if (el.length == kUndefined) {
            if (t == tags::PixelData && depth == 0 && !enc.implicit && !was_un) {
                if (!parse_fragments(el, pos, end)) return false;
            } else {
                // a sequence (SQ, or UN / implicit with undefined length: its
                // items implicit VR little endian when it was UN)
                Encoding inner = enc;
                if (was_un) inner = Encoding{true, false};
                if (!parse_items(el, pos, end, inner, depth)) return false;
            }
        } else {
            if (el.length > end - pos)
                return fail(format("(%04X,%04X) claims %u bytes, %llu are left", unsigned(t >> 16),
                                   unsigned(t & 0xffff), el.length, (unsigned long long)(end - pos)));
            if (!memcmp(el.vr, "SQ", 2)) {
                uint64_t p = pos;
                Encoding inner = enc;
                if (was_un) inner = Encoding{true, false};
                if (!parse_items(el, p, pos + el.length, inner, depth)) return false;
            } else if (el.length <= kHeaderReadLength) {
                el.value.resize(el.length);
                if (!read(pos, el.value.data(), el.length)) return false;
                el.loaded = true;
            }
            pos += el.length;
        }
        into.elements.push_back(std::move(el));
    }
    if (until_delimiter) return fail("an item without its delimiter (the file is cut short)");
    return true;
}

// A sequence's items from pos: up to end for a defined length, else up to
// the sequence delimiter (el.length undefined).
bool Dataset::Impl::parse_items(Element &el, uint64_t &pos, uint64_t end, Encoding enc, int depth)
{
    const bool undefined = el.length == kUndefined;
    el.has_items = true;
    while (pos < end) {
        uint8_t h[8];
        if (end - pos < 8 || !read(pos, h, 8)) return fail("a sequence item cut short");
        const Tag t = Tag(get16(h, enc.big)) << 16 | get16(h + 2, enc.big);
        const uint32_t len = get32(h + 4, enc.big);
        pos += 8;
        if (t == kSequenceEnd) {
            if (undefined) return true;
            return fail("a sequence delimiter in a sequence of defined length");
        }
        if (t != kItem)
            return fail(format("(%04X,%04X) where an item of (%04X,%04X) belongs", unsigned(t >> 16),
                               unsigned(t & 0xffff), unsigned(el.t >> 16), unsigned(el.t & 0xffff)));
        std::unique_ptr<Item> item(new Item);
        if (len == kUndefined) {
            if (!parse(*item, pos, end, true, enc, depth + 1, false)) return false;
        } else {
            if (len > end - pos) return fail(format("an item claims %u bytes, %llu are left", len,
                                                    (unsigned long long)(end - pos)));
            uint64_t p = pos;
            if (!parse(*item, p, pos + len, false, enc, depth + 1, false)) return false;
            pos += len;
        }
        el.items.push_back(std::move(item));
    }
    if (undefined) return fail("a sequence without its delimiter (the file is cut short)");
    return true;
}

// Encapsulated PixelData (PS3.5 A.4): items, each a fragment (the first the
// basic offset table), then the sequence delimiter. Where they lie is kept;
// their bytes are read when fragments() is asked.
bool Dataset::Impl::parse_fragments(Element &el, uint64_t &pos, uint64_t end)
{
    while (pos < end) {
        uint8_t h[8];
        if (end - pos < 8 || !read(pos, h, 8)) break;
        const Tag t = Tag(get16(h, el.enc.big)) << 16 | get16(h + 2, el.enc.big);
        const uint32_t len = get32(h + 4, el.enc.big);
        pos += 8;
        if (t == kSequenceEnd) return true;
        if (t != kItem || len == kUndefined)
            return fail(format("(%04X,%04X) among the compressed PixelData's items", unsigned(t >> 16),
                               unsigned(t & 0xffff)));
        if (len > end - pos) return fail(format("a compressed fragment claims %u bytes, %llu are left", len,
                                                (unsigned long long)(end - pos)));
        el.fragments.emplace_back(pos, len);
        pos += len;
    }
    return fail("compressed PixelData without its delimiter (the file is cut short)");
}

Element *Dataset::Impl::find(const Item *it, Tag t)
{
    if (!it) return nullptr;
    for (const Element &el : it->elements)
        if (el.t == t) return const_cast<Element *>(&el);
    return nullptr;
}

// Reads a value left on disk; its length was checked against the file.
bool Dataset::Impl::load(Element &el)
{
    if (el.loaded) return true;
    if (el.length == kUndefined) return false;
    el.value.resize(el.length);
    if (!read(el.at, el.value.data(), el.length)) return false;
    el.loaded = true;
    return true;
}

// An element's loaded value and its VR; nullptr when absent or a sequence.
const Element *Dataset::Impl::value_of(const Item *it, Tag t, const char *&vr)
{
    Element *el = find(it, t);
    if (!el || el->has_items || !load(*el)) return nullptr;
    vr = el->vr;
    return el;
}

Dataset::Dataset() : impl_(new Impl) {}
Dataset::~Dataset() = default;

void Dataset::prepare() {}

namespace {

// The data set after the meta header, inflated (raw deflate, RFC 1951).
int inflate_rest(Source &src, uint64_t from, std::vector<uint8_t> &out, const std::string &path, vxl_err *e)
{
    const vxl_zlib *z = vxl_zlib_api(e);
    if (!z) return VXL_ERR_IO;
    const uint64_t n = src.size() - from;
    std::vector<uint8_t> in(size_t(n > 0 ? n : 0));
    if (n && !src.read(from, in.data(), size_t(n)))
        return vxl_fail(e, VXL_ERR_IO, "'%s': cannot read the deflated data set", path.c_str());
    z_stream s;
    memset(&s, 0, sizeof s);
    if (VXL_INFLATE_INIT2(z, &s, -15) != Z_OK)
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': cannot start inflating the data set", path.c_str());
    s.next_in = in.data();
    s.avail_in = uInt(in.size());
    out.clear();
    int rc = Z_OK;
    while (rc != Z_STREAM_END) {
        // grown as the output arrives, never sized from the input's claim
        if (out.size() >= kMaxInflated) {
            z->inflateEnd(&s);
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s': the deflated data set inflates past %llu bytes", path.c_str(),
                            (unsigned long long)kMaxInflated);
        }
        const size_t have = out.size(), chunk = std::max<size_t>(size_t(1) << 16, have / 2);
        out.resize(have + chunk);
        s.next_out = out.data() + have;
        s.avail_out = uInt(chunk);
        rc = z->inflate(&s, Z_NO_FLUSH);
        out.resize(have + (chunk - s.avail_out));
        if (rc == Z_STREAM_END) break;
        if (rc != Z_OK || (s.avail_in == 0 && s.avail_out != 0)) {
            z->inflateEnd(&s);
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the deflated data set is damaged or cut short", path.c_str());
        }
    }
    z->inflateEnd(&s);
    return VXL_OK;
}

} // namespace

int Dataset::open(const std::string &path, vxl_err *e)
{
    Impl &d = *impl_;
    d.path = path;
    const char *p = path.c_str();
    if (!d.src.open_file(path)) return vxl_fail(e, VXL_ERR_IO, "'%s': cannot open: %s", p, strerror(errno));
    uint8_t head[132];
    uint64_t pos = 0;
    if (d.src.size() >= 132 && d.src.read(0, head, 132) && !memcmp(head + 128, "DICM", 4)) {
        pos = 132;
        // the meta header's own length when it starts with it (a deflated
        // data set's first bytes could pass for group 0002), else up to the
        // first element of another group
        uint8_t g[16];
        uint64_t meta_end = d.src.size();
        bool bounded = false;
        if (d.src.read(pos, g, 12) && get32(g, false) == 0x00000002u && !memcmp(g + 4, "UL", 2) &&
            get16(g + 6, false) == 4) {
            const uint64_t len = get32(g + 8, false);
            if (len <= d.src.size() - pos - 12) {
                meta_end = pos + 12 + len;
                bounded = true;
            }
        }
        Item meta;
        if (!d.parse(meta, pos, meta_end, false, Encoding{}, 0, !bounded))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': not a readable DICOM file: the meta header: %s", p,
                            d.problem.c_str());
        const char *vr = nullptr;
        const Element *ts = d.value_of(&meta, tags::TransferSyntaxUID, vr);
        if (!ts) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': not a readable DICOM file: no TransferSyntaxUID", p);
        d.uid.assign(ts->value.begin(), ts->value.end());
        while (!d.uid.empty() && (d.uid.back() == '\0' || d.uid.back() == ' ')) d.uid.pop_back();
    } else {
        // a bare data set (no preamble): explicit VR when a VR follows the
        // first tag, and a plausible first group, else not DICOM
        uint8_t h[6];
        if (!d.src.read(0, h, 6) || get16(h, false) < 0x0002 || get16(h, false) > 0x0008)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': not a readable DICOM file: no \"DICM\" and no data set", p);
        d.uid = is_vr(h + 4) ? syntax::ExplicitLittle : syntax::ImplicitLittle;
    }
    Encoding enc;
    enc.implicit = d.uid == syntax::ImplicitLittle;
    enc.big = d.uid == syntax::ExplicitBig;
    if (d.uid == syntax::Deflated) {
        std::vector<uint8_t> inflated;
        int rc = inflate_rest(d.src, pos, inflated, path, e);
        if (rc) return rc;
        d.src.use_memory(std::move(inflated));
        pos = 0;
    }
    if (!d.parse(d.root, pos, d.src.size(), false, enc, 0, false))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': not a readable DICOM file: %s", p, d.problem.c_str());
    return VXL_OK;
}

const Item *Dataset::root() const { return &impl_->root; }

std::string Dataset::syntax() const { return impl_->uid; }

bool Dataset::has(const Item *it, Tag t) const { return impl_->find(it, t) != nullptr; }

namespace {

bool is_text(const char *vr)
{
    static const char *const k[] = {"AE", "AS", "CS", "DA", "DS", "DT", "IS", "LO", "LT", "PN", "SH", "ST", "TM",
                                    "UC", "UI", "UR", "UT"};
    for (const char *v : k)
        if (!memcmp(vr, v, 2)) return true;
    return false;
}

// Value i of a backslash-separated string, padding (spaces, NUL) trimmed.
bool text_value(const std::vector<uint8_t> &v, unsigned long i, std::string &out)
{
    size_t start = 0;
    for (unsigned long k = 0; k < i; k++) {
        const void *bs = start < v.size() ? memchr(v.data() + start, '\\', v.size() - start) : nullptr;
        if (!bs) return false;
        start = size_t(static_cast<const uint8_t *>(bs) - v.data()) + 1;
    }
    size_t stop = start;
    while (stop < v.size() && v[stop] != '\\') stop++;
    while (start < stop && (v[start] == ' ' || v[start] == '\0')) start++;
    while (stop > start && (v[stop - 1] == ' ' || v[stop - 1] == '\0')) stop--;
    out.assign(v.begin() + long(start), v.begin() + long(stop));
    return true;
}

// Binary value i of size n in the element's byte order, as bytes of this
// machine's order; false when past the value.
bool binary_value(const Element &el, unsigned long i, size_t n, uint8_t *out)
{
    if (el.value.size() < n || i > el.value.size() / n - 1) return false;
    const uint8_t *b = el.value.data() + i * n;
    uint16_t probe = 1;
    uint8_t first;
    memcpy(&first, &probe, 1);
    const bool host_big = first == 0;
    for (size_t k = 0; k < n; k++) out[k] = el.enc.big != host_big ? b[n - 1 - k] : b[k];
    return true;
}

// Binary value i as a T of this machine.
template <typename T> bool binary_as(const Element &el, unsigned long i, T &out)
{
    uint8_t b[sizeof(T)];
    if (!binary_value(el, i, sizeof(T), b)) return false;
    memcpy(&out, b, sizeof(T));
    return true;
}

} // namespace

bool Dataset::string(const Item *it, Tag t, std::string &out) const
{
    const char *vr = nullptr;
    const Element *el = impl_->value_of(it, t, vr);
    if (!el || !is_text(vr)) return false;
    return text_value(el->value, 0, out);
}

bool Dataset::number(const Item *it, Tag t, unsigned long i, double &out) const
{
    const char *vr = nullptr;
    const Element *el = impl_->value_of(it, t, vr);
    if (!el) return false;
    if (!memcmp(vr, "DS", 2) || !memcmp(vr, "IS", 2)) {
        std::string s;
        if (!text_value(el->value, i, s) || s.empty()) return false;
        char *end = nullptr;
        const double x = strtod(s.c_str(), &end);
        if (*end || !std::isfinite(x)) return false;
        out = x;
        return true;
    }
    double d;
    if (!memcmp(vr, "FD", 2) && binary_as(*el, i, d)) {
        if (!std::isfinite(d)) return false;
        out = d;
        return true;
    }
    uint32_t u;
    if (!memcmp(vr, "UL", 2) && binary_as(*el, i, u)) {
        out = u;
        return true;
    }
    int32_t v;
    if (!memcmp(vr, "SL", 2) && binary_as(*el, i, v)) {
        out = v;
        return true;
    }
    return false;
}

// Value i of an element of VR want, as a T of this machine.
template <typename T, typename Out>
bool Dataset::Impl::binary_of(const Item *it, Tag t, const char *want, unsigned long i, Out &out)
{
    const char *vr = nullptr;
    const Element *el = value_of(it, t, vr);
    T x;
    if (!el || memcmp(vr, want, 2) || !binary_as(*el, i, x)) return false;
    out = x;
    return true;
}

bool Dataset::us(const Item *it, Tag t, unsigned long i, unsigned &out) const
{
    return impl_->binary_of<uint16_t>(it, t, "US", i, out);
}

bool Dataset::ss(const Item *it, Tag t, unsigned long i, int &out) const
{
    return impl_->binary_of<int16_t>(it, t, "SS", i, out);
}

size_t Dataset::items(const Item *it, Tag seq) const
{
    const Element *el = impl_->find(it, seq);
    return el && el->has_items ? el->items.size() : 0;
}

const Item *Dataset::item(const Item *it, Tag seq, size_t i) const
{
    const Element *el = impl_->find(it, seq);
    return el && el->has_items && i < el->items.size() ? el->items[i].get() : nullptr;
}

bool Dataset::words(const Item *it, Tag t, std::vector<uint16_t> &out) const
{
    const char *vr = nullptr;
    const Element *el = impl_->value_of(it, t, vr);
    if (!el || !(!memcmp(vr, "OW", 2) || !memcmp(vr, "US", 2))) return false;
    out.resize(el->value.size() / 2);
    for (size_t i = 0; i < out.size(); i++) binary_as(*el, i, out[i]);
    return true;
}

size_t Dataset::pixel_length() const
{
    const Element *el = impl_->find(&impl_->root, tags::PixelData);
    return el && el->length != kUndefined ? el->length : 0;
}

int Dataset::pixels(unsigned bits_alloc, const uint8_t *&data, size_t &len, vxl_err *e)
{
    Impl &d = *impl_;
    const char *p = d.path.c_str();
    Element *el = d.find(&d.root, tags::PixelData);
    if (!el) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': no PixelData", p);
    if (el->length == kUndefined)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': PixelData is encapsulated under an uncompressed transfer syntax", p);
    if (!d.load(*el)) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read PixelData: %s", p, d.problem.c_str());
    // a big-endian file's words (OW) or wider values turned to this
    // machine's order, in place
    const size_t unit = bits_alloc == 32 ? 4 : bits_alloc == 16 || !memcmp(el->vr, "OW", 2) ? 2 : 1;
    std::vector<uint8_t> &v = el->value;
    uint16_t probe = 1;
    uint8_t first;
    memcpy(&first, &probe, 1);
    if (unit > 1 && el->enc.big != (first == 0))
        for (size_t i = 0; i + unit <= v.size(); i += unit)
            for (size_t k = 0; k < unit / 2; k++) std::swap(v[i + k], v[i + unit - 1 - k]);
    // a 32-bit value in OW words of a big-endian file: as dcmtk reads it,
    // word order kept (each word swapped)
    data = v.data();
    len = v.size();
    return VXL_OK;
}

int Dataset::fragments(Fragments &fr, vxl_err *e)
{
    Impl &d = *impl_;
    const char *p = d.path.c_str();
    Element *el = d.find(&d.root, tags::PixelData);
    if (!el || el->fragments.empty())
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': compressed PixelData holds no fragments", p);
    // the items' values, one after the other in one buffer (their sizes
    // were checked against the file as they were parsed)
    size_t total = 0;
    for (const auto &f : el->fragments) total += f.second;
    d.pixel_bytes.resize(total);
    size_t at = 0;
    for (const auto &f : el->fragments) {
        if (!d.read(f.first, d.pixel_bytes.data() + at, f.second))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read compressed PixelData: %s", p, d.problem.c_str());
        at += f.second;
    }
    const uint8_t *b = d.pixel_bytes.data();
    const size_t bot_len = el->fragments[0].second;
    if (bot_len % 4) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': basic offset table of %zu bytes", p, bot_len);
    for (size_t k = 0; k < bot_len; k += 4) fr.bot.push_back(get32(b + k, false));
    at = bot_len;
    uint64_t offset = 0;
    for (size_t i = 1; i < el->fragments.size(); i++) {
        const size_t len = el->fragments[i].second;
        fr.items.emplace_back(b + at, len);
        fr.at.push_back(offset);
        offset += 8 + len; // item tag and length, then the value
        at += len;
    }
    if (fr.items.empty()) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': compressed PixelData holds no fragments", p);
    return VXL_OK;
}

bool Dataset::has_codec(const std::string &, unsigned) { return false; }

int Dataset::decode_frame(unsigned f, uint32_t &, void *, size_t, std::string &, vxl_err *e)
{
    return vxl_fail(e, VXL_ERR_FORMAT, "'%s': frame %u: this build has no codec of its own for %s",
                    impl_->path.c_str(), f + 1, syntax_name(impl_->uid).c_str());
}

} // namespace vxl_dicom
