// dicom_geometry.cpp - a series' images as one volume: which images belong,
// their order, time points, affine and the slices to make.
//
// DICOM's patient frame is LPS; ours (NIfTI's) is RAS, so x and y of every
// column and of the origin are negated. Voxel (i, j, k) is column i, row j of
// output slice k: column axis = ImageOrientationPatient[0..2] *
// PixelSpacing[1], row axis = IOP[3..5] * PixelSpacing[0], slice axis =
// (last position - first position) / (slices - 1), origin = the first
// position. The slice spacing comes from the positions, never from
// SliceThickness. With gantry tilt the slice axis is not along the normal:
// the affine is sheared, which is the true geometry (tilt_deg reports it).
//
// Series as scanners and PACS send them load the way dcm2niix and Slicer
// load them, with a note (Series::notes) instead of a refusal:
//   - images whose size or orientation differs from most of the series (a
//     localizer) are left out;
//   - a missing or zero PixelSpacing is taken as 1 mm;
//   - uneven steps (a missing slice, variable spacing) are resampled onto an
//     even grid at the series' usual step: each output slice is a linear blend
//     of the two input slices around it, exact where one lies on the grid.
//     Resampling keeps one volume and one affine, which is what every
//     renderer and the add-on's object need; splitting would hand the user
//     pieces of one scan.
// Several images at one position are time points (4D) when every position
// holds the same number with distinct time keys.
#include "dicom_series.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

extern "C" {
#include "loader_util.h"
}

