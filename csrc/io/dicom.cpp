// dicom.cpp - DICOM series through dcmtk (dcmdata): a folder of slices, a
// DICOMDIR (its folder, searched recursively) or one file of a series (the
// series of that file, from its folder), as one volume.
//
// Flow: every file's header is parsed with element values over 4 KiB left on
// disk (so a folder scan never reads pixels) -> files are grouped by
// SeriesInstanceUID -> the chosen series is checked and sorted (analyse():
// one pixel format and size, one orientation, slices ordered by
// ImagePositionPatient projected on the slice normal, even spacing) -> the
// limits are checked against the memory budget -> pixels are read slice by
// slice -> vxl_volume_build applies RescaleSlope/Intercept (CT lands in
// Hounsfield units); slices with differing rescale values are converted to
// float first.
//
// Geometry: DICOM's patient frame is LPS; ours (NIfTI's) is RAS, so x and y
// of every column and of the origin are negated. Voxel (i, j, k) is column i,
// row j of slice k in sorted order: column axis = ImageOrientationPatient[0..2]
// * PixelSpacing[1], row axis = IOP[3..5] * PixelSpacing[0], slice axis =
// (last position - first position) / (n - 1), origin = the first position.
// The slice spacing therefore comes from the positions, never from
// SliceThickness. With gantry tilt the slice axis is not along the normal:
// the affine is sheared, which is the true geometry (vxl_dicom_series
// reports the angle). Uneven steps (a missing slice) cannot be expressed by
// one affine and are refused, naming the gap.
//
// 4D: when every position holds the same number of files with distinct time
// keys, they are time points (group_time_points); vxl_load_options.frame
// picks one.
//
// Only the helper process voxlight-read-dicom runs this (helper_dicom.c,
// reader_stream.h): libvoxlight.so links no C++. Whether a path is DICOM
// at all is decided in the library, in C (dicom_detect.c).
//
// Transfer syntaxes: the uncompressed ones (dcmtk), RLE Lossless and JPEG
// Lossless (our own C, dicom_rle.c, dicom_jpeg_lossless.c). Not decoded:
// the other compressed (encapsulated) transfer syntaxes, multi-frame
// images, colour, BitsAllocated other than 8/16. Each is a clear error
// naming the file.
#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcpxitem.h>
#include <dcmtk/dcmdata/dctk.h>
#include <dcmtk/oflog/oflog.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstring>
#include <dirent.h>
#include <map>
#include <mutex>
#include <string>
#include <strings.h>
#include <type_traits>
#include <sys/stat.h>
#include <vector>

extern "C" {
#include "dicom_jpeg_lossless.h"
#include "dicom_rle.h"
#include "helper_main.h"
#include "loader_util.h"
}

