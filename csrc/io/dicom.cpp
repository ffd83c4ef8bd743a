// dicom.cpp - DICOM series: a folder of images, a DICOMDIR
// (its folder, searched recursively) or one file of a series (the series of
// that file, from its folder), as one volume. The entry points of the
// helper voxlight-read-dicom; the rooms are named in dicom_series.hpp.
//
// Flow: every file's header becomes one image per frame (dicom_header.cpp)
// -> images are grouped by SeriesInstanceUID -> the chosen series is sorted
// and its geometry derived (dicom_geometry.cpp) -> the size is checked
// against the memory budget -> the files are read in parallel, one file per
// task, each read once (dicom_pixels.cpp) -> the output slices are made by
// the plan (a copy, or a blend where the spacing was uneven) ->
// vxl_volume_build applies RescaleSlope/Intercept (CT lands in Hounsfield
// units); slices with differing rescale values are converted to float first.
// Colour (RGB, YBR_*, PALETTE COLOR, decoded to RGB) goes the same way with
// three samples a pixel into vxl_volume_build_colour: a colour volume whose
// scalar is the opacity source the options ask for (luminance by default);
// colour has no rescale (the Modality LUT, PS3.3 C.11.1, is for grey
// images only).
// What the reader decided (a localizer left out, 1 mm assumed, slices
// interpolated) goes to vxl_volume.notes.
//
// 4D: when every position holds the same number of images with distinct time
// keys, they are time points; vxl_load_options.frame picks one.
//
// Whether a path is DICOM at all is decided in the library, in C
// (dicom_detect.c): libvoxlight.so links no C++.
#include "dicom_series.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <strings.h>
#include <vector>

extern "C" {
#include "colour_volume.h"
#include "files.h"
#include "helper_main.h"
#include "loader_util.h"
#include "threads.h"
}

using namespace vxl_dicom;