namespace vxl_dicom {

namespace {

constexpr double kSamePosition = 0.01; // mm: images closer than this share a position
constexpr double kOnGrid = 1e-3;       // a blend weight this close to 0 or 1 takes the image as is

// What makes images stackable: size, pixel format and orientation (to 1e-3).
using Kind = std::tuple<unsigned, unsigned, unsigned, long, long, long, long, long, long>;
Kind kind_of(const Image &s)
{
    auto q = [](double x) { return std::lround(x * 1000); };
    return Kind(s.rows, s.cols, s.samples, q(s.iop[0]), q(s.iop[1]), q(s.iop[2]), q(s.iop[3]), q(s.iop[4]),
                q(s.iop[5]));
}

// Keeps the images of the kind most of the series has; the others
// (localizers, scouts, a reformat saved into the series) are left out with
// a note. No clear majority is a problem: which one the user wants is not
// ours to guess.
void drop_strays(Series &s)
{
    std::map<Kind, size_t> count;
    for (const Image &im : s.images) count[kind_of(im)]++;
    if (count.size() < 2) return;
    auto best = std::max_element(count.begin(), count.end(),
                                 [](const auto &a, const auto &b) { return a.second < b.second; });
    size_t ties = 0;
    for (const auto &kv : count) ties += kv.second == best->second;
    const Image &f = s.images[0];
    if (ties > 1) {
        for (const Image &im : s.images)
            if (kind_of(im) != kind_of(f)) {
                s.problem = format("images of different sizes or orientations in equal numbers: %ux%u ('%s') and "
                                   "%ux%u ('%s'); no majority to keep", f.cols, f.rows, f.path.c_str(), im.cols,
                                   im.rows, im.path.c_str());
                return;
            }
    }
    std::vector<Image> kept;
    std::string first_out;
    size_t out = 0;
    for (Image &im : s.images) {
        if (kind_of(im) == best->first) { kept.push_back(std::move(im)); continue; }
        if (!out++) first_out = format("'%s' (%ux%u)", basename_of(im.path).c_str(), im.cols, im.rows);
    }
    s.images = std::move(kept);
    s.notes.push_back(format("left out %zu image(s) whose size or orientation differs from the other %zu "
                             "(a localizer?), first %s", out, s.images.size(), first_out.c_str()));
}

// What every image must share with the first, or the reason it does not.
std::string check_pixels(std::vector<Image> &sl, std::vector<std::string> &notes)
{
    const Image &f = sl[0];
    for (const Image &s : sl) {
        const char *p = s.path.c_str();
        std::string why = decodable(s);
        if (!why.empty()) return why;
        if (s.samples != 1 && !is_colour(s))
            return format("'%s': %u samples per pixel of '%s' is not supported (grey, RGB and YBR_FULL, _422, "
                          "_ICT, _RCT are)", p, s.samples, s.photometric.c_str());
        if (s.photometric == "PALETTE COLOR" && (!is_palette(s) || s.pixel_rep || s.bits_alloc == 32))
            return format("'%s': PALETTE COLOR of %u sample(s) of %u %s bits is not supported (one unsigned 8- "
                          "or 16-bit index)", p, s.samples, s.bits_alloc, s.pixel_rep ? "signed" : "unsigned");
        if (is_colour(s) && (s.bits_alloc == 32 || s.pixel_rep))
            return format("'%s': colour of %u %s bits per sample is not supported (8 or 16, unsigned)", p,
                          s.bits_alloc, s.pixel_rep ? "signed" : "unsigned");
        if (s.photometric != f.photometric)
            return format("mixed PhotometricInterpretation in the series: %s ('%s') and %s ('%s')",
                          f.photometric.c_str(), f.path.c_str(), s.photometric.c_str(), p);
        if (s.bits_alloc != 8 && s.bits_alloc != 16 && s.bits_alloc != 32)
            return format("'%s': BitsAllocated %u is not supported (8, 16 or 32)", p, s.bits_alloc);
        if (s.bits_stored < 1 || s.bits_stored > s.bits_alloc)
            return format("'%s': BitsStored %u does not fit BitsAllocated %u", p, s.bits_stored, s.bits_alloc);
        if (s.pixel_rep > 1) return format("'%s': bad PixelRepresentation %u", p, s.pixel_rep);
        if (s.bits_alloc != f.bits_alloc || s.pixel_rep != f.pixel_rep || s.bits_stored != f.bits_stored)
            return format("mixed pixel types in the series: '%s' and '%s'", f.path.c_str(), p);
        if (s.slope == 0) return format("'%s': RescaleSlope is 0", p);
    }
    // a missing or zero PixelSpacing is 1 mm, as dcm2niix takes it
    size_t assumed = 0;
    for (Image &s : sl)
        if (!s.has_spacing || !(s.ps[0] > 0) || !(s.ps[1] > 0)) {
            s.ps[0] = s.ps[1] = 1;
            assumed++;
        }
    if (assumed)
        notes.push_back(format("PixelSpacing missing or zero in %zu of %zu image(s): 1 mm assumed", assumed,
                               sl.size()));
    for (const Image &s : sl)
        if (std::fabs(s.ps[0] - f.ps[0]) > 1e-4 * f.ps[0] || std::fabs(s.ps[1] - f.ps[1]) > 1e-4 * f.ps[1])
            return format("mixed PixelSpacing in the series: %g\\%g ('%s') and %g\\%g ('%s')", f.ps[0], f.ps[1],
                          f.path.c_str(), s.ps[0], s.ps[1], s.path.c_str());
    return "";
}

// Images without a position (some exports strip it) are placed in
// InstanceNumber order, SliceThickness apart (1 mm without one).
void place_unpositioned(Series &s)
{
    std::vector<Image> &sl = s.images;
    if (sl.size() < 2) return;
    size_t missing = 0;
    for (const Image &im : sl) missing += !im.has_ipp || !im.has_iop;
    if (!missing) return;
    std::stable_sort(sl.begin(), sl.end(), [](const Image &a, const Image &b) { return a.instance < b.instance; });
    const double step = sl[0].thickness > 0 ? sl[0].thickness : 1;
    for (size_t i = 0; i < sl.size(); i++) {
        sl[i].has_ipp = sl[i].has_iop = true;
        std::copy(sl[0].iop, sl[0].iop + 6, sl[i].iop);
        for (int a = 0; a < 3; a++) sl[i].ipp[a] = 0;
        sl[i].ipp[2] = double(i) * step;
        sl[i].tkey = 0;
    }
    s.notes.push_back(format("%zu of %zu image(s) have no ImagePositionPatient/ImageOrientationPatient: ordered by "
                             "InstanceNumber, %.4g mm apart%s", missing, sl.size(), step,
                             sl[0].thickness > 0 ? " (SliceThickness)" : " (assumed)"));
}

bool group_time_points(Series &s)
{
    std::vector<Image> &sl = s.images;
    std::vector<size_t> starts;
    for (size_t i = 0; i < sl.size(); i++)
        if (starts.empty() || sl[i].dist - sl[starts.back()].dist > kSamePosition) starts.push_back(i);
    starts.push_back(sl.size());
    const size_t t = starts[1] - starts[0];
    for (size_t g = 0; g + 1 < starts.size(); g++) {
        size_t b = starts[g], e = starts[g + 1];
        if (e - b != t) {
            s.problem = format("%zu image(s) at the position of '%s' but %zu at that of '%s' (%.4g mm along the "
                               "normal): a 4D series needs the same number of time points at every position "
                               "(missing or duplicate files?)", t, basename_of(sl[0].path).c_str(), e - b,
                               basename_of(sl[b].path).c_str(), sl[b].dist);
            return false;
        }
        std::stable_sort(sl.begin() + long(b), sl.begin() + long(e),
                         [](const Image &x, const Image &y) { return x.tkey < y.tkey; });
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

// The output slices over positions rep (sorted along the normal): one per
// position when the steps are even, else an even grid at the usual step.
// Returns the step vector between output slices through w.
bool plan_slices(Series &s, const std::vector<const Image *> &rep, double w[3])
{
    const size_t k = rep.size();
    std::vector<double> steps, sorted;
    for (size_t i = 1; i < k; i++) steps.push_back(rep[i]->dist - rep[i - 1]->dist);
    sorted = steps;
    std::sort(sorted.begin(), sorted.end());
    const double typical = sorted[sorted.size() / 2];
    const double tol = 0.01 * std::fabs(typical) + 1e-4;
    size_t uneven = 0, worst = 0;
    for (size_t i = 0; i < steps.size(); i++)
        if (std::fabs(steps[i] - typical) > tol) {
            if (!uneven++ || std::fabs(steps[i] - typical) > std::fabs(steps[worst] - typical)) worst = i;
        }
    const double length = rep[k - 1]->dist - rep[0]->dist;
    size_t m = k;
    if (uneven) {
        m = size_t(std::lround(length / typical)) + 1;
        if (m < 2 || m > 4 * k + 16) {
            s.problem = format("slice spacing too uneven to resample: %.4g mm between '%s' and '%s', usual step "
                               "%.4g mm", steps[worst], basename_of(rep[worst]->path).c_str(),
                               basename_of(rep[worst + 1]->path).c_str(), typical);
            return false;
        }
    }
    // every position must lie on the line through the first and the last
    for (int a = 0; a < 3; a++) w[a] = (rep[k - 1]->ipp[a] - rep[0]->ipp[a]) / length;
    for (size_t i = 0; i < k; i++)
        for (int a = 0; a < 3; a++)
            if (std::fabs(rep[0]->ipp[a] + (rep[i]->dist - rep[0]->dist) * w[a] - rep[i]->ipp[a]) > tol) {
                s.problem = format("'%s': ImagePositionPatient is off the line through the other slices",
                                   rep[i]->path.c_str());
                return false;
            }
    const double step = length / double(m - 1);
    for (int a = 0; a < 3; a++) w[a] *= step;
    s.plan.assign(m, Sample());
    size_t blended = 0, i = 0;
    for (size_t j = 0; j < m; j++) {
        Sample &p = s.plan[j];
        if (!uneven) { p.a = p.b = j; continue; }
        const double d = rep[0]->dist + double(j) * step;
        while (i + 2 < k && rep[i + 1]->dist <= d) i++;
        double t = (d - rep[i]->dist) / (rep[i + 1]->dist - rep[i]->dist);
        t = std::min(1.0, std::max(0.0, t));
        if (t < kOnGrid) p.a = p.b = i;
        else if (t > 1 - kOnGrid) p.a = p.b = i + 1;
        else { p.a = i; p.b = i + 1; p.t = t; blended++; }
    }
    if (uneven)
        s.notes.push_back(format("uneven slice spacing (a missing slice?): %.4g mm between '%s' and '%s' where the "
                                 "usual step is %.4g mm (%zu uneven step(s)); resampled to %zu slices every %.4g "
                                 "mm, %zu of them interpolated", steps[worst],
                                 basename_of(rep[worst]->path).c_str(), basename_of(rep[worst + 1]->path).c_str(),
                                 typical, uneven, m, step, blended));
    return true;
}

} // namespace

void analyse(Series &s)
{
    drop_strays(s);
    if (!s.problem.empty()) return;
    std::vector<Image> &sl = s.images;
    s.problem = check_pixels(sl, s.notes);
    if (!s.problem.empty()) return;
    place_unpositioned(s);
    for (const Image &im : sl)
        if (!im.geometry.empty()) { s.notes.push_back(im.geometry); break; }
    // every image shares f's orientation and pixel spacing (drop_strays and
    // check_pixels), so f stays valid for them after sorting
    const Image &f = sl[0];
    const double *r = f.iop, *c = f.iop + 3;
    double n[3];
    cross(r, c, n);
    double rl = std::sqrt(dot(r, r)), cl = std::sqrt(dot(c, c)), nl = std::sqrt(dot(n, n));
    if (!(std::fabs(rl - 1) < 1e-3 && std::fabs(cl - 1) < 1e-3 && std::fabs(dot(r, c)) < 1e-3)) {
        s.problem = format("'%s': ImageOrientationPatient is not two orthogonal unit vectors", f.path.c_str());
        return;
    }
    for (double &x : n) x /= nl;
    for (Image &t : sl) t.dist = dot(t.ipp, n);
    std::stable_sort(sl.begin(), sl.end(), [](const Image &a, const Image &b) { return a.dist < b.dist; });
    if (!group_time_points(s)) return;
    std::vector<const Image *> rep; // one image per position: the first time point's
    for (size_t i = 0; i < sl.size(); i += s.frames) rep.push_back(&sl[i]);

    double w[3] = {n[0], n[1], n[2]}; // slice axis (LPS), per output slice
    if (rep.size() > 1) {
        if (!plan_slices(s, rep, w)) return;
        double wl = std::sqrt(dot(w, w));
        double cosang = std::min(1.0, std::fabs(dot(w, n)) / wl);
        s.tilt_deg = std::acos(cosang) * 180.0 / M_PI;
        if (s.tilt_deg < 1e-3) s.tilt_deg = 0;
    } else {
        s.plan.assign(1, Sample());
        const double th = f.thickness > 0 ? f.thickness : f.between;
        if (th > 0) for (double &x : w) x *= th;
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

} // namespace vxl_dicom