namespace {

constexpr Uint32 kHeaderReadLength = 4096; // larger element values stay on disk
constexpr size_t kMaxFiles = 100000;        // a folder scan stops with an error past this
constexpr int kMaxDepth = 8;                // DICOMDIR trees are a few levels deep

struct Slice {
    std::string path, uid, modality, description;
    unsigned rows = 0, cols = 0, bits_alloc = 0, bits_stored = 0, pixel_rep = 0, samples = 1;
    long frames = 1;
    bool has_ipp = false, has_iop = false, encapsulated = false;
    // Compressed pixels our own C decodes (the rest are refused by name)
    enum class Codec { none, rle, jpeg_lossless } codec = Codec::none;
    E_TransferSyntax xs = EXS_Unknown;
    double ipp[3] = {0, 0, 0}, iop[6] = {1, 0, 0, 0, 1, 0}, ps[2] = {1, 1};
    double slope = 1, inter = 0, thickness = 0;
    std::string xfer;
    double dist = 0; // position along the slice normal
    double tkey = 0; // time order: TemporalPositionIdentifier, TriggerTime, AcquisitionNumber or InstanceNumber
};

struct Series {
    std::vector<Slice> slices; // sorted by position, then time: volume t is slices[k * frames + t]
    size_t frames = 1;         // time points (4D: several files at every position)
    double tilt_deg = 0;
    double affine[16];
    double spacing[3];
    std::string problem; // empty when loadable
};

// dcmtk logs warnings to stderr by default; a library must never print.
void quiet_dcmtk()
{
    static std::once_flag once;
    std::call_once(once, [] { OFLog::configure(OFLogger::OFF_LOG_LEVEL); });
}

std::string format(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char *fmt, ...)
{
    char buf[VXL_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    return buf;
}

std::string basename_of(const std::string &p)
{
    size_t s = p.rfind('/');
    return s == std::string::npos ? p : p.substr(s + 1);
}

std::string dirname_of(const std::string &p)
{
    size_t s = p.rfind('/');
    if (s == std::string::npos) return ".";
    return s == 0 ? "/" : p.substr(0, s);
}

bool is_dicomdir_name(const std::string &p) { return strcasecmp(basename_of(p).c_str(), "DICOMDIR") == 0; }

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

// Regular files under dir (recursively to kMaxDepth when recurse), skipping
// dot files and DICOMDIR itself, in name order. false when over kMaxFiles.
bool list_files(const std::string &dir, bool recurse, int depth, std::vector<std::string> &out)
{
    DIR *d = opendir(dir.c_str());
    if (!d) return true;
    std::vector<std::string> names;
    while (struct dirent *ent = readdir(d)) {
        if (ent->d_name[0] == '.') continue;
        names.emplace_back(ent->d_name);
    }
    closedir(d);
    std::sort(names.begin(), names.end());
    for (const auto &n : names) {
        std::string p = dir + "/" + n;
        struct stat st;
        if (stat(p.c_str(), &st) != 0) continue;
        if (S_ISDIR(st.st_mode)) {
            if (recurse && depth < kMaxDepth && !list_files(p, recurse, depth + 1, out)) return false;
        } else if (S_ISREG(st.st_mode) && !is_dicomdir_name(n)) {
            if (out.size() >= kMaxFiles) return false;
            out.push_back(p);
        }
    }
    return true;
}

std::string get_string(DcmDataset *ds, const DcmTagKey &tag)
{
    OFString s;
    if (ds->findAndGetOFString(tag, s).good()) return std::string(s.c_str());
    return "";
}

// n values of a DS element; false if absent or any is not finite.
bool get_doubles(DcmDataset *ds, const DcmTagKey &tag, double *v, int n)
{
    for (int i = 0; i < n; i++) {
        Float64 x;
        if (ds->findAndGetFloat64(tag, x, (unsigned long)i).bad() || !std::isfinite(x)) return false;
        v[i] = x;
    }
    return true;
}

unsigned get_us(DcmDataset *ds, const DcmTagKey &tag, unsigned dflt)
{
    Uint16 v;
    return ds->findAndGetUint16(tag, v).good() ? v : dflt;
}

enum class Parse { ok, not_dicom, bad };

// Reads one file's header. not_dicom: no SeriesInstanceUID/Rows/Columns (a
// README in the folder, say); bad: a file that claims to be DICOM but cannot
// be parsed, which is an error rather than a silently missing slice.
Parse read_slice(const std::string &path, Slice &s, std::string &why)
{
    DcmFileFormat ff;
    OFCondition c = ff.loadFile(path.c_str(), EXS_Unknown, EGL_noChange, kHeaderReadLength, ERM_autoDetect);
    if (c.bad()) {
        why = format("'%s': not a readable DICOM file: %s", path.c_str(), c.text());
        return has_dicm_magic(path) ? Parse::bad : Parse::not_dicom;
    }
    DcmDataset *ds = ff.getDataset();
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
    s.bits_alloc = get_us(ds, DCM_BitsAllocated, 0);
    s.bits_stored = get_us(ds, DCM_BitsStored, s.bits_alloc);
    s.pixel_rep = get_us(ds, DCM_PixelRepresentation, 0);
    s.samples = get_us(ds, DCM_SamplesPerPixel, 1);
    Sint32 frames;
    if (ds->findAndGetSint32(DCM_NumberOfFrames, frames).good()) s.frames = frames;
    s.has_ipp = get_doubles(ds, DCM_ImagePositionPatient, s.ipp, 3);
    s.has_iop = get_doubles(ds, DCM_ImageOrientationPatient, s.iop, 6);
    double ps[2];
    if (get_doubles(ds, DCM_PixelSpacing, ps, 2)) { s.ps[0] = ps[0]; s.ps[1] = ps[1]; }
    double v;
    if (get_doubles(ds, DCM_RescaleSlope, &v, 1)) s.slope = v;
    if (get_doubles(ds, DCM_RescaleIntercept, &v, 1)) s.inter = v;
    if (get_doubles(ds, DCM_SliceThickness, &v, 1)) s.thickness = v;
    // the first of these a file has orders its time points (4D series)
    const DcmTagKey time_tags[] = {DCM_TemporalPositionIdentifier, DCM_TriggerTime, DCM_AcquisitionNumber,
                                   DCM_InstanceNumber};
    for (const DcmTagKey &t : time_tags) {
        Sint32 iv; // IS elements (dcmtk reads no Float64 from them); TriggerTime is DS
        if (ds->findAndGetSint32(t, iv).good()) { s.tkey = iv; break; }
        if (get_doubles(ds, t, &v, 1)) { s.tkey = v; break; }
    }
    DcmXfer x(ds->getOriginalXfer());
    s.xfer = x.getXferName();
    s.xs = x.getXfer();
    if (s.xs == EXS_RLELossless) s.codec = Slice::Codec::rle;
    if (s.xs == EXS_JPEGProcess14 || s.xs == EXS_JPEGProcess14SV1) s.codec = Slice::Codec::jpeg_lossless;
#if PACKAGE_VERSION_NUMBER >= 369 // dcmtk 3.6.9 (Debian 13) deprecates isEncapsulated()
    s.encapsulated = x.usesEncapsulatedFormat();
#else
    s.encapsulated = x.isEncapsulated();
#endif
    return Parse::ok;
}

void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// What every slice must share with the first, or the reason it does not.
std::string check_pixels(const std::vector<Slice> &sl)
{
    const Slice &f = sl[0];
    for (const Slice &s : sl) {
        const char *p = s.path.c_str();
        if (s.encapsulated && s.codec == Slice::Codec::none)
            return format("'%s': compressed transfer syntax '%s' is not supported (decompress first, e.g. "
                          "dcmdjpeg or gdcmconv --raw)", p, s.xfer.c_str());
        if (s.frames != 1)
            return format("'%s': multi-frame image (NumberOfFrames %ld) is not supported", p, s.frames);
        if (s.samples != 1)
            return format("'%s': %u samples per pixel (colour) is not supported; greyscale only", p, s.samples);
        if (s.bits_alloc != 8 && s.bits_alloc != 16)
            return format("'%s': BitsAllocated %u is not supported (8 or 16)", p, s.bits_alloc);
        if (s.bits_stored < 1 || s.bits_stored > s.bits_alloc)
            return format("'%s': BitsStored %u does not fit BitsAllocated %u", p, s.bits_stored, s.bits_alloc);
        if (s.pixel_rep > 1) return format("'%s': bad PixelRepresentation %u", p, s.pixel_rep);
        if (s.rows != f.rows || s.cols != f.cols)
            return format("mixed image sizes in the series: %ux%u ('%s') and %ux%u ('%s')", f.cols, f.rows,
                          f.path.c_str(), s.cols, s.rows, p);
        if (s.bits_alloc != f.bits_alloc || s.pixel_rep != f.pixel_rep || s.bits_stored != f.bits_stored)
            return format("mixed pixel types in the series: '%s' and '%s'", f.path.c_str(), p);
        if (!(s.ps[0] > 0) || !(s.ps[1] > 0))
            return format("'%s': bad PixelSpacing %g\\%g", p, s.ps[0], s.ps[1]);
        if (std::fabs(s.ps[0] - f.ps[0]) > 1e-4 * f.ps[0] || std::fabs(s.ps[1] - f.ps[1]) > 1e-4 * f.ps[1])
            return format("mixed PixelSpacing in the series: %g\\%g ('%s') and %g\\%g ('%s')", f.ps[0], f.ps[1],
                          f.path.c_str(), s.ps[0], s.ps[1], p);
        if (s.slope == 0) return format("'%s': RescaleSlope is 0", p);
    }
    return "";
}

// Several files at one position are time points of a 4D series (cardiac
// phases, perfusion) when every position has the same number of them with
// distinct time keys: each position's files are sorted by time and
// s.frames set. Files closer than kSamePosition count as one position.
constexpr double kSamePosition = 0.01; // mm
bool group_time_points(Series &s)
{
    std::vector<Slice> &sl = s.slices;
    std::vector<size_t> starts;
    for (size_t i = 0; i < sl.size(); i++)
        if (starts.empty() || sl[i].dist - sl[starts.back()].dist > kSamePosition) starts.push_back(i);
    starts.push_back(sl.size());
    const size_t t = starts[1] - starts[0];
    for (size_t g = 0; g + 1 < starts.size(); g++) {
        size_t b = starts[g], e = starts[g + 1];
        if (e - b != t) {
            s.problem = format("%zu file(s) at the position of '%s' but %zu at that of '%s' (%.4g mm along the "
                               "normal): a 4D series needs the same number of time points at every position "
                               "(missing or duplicate files?)", t, basename_of(sl[0].path).c_str(), e - b,
                               basename_of(sl[b].path).c_str(), sl[b].dist);
            return false;
        }
        std::stable_sort(sl.begin() + long(b), sl.begin() + long(e),
                         [](const Slice &x, const Slice &y) { return x.tkey < y.tkey; });
        for (size_t i = b + 1; i < e; i++)
            if (sl[i].tkey == sl[i - 1].tkey) {
                s.problem = format("'%s' and '%s' lie at the same position (%.4g mm along the normal) with the same "
                                   "time (%.6g): duplicates, not time points", sl[i - 1].path.c_str(),
                                   sl[i].path.c_str(), sl[i].dist, sl[i].tkey);
                return false;
            }
    }
    s.frames = t;
    return true;
}

// Sorts the slices along the normal and derives the geometry; sets
// s.problem when the series cannot become one volume.
void analyse(Series &s)
{
    std::vector<Slice> &sl = s.slices;
    s.problem = check_pixels(sl);
    if (!s.problem.empty()) return;
    // every file shares f's orientation and pixel spacing (checked below and
    // in check_pixels), so f stays valid for them after sorting
    const Slice &f = sl[0];
    const double *r = f.iop, *c = f.iop + 3;
    double n[3];
    cross(r, c, n);
    double rl = std::sqrt(dot(r, r)), cl = std::sqrt(dot(c, c)), nl = std::sqrt(dot(n, n));
    if (!(std::fabs(rl - 1) < 1e-3 && std::fabs(cl - 1) < 1e-3 && std::fabs(dot(r, c)) < 1e-3)) {
        s.problem = format("'%s': ImageOrientationPatient is not two orthogonal unit vectors", f.path.c_str());
        return;
    }
    for (double &x : n) x /= nl;
    for (Slice &t : sl) {
        if (sl.size() > 1 && (!t.has_ipp || !t.has_iop)) {
            s.problem = format("'%s': no ImagePositionPatient/ImageOrientationPatient, so the slices cannot be "
                               "ordered", t.path.c_str());
            return;
        }
        for (int a = 0; a < 6; a++)
            if (std::fabs(t.iop[a] - f.iop[a]) > 1e-4) {
                s.problem = format("slices of different orientations in one series: '%s' and '%s'",
                                   f.path.c_str(), t.path.c_str());
                return;
            }
        t.dist = dot(t.ipp, n);
    }
    std::stable_sort(sl.begin(), sl.end(), [](const Slice &a, const Slice &b) { return a.dist < b.dist; });
    if (!group_time_points(s)) return;
    // one file per position from here on: the first time point's
    std::vector<const Slice *> rep;
    for (size_t i = 0; i < sl.size(); i += s.frames) rep.push_back(&sl[i]);

    double w[3] = {n[0], n[1], n[2]}; // slice axis (LPS), per slice step
    size_t k = rep.size();
    if (k > 1) {
        std::vector<double> steps;
        for (size_t i = 1; i < k; i++) steps.push_back(rep[i]->dist - rep[i - 1]->dist);
        std::vector<double> sorted = steps;
        std::sort(sorted.begin(), sorted.end());
        double typical = sorted[sorted.size() / 2];
        double tol = 0.01 * std::fabs(typical) + 1e-4;
        for (size_t i = 0; i < steps.size(); i++)
            if (std::fabs(steps[i] - typical) > tol) {
                s.problem = format("uneven slice spacing (a missing slice?): %.4g mm between '%s' and '%s', the "
                                   "series' spacing is %.4g mm", steps[i], basename_of(rep[i]->path).c_str(),
                                   basename_of(rep[i + 1]->path).c_str(), typical);
                return;
            }
        for (int a = 0; a < 3; a++) w[a] = (rep[k - 1]->ipp[a] - rep[0]->ipp[a]) / double(k - 1);
        // every position must lie on the line first + i*w
        for (size_t i = 0; i < k; i++)
            for (int a = 0; a < 3; a++)
                if (std::fabs(rep[0]->ipp[a] + double(i) * w[a] - rep[i]->ipp[a]) > tol) {
                    s.problem = format("'%s': ImagePositionPatient is off the line through the other slices",
                                       rep[i]->path.c_str());
                    return;
                }
        double wl = std::sqrt(dot(w, w));
        double cosang = std::min(1.0, std::fabs(dot(w, n)) / wl);
        s.tilt_deg = std::acos(cosang) * 180.0 / M_PI;
        if (s.tilt_deg < 1e-3) s.tilt_deg = 0;
    } else if (f.thickness > 0) {
        for (double &x : w) x *= f.thickness;
    }
    double dir[3][3];
    for (int a = 0; a < 3; a++) {
        dir[0][a] = r[a] * f.ps[1]; // along a row: column index i, column spacing
        dir[1][a] = c[a] * f.ps[0]; // down a column: row index j, row spacing
        dir[2][a] = w[a];
    }
    const double *first = rep[0]->ipp; // after sorting: the lowest position along the normal
    double origin[3] = {first[0], first[1], first[2]};
    for (int col = 0; col < 3; col++) { dir[col][0] = -dir[col][0]; dir[col][1] = -dir[col][1]; } // LPS -> RAS
    origin[0] = -origin[0];
    origin[1] = -origin[1];
    if (!vxl_affine_from(dir, origin, s.affine)) {
        s.problem = format("'%s': the voxel-to-patient transform is degenerate", f.path.c_str());
        return;
    }
    for (int a = 0; a < 3; a++) s.spacing[a] = std::sqrt(dot(dir[a], dir[a]));
}

// The files a path stands for, and the series they hold (sorted by UID).
struct Scan {
    std::string origin;      // the file the caller named, if one
    std::vector<Series> series;
};

int scan(const std::string &path, Scan &out, vxl_err *e)
{
    quiet_dcmtk();
    struct stat st;
    if (stat(path.c_str(), &st) != 0) return vxl_fail(e, VXL_ERR_IO, "'%s': %s", path.c_str(), strerror(errno));
    std::vector<std::string> files;
    bool complete;
    std::string where = path;
    if (S_ISDIR(st.st_mode)) {
        complete = list_files(path, true, 0, files);
    } else if (is_dicomdir_name(path)) {
        where = dirname_of(path);
        complete = list_files(where, true, 0, files);
    } else {
        if (!S_ISREG(st.st_mode)) return vxl_fail(e, VXL_ERR_IO, "'%s' is not a regular file", path.c_str());
        out.origin = path;
        where = dirname_of(path);
        complete = list_files(where, false, 0, files);
        // the named file first, so its own errors are the ones reported
        files.erase(std::remove(files.begin(), files.end(), where + "/" + basename_of(path)), files.end());
        files.insert(files.begin(), path);
    }
    if (!complete)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': more than %zu files; name the series' own folder", where.c_str(),
                        kMaxFiles);
    std::map<std::string, Series> by_uid;
    for (const std::string &f : files) {
        Slice s;
        std::string why;
        Parse p = read_slice(f, s, why);
        if (p == Parse::bad || (p == Parse::not_dicom && f == out.origin))
            return vxl_fail(e, VXL_ERR_FORMAT, "%s", why.c_str());
        if (p == Parse::ok) by_uid[s.uid].slices.push_back(std::move(s));
    }
    if (by_uid.empty()) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': no DICOM images found", where.c_str());
    for (auto &kv : by_uid) {
        analyse(kv.second);
        out.series.push_back(std::move(kv.second));
    }
    return VXL_OK;
}

std::string series_line(size_t i, const Series &s)
{
    const Slice &f = s.slices[0];
    return format("%zu: %s (%s%s%s, %zu files)", i, f.uid.c_str(), f.modality.empty() ? "?" : f.modality.c_str(),
                  f.description.empty() ? "" : ", ", f.description.c_str(), s.slices.size());
}

// The series the options (or the named file) pick.
int choose(const Scan &sc, const std::string &path, const char *want, const Series **out, vxl_err *e)
{
    const auto &all = sc.series;
    if (want && *want) {
        for (const Series &s : all)
            if (s.slices[0].uid == want) { *out = &s; return VXL_OK; }
        char *end;
        unsigned long i = strtoul(want, &end, 10);
        if (!*end && std::isdigit((unsigned char)want[0]) && i < all.size()) { *out = &all[i]; return VXL_OK; }
        std::string list;
        for (size_t k = 0; k < all.size(); k++) list += "; " + series_line(k, all[k]);
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': no series '%s' (an index 0..%zu or a UID)%s",
                        path.c_str(), want, all.size() - 1, list.c_str());
    }
    if (!sc.origin.empty()) {
        for (const Series &s : all)
            for (const Slice &t : s.slices)
                if (t.path == sc.origin) { *out = &s; return VXL_OK; }
    }
    if (all.size() == 1) { *out = &all[0]; return VXL_OK; }
    std::string list;
    for (size_t k = 0; k < all.size(); k++) list += "; " + series_line(k, all[k]);
    return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s' holds %zu DICOM series: choose one (series option, CLI "
                    "--series N|UID)%s", path.c_str(), all.size(), list.c_str());
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