namespace {

constexpr size_t kMaxFiles = 100000; // a folder scan stops with an error past this
constexpr int kMaxDepth = 8;         // DICOMDIR trees are a few levels deep
constexpr unsigned kMaxReaders = 16; // threads reading files; beyond this the disk is the limit

bool is_dicomdir_name(const std::string &p) { return strcasecmp(basename_of(p).c_str(), "DICOMDIR") == 0; }

// Regular files under dir (recursively to kMaxDepth when recurse), skipping
// dot files and DICOMDIR itself, in name order. false when over kMaxFiles.
bool list_files(const std::string &dir, bool recurse, int depth, std::vector<std::string> &out)
{
    vxl_dir *d = vxl_dir_open(dir.c_str());
    if (!d) return true;
    std::vector<std::string> names;
    while (const char *name = vxl_dir_next(d)) {
        if (name[0] == '.') continue;
        names.emplace_back(name);
    }
    vxl_dir_close(d);
    std::sort(names.begin(), names.end());
    for (const auto &n : names) {
        std::string p = dir + "/" + n;
        vxl_path_info st;
        if (vxl_path_stat(p.c_str(), &st) != 0) continue;
        if (st.kind == VXL_PATH_DIR) {
            if (recurse && depth < kMaxDepth && !list_files(p, recurse, depth + 1, out)) return false;
        } else if (st.kind == VXL_PATH_FILE && !is_dicomdir_name(n)) {
            if (out.size() >= kMaxFiles) return false;
            out.push_back(p);
        }
    }
    return true;
}

// The files a path stands for, and the series they hold (sorted by UID).
struct Scan {
    std::string origin;      // the file the caller named, if one
    std::vector<Series> series;
};

int scan(const std::string &path, Scan &out, vxl_err *e)
{
    Dataset::prepare();
    vxl_path_info st;
    if (vxl_path_stat(path.c_str(), &st) != 0)
        return vxl_fail(e, VXL_ERR_IO, "'%s': %s", path.c_str(), strerror(errno));
    std::vector<std::string> files;
    bool complete;
    std::string where = path;
    if (st.kind == VXL_PATH_DIR) {
        complete = list_files(path, true, 0, files);
    } else if (is_dicomdir_name(path)) {
        where = dirname_of(path);
        complete = list_files(where, true, 0, files);
    } else {
        if (st.kind != VXL_PATH_FILE) return vxl_fail(e, VXL_ERR_IO, "'%s' is not a regular file", path.c_str());
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
    std::map<std::string, Series> by_uid; // UID, then the stack of a file with several
    for (const std::string &f : files) {
        std::vector<Image> images;
        std::string why;
        Parse p = read_header(f, images, why);
        if (p == Parse::bad || (p == Parse::not_dicom && f == out.origin))
            return vxl_fail(e, VXL_ERR_FORMAT, "%s", why.c_str());
        if (p == Parse::ok)
            for (Image &im : images) by_uid[im.uid + '\n' + im.stack].images.push_back(std::move(im));
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
    const Image &f = s.images[0];
    return format("%zu: %s (%s%s%s, %zu images)", i, f.uid.c_str(), f.modality.empty() ? "?" : f.modality.c_str(),
                  f.description.empty() ? "" : ", ", f.description.c_str(), s.images.size());
}

// The series the options (or the named file) pick.
int choose(const Scan &sc, const std::string &path, const char *want, const Series **out, vxl_err *e)
{
    const auto &all = sc.series;
    if (want && *want) {
        for (const Series &s : all)
            if (s.images[0].uid == want) { *out = &s; return VXL_OK; }
        char *end;
        unsigned long i = strtoul(want, &end, 10);
        if (!*end && std::isdigit((unsigned char)want[0]) && i < all.size()) { *out = &all[i]; return VXL_OK; }
        std::string list;
        for (size_t k = 0; k < all.size(); k++) list += "; " + series_line(k, all[k]);
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': no series '%s' (an index 0..%zu or a UID)%s",
                        path.c_str(), want, all.size() - 1, list.c_str());
    }
    if (!sc.origin.empty()) { // the named file's series, unless the file holds several (stacks)
        const Series *found = nullptr;
        size_t holders = 0;
        for (const Series &s : all)
            if (std::any_of(s.images.begin(), s.images.end(), [&](const Image &t) { return t.path == sc.origin; })) {
                found = &s;
                holders++;
            }
        if (holders == 1) { *out = found; return VXL_OK; }
    }
    if (all.size() == 1) { *out = &all[0]; return VXL_OK; }
    std::string list;
    for (size_t k = 0; k < all.size(); k++) list += "; " + series_line(k, all[k]);
    return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s' holds %zu DICOM series: choose one (series option, CLI "
                    "--series N|UID)%s", path.c_str(), all.size(), list.c_str());
}

// The files to read for one time point: each file once, with the images
// (frames) wanted from it and where each goes.
struct FileTask {
    std::vector<const Image *> images;
    std::vector<void *> dst;
};

// Reads every task, on up to vxl_cpu_count() threads, one file per task.
// The error reported is that of the first failing task in task order, so
// the message does not depend on thread timing.
struct ReadPool {
    std::vector<FileTask> *tasks = nullptr;
    std::atomic<size_t> next{0};
    std::atomic<bool> failed{false};
    std::vector<vxl_err> errors;
    std::vector<int> codes;
};

void *read_worker(void *arg)
{
    ReadPool &pool = *static_cast<ReadPool *>(arg);
    for (;;) {
        const size_t i = pool.next.fetch_add(1);
        if (i >= pool.tasks->size() || pool.failed.load()) return nullptr;
        FileTask &t = (*pool.tasks)[i];
        try {
            pool.codes[i] = read_frames(t.images, t.dst, &pool.errors[i]);
        } catch (const std::bad_alloc &) {
            pool.codes[i] = vxl_fail(&pool.errors[i], VXL_ERR_NO_MEMORY, "'%s': out of memory decoding",
                                     t.images[0]->path.c_str());
        }
        if (pool.codes[i]) pool.failed.store(true);
    }
}

int read_all(std::vector<FileTask> &tasks, vxl_err *e)
{
    ReadPool pool;
    pool.tasks = &tasks;
    pool.errors.assign(tasks.size(), vxl_err());
    pool.codes.assign(tasks.size(), VXL_OK);
    const unsigned n = unsigned(std::min<size_t>({vxl_cpu_count(), kMaxReaders, tasks.size()}));
    std::vector<vxl_thread> threads(n);
    unsigned started = 0;
    for (; started + 1 < n; started++)
        if (vxl_thread_start(&threads[started], read_worker, &pool) != 0) break;
    read_worker(&pool); // this thread works too (and alone when no thread started)
    for (unsigned i = 0; i < started; i++) vxl_thread_join(threads[i]);
    for (size_t i = 0; i < tasks.size(); i++)
        if (pool.codes[i]) return vxl_fail(e, pool.codes[i], "%s", pool.errors[i].msg);
    return VXL_OK;
}

// A multi-frame file is one task, so an enhanced CT in one file would
// decode on one core. Its compressed frames are split into a piece per core,
// each piece reading the file for itself: decoding a frame costs far more
// than rereading the compressed bytes. Uncompressed frames cost no decoding
// and stay whole.
void split_for_cores(std::vector<FileTask> &tasks)
{
    const size_t cores = std::min<size_t>(vxl_cpu_count(), kMaxReaders);
    if (tasks.empty() || tasks.size() >= cores) return;
    const size_t share = (cores + tasks.size() - 1) / tasks.size();
    std::vector<FileTask> out;
    for (FileTask &t : tasks) {
        const size_t n = t.images.size();
        const size_t pieces = t.images[0]->encapsulated ? std::min(n, share) : 1;
        for (size_t p = 0; p < pieces; p++) {
            FileTask piece;
            for (size_t i = p * n / pieces; i < (p + 1) * n / pieces; i++) {
                piece.images.push_back(t.images[i]);
                piece.dst.push_back(t.dst[i]);
            }
            out.push_back(std::move(piece));
        }
    }
    tasks.swap(out);
}

uint32_t dtype_of(const Image &s)
{
    if (s.bits_alloc == 8) return s.pixel_rep ? VXL_DTYPE_I8 : VXL_DTYPE_U8;
    if (s.bits_alloc == 32) return s.pixel_rep ? VXL_DTYPE_I32 : VXL_DTYPE_U32;
    return s.pixel_rep ? VXL_DTYPE_I16 : VXL_DTYPE_U16;
}

double value_at(uint32_t dtype, const unsigned char *slice, size_t i)
{
    switch (dtype) {
    case VXL_DTYPE_U8: return slice[i];
    case VXL_DTYPE_I8: return reinterpret_cast<const int8_t *>(slice)[i];
    case VXL_DTYPE_U16: return reinterpret_cast<const uint16_t *>(slice)[i];
    case VXL_DTYPE_I16: return reinterpret_cast<const int16_t *>(slice)[i];
    case VXL_DTYPE_U32: return reinterpret_cast<const uint32_t *>(slice)[i];
    default: return reinterpret_cast<const int32_t *>(slice)[i];
    }
}

template <typename T> void store_rounded(double v, unsigned char *slice, size_t i)
{
    reinterpret_cast<T *>(slice)[i] = T(std::lround(v));
}

int load_series(const Series &s, const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    const uint32_t frame = vxl_load_frame(opt);
    if (frame >= s.frames)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': frame %u requested, the series has %zu (0..%zu)", path,
                        frame, s.frames, s.frames - 1);
    std::vector<const Image *> pos; // this time point's images, in position order
    for (size_t i = frame; i < s.images.size(); i += s.frames) pos.push_back(&s.images[i]);
    const Image &f = *pos[0];
    const size_t m = s.plan.size(), k = pos.size();
    const bool resampled = m != k || std::any_of(s.plan.begin(), s.plan.end(),
                                                 [](const Sample &p) { return p.a != p.b; });
    const uint32_t dims[3] = {f.cols, f.rows, uint32_t(m)};
    const unsigned comps = components_of(f); // 3: colour as RGB (read_frames)
    bool same_scale = true;
    for (const Image *t : pos) same_scale = same_scale && (comps > 1 || (t->slope == f.slope && t->inter == f.inter));
    const uint32_t dtype = dtype_of(f);
    // per-slice rescale values (PET, some MR) need floats; checked against
    // the budget at the size they will be stored in, before any allocation,
    // with the decoded positions counted too when they are blended
    const size_t per = size_t(f.rows) * f.cols * comps, elem = f.bits_alloc / 8;
    const uint32_t whole[3] = {f.cols, f.rows, uint32_t(m + (resampled || !same_scale ? k : 0))};
    uint64_t nbytes;
    int rc = comps > 1 ? vxl_plan_colour_voxels(f.path.c_str(), whole, dtype, comps, opt, &nbytes, e)
                       : vxl_plan_voxels(f.path.c_str(), whole, same_scale ? dtype : VXL_DTYPE_F32, opt, &nbytes, e);
    if (rc) return rc;
    // decoded positions: straight into the output when the plan is a copy
    // with one scale, else into their own slices first
    const bool direct = !resampled && same_scale;
    std::vector<unsigned char> decoded(per * elem * (direct ? m : k));
    std::map<std::string, size_t> task_of;
    std::vector<FileTask> tasks;
    for (size_t i = 0; i < k; i++) {
        auto it = task_of.emplace(pos[i]->path, tasks.size()).first;
        if (it->second == tasks.size()) tasks.emplace_back();
        tasks[it->second].images.push_back(pos[i]);
        tasks[it->second].dst.push_back(decoded.data() + i * per * elem);
    }
    split_for_cores(tasks);
    rc = read_all(tasks, e);
    if (rc) return rc;
    std::vector<unsigned char> blended;
    std::vector<float> scaled;
    if (!same_scale) scaled.resize(per * m);
    else if (!direct) blended.resize(per * elem * m);
    for (size_t j = 0; j < m && !direct; j++) {
        const Sample &p = s.plan[j];
        const unsigned char *a = decoded.data() + p.a * per * elem, *b = decoded.data() + p.b * per * elem;
        const Image &ia = *pos[p.a], &ib = *pos[p.b];
        unsigned char *o = blended.data() + j * per * elem;
        for (size_t i = 0; i < per; i++) {
            double va = value_at(dtype, a, i), vb = value_at(dtype, b, i);
            if (!same_scale) {
                va = va * ia.slope + ia.inter;
                vb = vb * ib.slope + ib.inter;
                scaled[j * per + i] = float(va + p.t * (vb - va));
                continue;
            }
            const double v = va + p.t * (vb - va);
            switch (dtype) {
            case VXL_DTYPE_U8: store_rounded<uint8_t>(v, o, i); break;
            case VXL_DTYPE_I8: store_rounded<int8_t>(v, o, i); break;
            case VXL_DTYPE_U16: store_rounded<uint16_t>(v, o, i); break;
            case VXL_DTYPE_I16: store_rounded<int16_t>(v, o, i); break;
            case VXL_DTYPE_U32: store_rounded<uint32_t>(v, o, i); break;
            default: store_rounded<int32_t>(v, o, i); break;
            }
        }
    }
    vxl_err inner = {};
    const void *data = direct ? decoded.data() : blended.data();
    if (comps > 1)
        rc = vxl_volume_build_colour(data, dtype, comps, 0, dims, s.spacing, s.affine, 0, 0, opt,
                                     format("DICOM %s", f.photometric.c_str()).c_str(), out, &inner);
    else if (same_scale)
        rc = vxl_volume_build(data, dtype, dims, s.spacing, s.affine, f.slope, f.inter, opt, out, &inner);
    else
        rc = vxl_volume_build(scaled.data(), VXL_DTYPE_F32, dims, s.spacing, s.affine, 0, 0, opt, out, &inner);
    if (rc) return vxl_fail_in(e, f.path.c_str(), &inner);
    (*out)->affine_source = 2; // from the header
    (*out)->frame_count = uint32_t(s.frames);
    (*out)->frame = frame;
    for (const std::string &n : s.notes) vxl_volume_note(*out, "%s", n.c_str());
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
            const Image &f = s.images[0];
            vxl_dicom_series &d = list[i];
            d.struct_size = uint32_t(sizeof d);
            d.slice_count = uint32_t(s.images.size());
            d.dims[0] = f.cols;
            d.dims[1] = f.rows;
            d.dims[2] = uint32_t(s.plan.empty() ? s.images.size() / s.frames : s.plan.size());
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
