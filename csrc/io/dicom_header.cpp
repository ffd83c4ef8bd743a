// dicom_header.cpp - one DICOM file's header as the images it holds: a
// single-frame image, each frame of a classic multi-frame image, or each
// frame of an enhanced image (per-frame and shared functional groups, PS3.3
// C.7.6.16). The header is parsed through the data set seam
// (dicom_dataset.hpp) with element values over 4 KiB left on disk, so a
// folder scan never reads pixels; functional group sequences are always
// parsed.
#include "dicom_series.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

extern "C" {
#include "files.h"
}

namespace vxl_dicom {

namespace {

constexpr long kMaxFrames = 1L << 20;      // more frames than this is a damaged header

// "DICM" at byte 128: a Part 10 file.
bool has_dicm_magic(const std::string &path)
{
    const int fd = vxl_file_open_read(path.c_str(), 0);
    if (fd < 0) return false;
    unsigned char b[132];
    bool ok = vxl_file_pread(fd, b, sizeof b, 0) == int64_t(sizeof b) && memcmp(b + 128, "DICM", 4) == 0;
    vxl_file_close(fd);
    return ok;
}

std::string get_string(const Dataset &ds, const Item *it, Tag t)
{
    std::string s;
    return ds.string(it, t, s) ? s : "";
}

// n values of a numeric element; false if absent or any is not finite.
bool get_doubles(const Dataset &ds, const Item *it, Tag t, double *v, int n)
{
    if (!it) return false;
    for (int i = 0; i < n; i++)
        if (!ds.number(it, t, (unsigned long)i, v[i])) return false;
    return true;
}

unsigned get_us(const Dataset &ds, const Item *it, Tag t, unsigned dflt)
{
    unsigned v;
    return ds.us(it, t, 0, v) ? v : dflt;
}

bool get_number(const Dataset &ds, const Item *it, Tag t, double &v) { return get_doubles(ds, it, t, &v, 1); }

// The item of a functional group macro for one frame: the frame's own
// (per-frame group) first, else the shared group's (PS3.3 C.7.6.16).
const Item *macro(const Dataset &ds, const Item *per_frame, const Item *shared, Tag seq)
{
    if (const Item *it = per_frame ? ds.item(per_frame, seq, 0) : nullptr) return it;
    return shared ? ds.item(shared, seq, 0) : nullptr;
}

// Geometry and values a frame's functional groups give; what they do not
// give keeps the file-level value already in im.
void apply_groups(const Dataset &ds, const Item *per_frame, const Item *shared, Image &im)
{
    using namespace tags;
    double v[6];
    if (get_doubles(ds, macro(ds, per_frame, shared, PlanePositionSequence), ImagePositionPatient, v, 3)) {
        std::copy(v, v + 3, im.ipp);
        im.has_ipp = true;
    }
    if (get_doubles(ds, macro(ds, per_frame, shared, PlaneOrientationSequence), ImageOrientationPatient, v, 6)) {
        std::copy(v, v + 6, im.iop);
        im.has_iop = true;
    }
    if (const Item *pm = macro(ds, per_frame, shared, PixelMeasuresSequence)) {
        if (get_doubles(ds, pm, PixelSpacing, v, 2)) { im.ps[0] = v[0]; im.ps[1] = v[1]; im.has_spacing = true; }
        if (get_doubles(ds, pm, SliceThickness, v, 1)) im.thickness = v[0];
        if (get_doubles(ds, pm, SpacingBetweenSlices, v, 1)) im.between = v[0];
    }
    if (const Item *pv = macro(ds, per_frame, shared, PixelValueTransformationSequence)) {
        if (get_doubles(ds, pv, RescaleSlope, v, 1)) im.slope = v[0];
        if (get_doubles(ds, pv, RescaleIntercept, v, 1)) im.inter = v[0];
    }
    if (const Item *fc = macro(ds, per_frame, nullptr, FrameContentSequence)) {
        double t;
        if (get_number(ds, fc, TemporalPositionIndex, t)) im.tkey = t;
        else im.tkey = im.frame; // frames at one position without a temporal index: file order
        im.stack = get_string(ds, fc, StackID);
    }
}

// A classic multi-frame image (no functional groups) describes one plane;
// its frames are stacked along the normal: at GridFrameOffsetVector's
// offsets (RT dose) when the file has them, else every SpacingBetweenSlices,
// SliceThickness or, failing both, 1 mm. Without a position the stack starts
// at the origin with axial orientation.
void stack_classic_frames(const Dataset &ds, std::vector<Image> &out)
{
    Image &f = out[0];
    const size_t n = out.size();
    std::vector<double> offsets(n);
    bool grid = get_doubles(ds, ds.root(), tags::GridFrameOffsetVector, offsets.data(), int(n));
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
    using namespace tags;
    out.clear();
    Dataset ds;
    vxl_err err = {};
    if (ds.open(path, &err)) {
        why = err.msg;
        return has_dicm_magic(path) ? Parse::bad : Parse::not_dicom;
    }
    const Item *root = ds.root();
    Image s;
    s.path = path;
    s.uid = get_string(ds, root, SeriesInstanceUID);
    s.rows = get_us(ds, root, Rows, 0);
    s.cols = get_us(ds, root, Columns, 0);
    if (s.uid.empty() || !s.rows || !s.cols) {
        why = format("'%s': no DICOM image (SeriesInstanceUID, Rows and Columns are required)", path.c_str());
        return has_dicm_magic(path) ? Parse::bad : Parse::not_dicom;
    }
    s.modality = get_string(ds, root, Modality);
    s.description = get_string(ds, root, SeriesDescription);
    s.photometric = get_string(ds, root, PhotometricInterpretation);
    s.bits_alloc = get_us(ds, root, BitsAllocated, 0);
    s.bits_stored = get_us(ds, root, BitsStored, s.bits_alloc);
    s.pixel_rep = get_us(ds, root, PixelRepresentation, 0);
    s.samples = get_us(ds, root, SamplesPerPixel, 1);
    s.planar = get_us(ds, root, PlanarConfiguration, 0);
    double v[6];
    if (get_number(ds, root, NumberOfFrames, v[0])) {
        if (!(v[0] >= 1 && v[0] <= double(kMaxFrames))) {
            why = format("'%s': bad NumberOfFrames %g", path.c_str(), v[0]);
            return Parse::bad;
        }
        s.file_frames = long(v[0]);
    }
    s.has_ipp = get_doubles(ds, root, ImagePositionPatient, s.ipp, 3);
    s.has_iop = get_doubles(ds, root, ImageOrientationPatient, s.iop, 6);
    if (get_doubles(ds, root, PixelSpacing, v, 2)) { s.ps[0] = v[0]; s.ps[1] = v[1]; s.has_spacing = true; }
    if (get_doubles(ds, root, RescaleSlope, v, 1)) s.slope = v[0];
    if (get_doubles(ds, root, RescaleIntercept, v, 1)) s.inter = v[0];
    if (get_doubles(ds, root, SliceThickness, v, 1)) s.thickness = v[0];
    if (get_doubles(ds, root, SpacingBetweenSlices, v, 1)) s.between = v[0];
    get_number(ds, root, InstanceNumber, s.instance);
    // the first of these a file has orders its time points (4D series)
    const Tag time_tags[] = {TemporalPositionIdentifier, TriggerTime, AcquisitionNumber, InstanceNumber};
    for (Tag t : time_tags)
        if (get_number(ds, root, t, s.tkey)) break;
    s.syntax = ds.syntax();
    s.xfer = syntax_name(s.syntax);
    s.encapsulated = syntax_encapsulated(s.syntax);
    const Item *shared = ds.item(root, SharedFunctionalGroupsSequence, 0);
    const size_t per = ds.items(root, PerFrameFunctionalGroupsSequence);
    if (per != 0 && per != size_t(s.file_frames)) {
        why = format("'%s': %zu per-frame functional groups for NumberOfFrames %ld", path.c_str(), per,
                     s.file_frames);
        return Parse::bad;
    }
    out.assign(size_t(s.file_frames), s);
    for (size_t i = 0; i < out.size(); i++) out[i].frame = unsigned(i);
    if (shared || per) {
        for (size_t i = 0; i < out.size(); i++)
            apply_groups(ds, per ? ds.item(root, PerFrameFunctionalGroupsSequence, i) : nullptr, shared, out[i]);
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