// A slice's n stored values at src (bits_alloc each, native byte order) into
// dst, masked to bits_stored and sign-extended where signed.
void unpack_slice(const Slice &s, const void *src, size_t n, void *dst)
{
    const bool sgn = s.pixel_rep == 1;
    if (s.bits_alloc == 8) {
        if (sgn) unpack(static_cast<const int8_t *>(src), n, s.bits_stored, true, static_cast<int8_t *>(dst));
        else unpack(static_cast<const uint8_t *>(src), n, s.bits_stored, false, static_cast<uint8_t *>(dst));
    } else {
        if (sgn) unpack(static_cast<const int16_t *>(src), n, s.bits_stored, true, static_cast<int16_t *>(dst));
        else unpack(static_cast<const uint16_t *>(src), n, s.bits_stored, false, static_cast<uint16_t *>(dst));
    }
}

// A compressed slice's one frame: its fragments (the items after the basic
// offset table) joined, then decoded by our own C (dicom_rle.c,
// dicom_jpeg_lossless.c) into out (rows*cols values of bits_alloc, native
// byte order).
int decode_frame(const Slice &s, DcmElement *el, std::vector<uint8_t> &out, vxl_err *e)
{
    const char *p = s.path.c_str();
    DcmPixelSequence *seq = nullptr;
    if (el->ident() != EVR_PixelData ||
        static_cast<DcmPixelData *>(el)->getEncapsulatedRepresentation(s.xs, nullptr, seq).bad() || !seq)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': compressed PixelData holds no fragments", p);
    std::vector<uint8_t> frame;
    for (unsigned long i = 1; i < seq->card(); i++) {
        DcmPixelItem *item = nullptr;
        Uint8 *b = nullptr;
        if (seq->getItem(item, i).bad() || !item || (item->getLength() && (item->getUint8Array(b).bad() || !b)))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read compressed fragment %lu", p, i);
        frame.insert(frame.end(), b, b + item->getLength());
    }
    out.resize(size_t(s.rows) * s.cols * (s.bits_alloc / 8));
    vxl_err codec = {};
    const int rc = s.codec == Slice::Codec::rle
        ? vxl_dicom_rle_decode(frame.data(), frame.size(), s.rows, s.cols, s.bits_alloc / 8, out.data(), &codec)
        : vxl_jpeg_lossless_decode(frame.data(), frame.size(), s.rows, s.cols, s.bits_alloc / 8, out.data(), &codec);
    return rc ? vxl_fail(e, rc, "'%s': %s", p, codec.msg) : VXL_OK;
}

