// dicom_header.cpp - one DICOM file's header as the images it holds: a
// single-frame image, each frame of a classic multi-frame image, or each
// frame of an enhanced image (per-frame and shared functional groups, PS3.3
// C.7.6.16). The header is parsed with element values over 4 KiB left on
// disk, so a folder scan never reads pixels; functional group sequences are
// always parsed.
#include "dicom_series.hpp"

#include <cmath>
#include <cstdio>

namespace vxl_dicom {

namespace {

constexpr long kMaxFrames = 1L << 20;      // more frames than this is a damaged header

// "DICM" at byte 128: a Part 10 file.
bool has_dicm_magic(const std::string &path)
{
    FILE *f = fopen(path.c_str(), "rb");
    if (!f) return false;
    unsigned char b[132];
    bool ok = fread(b, 1, sizeof b, f) == sizeof b && memcmp(b + 128, "DICM", 4) == 0;
    fclose(f);
    return ok;
}

std::string get_string(DcmItem *ds, const DcmTagKey &tag)
{
    OFString s;
    if (ds && ds->findAndGetOFString(tag, s).good()) return std::string(s.c_str());
    return "";
}

// n values of a DS/FD element; false if absent or any is not finite.
bool get_doubles(DcmItem *ds, const DcmTagKey &tag, double *v, int n)
{
    if (!ds) return false;
    for (int i = 0; i < n; i++) {
        Float64 x;
        if (ds->findAndGetFloat64(tag, x, (unsigned long)i).bad() || !std::isfinite(x)) return false;
        v[i] = x;
    }
    return true;
}

unsigned get_us(DcmItem *ds, const DcmTagKey &tag, unsigned dflt)
{
    Uint16 v;
    return ds->findAndGetUint16(tag, v).good() ? v : dflt;
}

// An IS or DS element as a number (dcmtk reads no Float64 from IS).
bool get_number(DcmItem *ds, const DcmTagKey &tag, double &v)
{
    Sint32 iv;
    if (ds && ds->findAndGetSint32(tag, iv).good()) { v = iv; return true; }
    Uint32 uv;
    if (ds && ds->findAndGetUint32(tag, uv).good()) { v = uv; return true; }
    return get_doubles(ds, tag, &v, 1);
}

// The item of a functional group macro for one frame: the frame's own
// (per-frame group) first, else the shared group's (PS3.3 C.7.6.16).
DcmItem *macro(DcmItem *per_frame, DcmItem *shared, const DcmTagKey &seq)
{
    DcmItem *it = nullptr;
    if (per_frame && per_frame->findAndGetSequenceItem(seq, it, 0).good() && it) return it;
    it = nullptr;
    if (shared && shared->findAndGetSequenceItem(seq, it, 0).good() && it) return it;
    return nullptr;
}

// Geometry and values a frame's functional groups give; what they do not
// give keeps the file-level value already in im.
void apply_groups(DcmItem *per_frame, DcmItem *shared, Image &im)
{
    double v[6];
    if (get_doubles(macro(per_frame, shared, DCM_PlanePositionSequence), DCM_ImagePositionPatient, v, 3)) {
        std::copy(v, v + 3, im.ipp);
        im.has_ipp = true;
    }
    if (get_doubles(macro(per_frame, shared, DCM_PlaneOrientationSequence), DCM_ImageOrientationPatient, v, 6)) {
        std::copy(v, v + 6, im.iop);
        im.has_iop = true;
    }
    if (DcmItem *pm = macro(per_frame, shared, DCM_PixelMeasuresSequence)) {
        if (get_doubles(pm, DCM_PixelSpacing, v, 2)) { im.ps[0] = v[0]; im.ps[1] = v[1]; im.has_spacing = true; }
        if (get_doubles(pm, DCM_SliceThickness, v, 1)) im.thickness = v[0];
        if (get_doubles(pm, DCM_SpacingBetweenSlices, v, 1)) im.between = v[0];
    }
    if (DcmItem *pv = macro(per_frame, shared, DCM_PixelValueTransformationSequence)) {
        if (get_doubles(pv, DCM_RescaleSlope, v, 1)) im.slope = v[0];
        if (get_doubles(pv, DCM_RescaleIntercept, v, 1)) im.inter = v[0];
    }
    if (DcmItem *fc = macro(per_frame, nullptr, DCM_FrameContentSequence)) {
        double t;
        if (get_number(fc, DCM_TemporalPositionIndex, t)) im.tkey = t;
        else im.tkey = im.frame; // frames at one position without a temporal index: file order
        im.stack = get_string(fc, DCM_StackID);
    }
}

// A classic multi-frame image (no functional groups) describes one plane;
// its frames are stacked along the normal: at GridFrameOffsetVector's
// offsets (RT dose) when the file has them, else every SpacingBetweenSlices,
// SliceThickness or, failing both, 1 mm. Without a position the stack starts
// at the origin with axial orientation.
void stack_classic_frames(DcmDataset *ds, std::vector<Image> &out)
{
    Image &f = out[0];
    const size_t n = out.size();
    std::vector<double> offsets(n);
    bool grid = get_doubles(ds, DCM_GridFrameOffsetVector, offsets.data(), int(n));
    double step = f.between > 0 ? f.between : f.thickness > 0 ? f.thickness : 1;
    std::string how = grid ? "" : f.between > 0 ? "SpacingBetweenSlices" : f.thickness > 0 ? "SliceThickness" : "";
    double normal[3];
    cross(f.iop, f.iop + 3, normal);
    // a first offset other than 0 makes the offsets z coordinates (PS3.3 C.8.8.3.2)
    const bool absolute = grid && offsets[0] != 0;
    for (size_t i = 0; i < n; i++) {
        Image &im = out[i];
        double d = grid ? offsets[i] : double(i) * step;
        for (int a = 0; a < 3; a++) im.ipp[a] = f.ipp[a] + d * normal[a];
        if (absolute) { im.ipp[0] = f.ipp[0]; im.ipp[1] = f.ipp[1]; im.ipp[2] = offsets[i]; }
        im.has_ipp = im.has_iop = true;
        im.tkey = 0;
        if (grid) continue;
        if (!f.has_ipp || !f.has_iop)
            im.geometry = format("no position or orientation: %ld frames stacked axially every %.4g mm%s%s",
                                 f.file_frames, step, how.empty() ? " (assumed)" : " (", how.empty() ? "" :
                                 (how + ")").c_str());
        else
            im.geometry = format("%ld frames stacked along the normal every %.4g mm%s%s", f.file_frames, step,
                                 how.empty() ? " (assumed: no SpacingBetweenSlices or SliceThickness)" : " (",
                                 how.empty() ? "" : (how + ")").c_str());
    }
}

} // namespace

Parse read_header(const std::string &path, std::vector<Image> &out, std::string &why)
{
    out.clear();
    DcmFileFormat ff;
    OFCondition c = ff.loadFile(path.c_str(), EXS_Unknown, EGL_noChange, kHeaderReadLength, ERM_autoDetect);
    if (c.bad()) {
        why = format("'%s': not a readable DICOM file: %s", path.c_str(), c.text());
        return has_dicm_magic(path) ? Parse::bad : Parse::not_dicom;
    }
    DcmDataset *ds = ff.getDataset();
    Image s;
    s.path = path;
    s.uid = get_string(ds, DCM_SeriesInstanceUID);
    s.rows = get_us(ds, DCM_Rows, 0);
    s.cols = get_us(ds, DCM_Columns, 0);
    if (s.uid.empty() || !s.rows || !s.cols) {
        why = format("'%s': no DICOM image (SeriesInstanceUID, Rows and Columns are required)", path.c_str());
        return has_dicm_magic(path) ? Parse::bad : Parse::not_dicom;
    }
    s.modality = get_string(ds, DCM_Modality);
    s.description = get_string(ds, DCM_SeriesDescription);
    s.photometric = get_string(ds, DCM_PhotometricInterpretation);
    s.bits_alloc = get_us(ds, DCM_BitsAllocated, 0);
    s.bits_stored = get_us(ds, DCM_BitsStored, s.bits_alloc);
    s.pixel_rep = get_us(ds, DCM_PixelRepresentation, 0);
    s.samples = get_us(ds, DCM_SamplesPerPixel, 1);
    s.planar = get_us(ds, DCM_PlanarConfiguration, 0);
    double v[6];
    if (get_number(ds, DCM_NumberOfFrames, v[0])) {
        if (!(v[0] >= 1 && v[0] <= double(kMaxFrames))) {
            why = format("'%s': bad NumberOfFrames %g", path.c_str(), v[0]);
            return Parse::bad;
        }
        s.file_frames = long(v[0]);
    }
    s.has_ipp = get_doubles(ds, DCM_ImagePositionPatient, s.ipp, 3);
    s.has_iop = get_doubles(ds, DCM_ImageOrientationPatient, s.iop, 6);
    if (get_doubles(ds, DCM_PixelSpacing, v, 2)) { s.ps[0] = v[0]; s.ps[1] = v[1]; s.has_spacing = true; }
    if (get_doubles(ds, DCM_RescaleSlope, v, 1)) s.slope = v[0];
    if (get_doubles(ds, DCM_RescaleIntercept, v, 1)) s.inter = v[0];
    if (get_doubles(ds, DCM_SliceThickness, v, 1)) s.thickness = v[0];
    if (get_doubles(ds, DCM_SpacingBetweenSlices, v, 1)) s.between = v[0];
    get_number(ds, DCM_InstanceNumber, s.instance);
    // the first of these a file has orders its time points (4D series)
    const DcmTagKey time_tags[] = {DCM_TemporalPositionIdentifier, DCM_TriggerTime, DCM_AcquisitionNumber,
                                   DCM_InstanceNumber};
    for (const DcmTagKey &t : time_tags)
        if (get_number(ds, t, s.tkey)) break;
    DcmXfer x(ds->getOriginalXfer());
    s.xfer = x.getXferName();
    s.xs = x.getXfer();
#if PACKAGE_VERSION_NUMBER >= 369 // dcmtk 3.6.9 (Debian 13) deprecates isEncapsulated()
    s.encapsulated = x.usesEncapsulatedFormat();
#else
    s.encapsulated = x.isEncapsulated();
#endif
    // HTJ2K's frames are JPEG 2000 codestreams with the HT block coder,
    // which OpenJPEG 2.5 decodes: known by the meta header's UID, since
    // dcmtk 3.6.7 (Debian 12) does not know these syntaxes (it still reads
    // the data set, explicit little endian, and the encapsulated PixelData)
    const std::string uid = get_string(ff.getMetaInfo(), DCM_TransferSyntaxUID);
    if (uid == "1.2.840.10008.1.2.4.201" || uid == "1.2.840.10008.1.2.4.202" || uid == "1.2.840.10008.1.2.4.203") {
        s.htj2k = s.encapsulated = true;
        s.xfer = uid == "1.2.840.10008.1.2.4.201" ? "HTJ2K Lossless" : uid == "1.2.840.10008.1.2.4.202"
                                                                      ? "HTJ2K with RPCL Options Lossless"
                                                                      : "HTJ2K";
    }
    DcmItem *shared = nullptr;
    if (ds->findAndGetSequenceItem(DCM_SharedFunctionalGroupsSequence, shared, 0).bad()) shared = nullptr;
    DcmSequenceOfItems *per = nullptr;
    if (ds->findAndGetSequence(DCM_PerFrameFunctionalGroupsSequence, per).bad()) per = nullptr;
    if (per && per->card() != 0 && per->card() != static_cast<unsigned long>(s.file_frames)) {
        why = format("'%s': %lu per-frame functional groups for NumberOfFrames %ld", path.c_str(), per->card(),
                     s.file_frames);
        return Parse::bad;
    }
    out.assign(size_t(s.file_frames), s);
    for (size_t i = 0; i < out.size(); i++) out[i].frame = unsigned(i);
    if (shared || (per && per->card())) {
        for (size_t i = 0; i < out.size(); i++) apply_groups(per ? per->getItem(static_cast<unsigned long>(i)) : nullptr,
                                                              shared, out[i]);
        // several stacks in one file (orthogonal stacks of one enhanced MR)
        // are several volumes: each becomes its own series; one stack is the
        // file's series as it is
        bool several = false;
        for (const Image &im : out) several = several || im.stack != out[0].stack;
        for (Image &im : out) {
            if (!several) im.stack.clear();
            else if (im.description.empty()) im.description = "stack " + im.stack;
            else im.description += " (stack " + im.stack + ")";
        }
    } else if (s.file_frames > 1) {
        stack_classic_frames(ds, out);
    }
    return Parse::ok;
}

} // namespace vxl_dicom
