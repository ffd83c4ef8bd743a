// dicom_dataset_dcmtk.cpp - the data set seam (dicom_dataset.hpp) on
// dcmtk: its parser (values over kHeaderReadLength stay on disk until
// asked for), and its JPEG Baseline/Extended (dcmjpeg, on IJG) and JPEG-LS
// (dcmjpls, on CharLS) codecs, with colour lossless JPEG, which our decoder
// does not take. The Linux helper voxlight-read-dicom links this file.
#include "dicom_dataset.hpp"

#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcpixseq.h>
#include <dcmtk/dcmdata/dcpxitem.h>
#include <dcmtk/dcmdata/dctk.h>
#include <dcmtk/dcmjpeg/djdecode.h>
#include <dcmtk/dcmjpls/djdecode.h>
#include <dcmtk/oflog/oflog.h>

#include <cmath>
#include <mutex>
#include <utility>

namespace vxl_dicom {

struct Dataset::Impl {
    DcmFileFormat ff;
    std::string path;
    E_TransferSyntax xs = EXS_Unknown;
    std::string uid;
};

namespace {

DcmItem *as_dcmtk(const Item *it) { return reinterpret_cast<DcmItem *>(const_cast<Item *>(it)); }
const Item *as_item(DcmItem *it) { return reinterpret_cast<const Item *>(it); }
DcmTagKey key(Tag t) { return DcmTagKey(Uint16(t >> 16), Uint16(t & 0xffff)); }

} // namespace

Dataset::Dataset() : impl_(new Impl) {}
Dataset::~Dataset() = default;

// No logging (dcmtk prints warnings to stderr by default; a library must
// never print); elements an archive rewrote as UN (unknown VR) read with
// their dictionary VR, so a PixelSpacing stored as UN is still found; the
// codecs registered in dcmtk's process-wide list, once, as dcmtk asks.
void Dataset::prepare()
{
    static std::once_flag once;
    std::call_once(once, [] {
        OFLog::configure(OFLogger::OFF_LOG_LEVEL);
        dcmEnableUnknownVRConversion.set(OFTrue);
        DJDecoderRegistration::registerCodecs();
        DJLSDecoderRegistration::registerCodecs();
    });
}

int Dataset::open(const std::string &path, vxl_err *e)
{
    prepare();
    impl_->path = path;
    OFCondition c = impl_->ff.loadFile(path.c_str(), EXS_Unknown, EGL_noChange, kHeaderReadLength, ERM_autoDetect);
    if (c.bad()) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': not a readable DICOM file: %s", path.c_str(), c.text());
    DcmXfer x(impl_->ff.getDataset()->getOriginalXfer());
    impl_->xs = x.getXfer();
    // the meta header's UID where it has one: dcmtk 3.6.7 does not know
    // HTJ2K's (it still reads the data set, explicit little endian)
    OFString meta;
    if (impl_->ff.getMetaInfo()->findAndGetOFString(DCM_TransferSyntaxUID, meta).good() && !meta.empty())
        impl_->uid = meta.c_str();
    else
        impl_->uid = x.getXferID();
    return VXL_OK;
}

const Item *Dataset::root() const { return as_item(impl_->ff.getDataset()); }

std::string Dataset::syntax() const { return impl_->uid; }

bool Dataset::has(const Item *it, Tag t) const { return it && as_dcmtk(it)->tagExists(key(t)); }

bool Dataset::string(const Item *it, Tag t, std::string &out) const
{
    OFString s;
    if (!it || as_dcmtk(it)->findAndGetOFString(key(t), s).bad()) return false;
    out = s.c_str();
    return true;
}

// dcmtk reads no Float64 from IS, nor a Sint32 from DS: each is tried.
bool Dataset::number(const Item *it, Tag t, unsigned long i, double &out) const
{
    if (!it) return false;
    DcmItem *ds = as_dcmtk(it);
    Sint32 iv;
    if (ds->findAndGetSint32(key(t), iv, i).good()) { out = iv; return true; }
    Uint32 uv;
    if (ds->findAndGetUint32(key(t), uv, i).good()) { out = uv; return true; }
    Float64 x;
    if (ds->findAndGetFloat64(key(t), x, i).bad() || !std::isfinite(x)) return false;
    out = x;
    return true;
}

bool Dataset::us(const Item *it, Tag t, unsigned long i, unsigned &out) const
{
    Uint16 v;
    if (!it || as_dcmtk(it)->findAndGetUint16(key(t), v, i).bad()) return false;
    out = v;
    return true;
}

bool Dataset::ss(const Item *it, Tag t, unsigned long i, int &out) const
{
    Sint16 v;
    if (!it || as_dcmtk(it)->findAndGetSint16(key(t), v, i).bad()) return false;
    out = v;
    return true;
}

size_t Dataset::items(const Item *it, Tag seq) const
{
    DcmSequenceOfItems *s = nullptr;
    if (!it || as_dcmtk(it)->findAndGetSequence(key(seq), s).bad() || !s) return 0;
    return s->card();
}

const Item *Dataset::item(const Item *it, Tag seq, size_t i) const
{
    DcmItem *out = nullptr;
    if (!it || as_dcmtk(it)->findAndGetSequenceItem(key(seq), out, long(i)).bad()) return nullptr;
    return as_item(out);
}

bool Dataset::words(const Item *it, Tag t, std::vector<uint16_t> &out) const
{
    DcmElement *el = nullptr;
    Uint16 *w = nullptr;
    if (!it || as_dcmtk(it)->findAndGetElement(key(t), el).bad() || !el || el->getUint16Array(w).bad() || !w)
        return false;
    out.assign(w, w + el->getLength() / 2);
    return true;
}

size_t Dataset::pixel_length() const
{
    DcmElement *el = nullptr;
    if (impl_->ff.getDataset()->findAndGetElement(DCM_PixelData, el).bad() || !el) return 0;
    return el->getLength();
}

int Dataset::pixels(unsigned bits_alloc, const uint8_t *&data, size_t &len, vxl_err *e)
{
    const char *p = impl_->path.c_str();
    DcmElement *el = nullptr;
    if (impl_->ff.getDataset()->findAndGetElement(DCM_PixelData, el).bad() || !el)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': no PixelData", p);
    len = el->getLength();
    OFCondition c;
    if (bits_alloc == 8) {
        Uint8 *b = nullptr;
        c = el->getUint8Array(b);
        data = b;
    } else {
        // dcmtk holds an OW element as 16-bit words already in native
        // order, so on a little-endian host a big-endian file's 32-bit
        // values have their two halves swapped: swapped back in place
        Uint16 *w = nullptr;
        c = el->getUint16Array(w);
        data = reinterpret_cast<const uint8_t *>(w);
        if (c.good() && w && bits_alloc == 32 && impl_->xs == EXS_BigEndianExplicit &&
            gLocalByteOrder == EBO_LittleEndian)
            for (size_t i = 0; i + 1 < len / 2; i += 2) std::swap(w[i], w[i + 1]);
    }
    if (c.bad() || !data) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read PixelData: %s", p, c.text());
    return VXL_OK;
}

int Dataset::fragments(Fragments &fr, vxl_err *e)
{
    const char *p = impl_->path.c_str();
    DcmElement *el = nullptr;
    if (impl_->ff.getDataset()->findAndGetElement(DCM_PixelData, el).bad() || !el)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': no PixelData", p);
    DcmPixelSequence *seq = nullptr;
    // the fragments are kept under the syntax the data set was read with:
    // for one dcmtk does not know (HTJ2K on 3.6.7), not the file's UID
    E_TransferSyntax held = impl_->xs;
    const DcmRepresentationParameter *param = nullptr;
    if (el->ident() == EVR_PixelData && DcmXfer(impl_->uid.c_str()).getXfer() == EXS_Unknown)
        static_cast<DcmPixelData *>(el)->getOriginalRepresentationKey(held, param);
    if (el->ident() != EVR_PixelData ||
        static_cast<DcmPixelData *>(el)->getEncapsulatedRepresentation(held, param, seq).bad() || !seq ||
        seq->card() < 1)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': compressed PixelData holds no fragments", p);
    uint64_t at = 0;
    for (unsigned long i = 0; i < seq->card(); i++) {
        DcmPixelItem *item = nullptr;
        Uint8 *b = nullptr;
        if (seq->getItem(item, i).bad() || !item || (item->getLength() && (item->getUint8Array(b).bad() || !b)))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read compressed item %lu", p, i);
        const size_t len = item->getLength();
        if (i == 0) {
            if (len % 4) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': basic offset table of %zu bytes", p, len);
            for (size_t k = 0; k < len; k += 4)
                fr.bot.push_back(uint32_t(b[k]) | uint32_t(b[k + 1]) << 8 | uint32_t(b[k + 2]) << 16 |
                                 uint32_t(b[k + 3]) << 24);
            continue;
        }
        fr.items.emplace_back(b, len);
        fr.at.push_back(at);
        at += 8 + len; // item tag and length, then the value
    }
    if (fr.items.empty()) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': compressed PixelData holds no fragments", p);
    return VXL_OK;
}

bool Dataset::has_codec(const std::string &uid, unsigned samples)
{
    // our lossless JPEG decoder is grey only; dcmjpeg takes colour
    if (uid == syntax::JpegLossless14 || uid == syntax::JpegLosslessSV1) return samples != 1;
    return uid == syntax::JpegBaseline || uid == syntax::JpegExtended || uid == syntax::JpegLsLossless ||
           uid == syntax::JpegLsNearLossless;
}

int Dataset::decode_frame(unsigned f, uint32_t &start_fragment, void *dst, size_t room, std::string &model,
                          vxl_err *e)
{
    const char *p = impl_->path.c_str();
    DcmDataset *ds = impl_->ff.getDataset();
    DcmElement *el = nullptr;
    if (ds->findAndGetElement(DCM_PixelData, el).bad() || !el || el->ident() != EVR_PixelData)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': no PixelData", p);
    OFString m;
    Uint32 start = start_fragment;
    OFCondition c = static_cast<DcmPixelData *>(el)->getUncompressedFrame(ds, f, start, dst, Uint32(room), m);
    start_fragment = start;
    if (c.bad())
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': frame %u: %s decoder: %s", p, f + 1, syntax_name(impl_->uid).c_str(),
                        c.text());
    model = m.c_str();
    return VXL_OK;
}

} // namespace vxl_dicom