// Reads one slice's pixels into dst (rows*cols values of bits_alloc).
int read_pixels(const Slice &s, void *dst, vxl_err *e)
{
    const char *p = s.path.c_str();
    DcmFileFormat ff;
    OFCondition c = ff.loadFile(p, EXS_Unknown, EGL_noChange, kHeaderReadLength, ERM_autoDetect);
    if (c.bad()) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read: %s", p, c.text());
    DcmElement *el = nullptr;
    if (ff.getDataset()->findAndGetElement(DCM_PixelData, el).bad() || !el)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': no PixelData", p);
    const size_t n = size_t(s.rows) * s.cols, bytes = n * (s.bits_alloc / 8);
    if (s.codec != Slice::Codec::none) {
        std::vector<uint8_t> raw;
        int rc = decode_frame(s, el, raw, e);
        if (rc) return rc;
        unpack_slice(s, raw.data(), n, dst);
        return VXL_OK;
    }
    if (el->getLength() < bytes)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': truncated PixelData: %zu bytes for %ux%u pixels of %u bits, got %lu",
                        p, bytes, s.cols, s.rows, s.bits_alloc, (unsigned long)el->getLength());
    const void *a = nullptr;
    if (s.bits_alloc == 8) {
        Uint8 *b = nullptr;
        c = el->getUint8Array(b);
        a = b;
    } else {
        Uint16 *b = nullptr;
        c = el->getUint16Array(b);
        a = b;
    }
    if (c.bad() || !a) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read PixelData: %s", p, c.text());
    unpack_slice(s, a, n, dst);
    return VXL_OK;
}

uint32_t dtype_of(const Slice &s)
{
    if (s.bits_alloc == 8) return s.pixel_rep ? VXL_DTYPE_I8 : VXL_DTYPE_U8;
    return s.pixel_rep ? VXL_DTYPE_I16 : VXL_DTYPE_U16;
}

int load_series(const Series &s, const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    const uint32_t frame = vxl_load_frame(opt);
    if (frame >= s.frames)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': frame %u requested, the series has %zu (0..%zu)", path,
                        frame, s.frames, s.frames - 1);
    std::vector<const Slice *> vol; // this time point's files, in position order
    for (size_t i = frame; i < s.slices.size(); i += s.frames) vol.push_back(&s.slices[i]);
    const Slice &f = *vol[0];
    const uint32_t dims[3] = {f.cols, f.rows, uint32_t(vol.size())};
    bool same_scale = true;
    for (const Slice *t : vol) same_scale = same_scale && t->slope == f.slope && t->inter == f.inter;
    const uint32_t dtype = dtype_of(f);
    // per-slice rescale values (PET, some MR) need floats; checked against
    // the budget at the size they will be stored in, before any allocation
    uint64_t nbytes;
    int rc = vxl_plan_voxels(f.path.c_str(), dims, same_scale ? dtype : VXL_DTYPE_F32, opt, &nbytes, e);
    if (rc) return rc;
    const size_t per = size_t(f.rows) * f.cols, elem = f.bits_alloc / 8;
    std::vector<unsigned char> raw(same_scale ? size_t(nbytes) : per * elem);
    std::vector<float> scaled;
    if (!same_scale) scaled.resize(per * dims[2]);
    for (size_t k = 0; k < vol.size(); k++) {
        const Slice &t = *vol[k];
        rc = read_pixels(t, same_scale ? raw.data() + k * per * elem : raw.data(), e);
        if (rc) return rc;
        if (same_scale) continue;
        for (size_t i = 0; i < per; i++) {
            double v = dtype == VXL_DTYPE_U8 ? raw[i]
                     : dtype == VXL_DTYPE_I8 ? reinterpret_cast<const int8_t *>(raw.data())[i]
                     : dtype == VXL_DTYPE_U16 ? reinterpret_cast<const uint16_t *>(raw.data())[i]
                                              : reinterpret_cast<const int16_t *>(raw.data())[i];
            scaled[k * per + i] = float(v * t.slope + t.inter);
        }
    }
    vxl_err inner = {};
    if (same_scale)
        rc = vxl_volume_build(raw.data(), dtype, dims, s.spacing, s.affine, f.slope, f.inter, opt, out, &inner);
    else
        rc = vxl_volume_build(scaled.data(), VXL_DTYPE_F32, dims, s.spacing, s.affine, 0, 0, opt, out, &inner);
    if (rc) return vxl_fail_in(e, f.path.c_str(), &inner);
    (*out)->affine_source = 2; // from the header
    (*out)->frame_count = uint32_t(s.frames);
    (*out)->frame = frame;
    return VXL_OK;
}

void copy_field(char *dst, size_t n, const std::string &s)
{
    snprintf(dst, n, "%s", s.c_str());
}

} // namespace

extern "C" int vxl_dicom_read(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    if (!out) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = nullptr;
    if (!path || !*path) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path is empty");
    try {
        Scan sc;
        int rc = scan(path, sc, e);
        if (rc) return rc;
        const Series *s = nullptr;
        rc = choose(sc, path, vxl_load_series(opt), &s, e);
        if (rc) return rc;
        if (!s->problem.empty()) return vxl_fail(e, VXL_ERR_FORMAT, "%s", s->problem.c_str());
        return load_series(*s, path, opt, out, e);
    } catch (const std::bad_alloc &) {
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory reading the DICOM series", path);
    } catch (const std::exception &x) {
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %s", path, x.what());
    }
}

extern "C" int vxl_dicom_read_series(const char *path, vxl_dicom_series **out, uint32_t *count, vxl_err *e)
{
    if (!out || !count) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out or count is NULL");
    *out = nullptr;
    *count = 0;
    if (!path || !*path) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path is empty");
    try {
        Scan sc;
        int rc = scan(path, sc, e);
        if (rc) return rc;
        vxl_dicom_series *list =
            static_cast<vxl_dicom_series *>(calloc(sc.series.size() ? sc.series.size() : 1, sizeof *list));
        if (!list) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory listing DICOM series", path);
        for (size_t i = 0; i < sc.series.size(); i++) {
            const Series &s = sc.series[i];
            const Slice &f = s.slices[0];
            vxl_dicom_series &d = list[i];
            d.struct_size = uint32_t(sizeof d);
            d.slice_count = uint32_t(s.slices.size());
            d.dims[0] = f.cols;
            d.dims[1] = f.rows;
            d.dims[2] = uint32_t(s.slices.size() / s.frames);
            d.frame_count = uint32_t(s.frames);
            d.loadable = s.problem.empty();
            d.gantry_tilt_deg = s.tilt_deg;
            copy_field(d.uid, sizeof d.uid, f.uid);
            copy_field(d.modality, sizeof d.modality, f.modality);
            copy_field(d.description, sizeof d.description, f.description);
            copy_field(d.problem, sizeof d.problem, s.problem);
        }
        *out = list;
        *count = uint32_t(sc.series.size());
        return VXL_OK;
    } catch (const std::bad_alloc &) {
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory listing DICOM series", path);
    } catch (const std::exception &x) {
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %s", path, x.what());
    }
}
