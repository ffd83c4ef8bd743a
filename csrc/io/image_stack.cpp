// image_stack.cpp - image stacks through OpenImageIO: a multi-page TIFF, a
// numbered series (slice_0001.tif, slice_0002.tif, ... or .png), or a folder
// of .tif/.tiff/.png images, as one volume.
//
// Layout: slice k is image k of the stack (pages in file order; numbered
// files by number; a folder in natural name order). Naming one file of a
// numbered series (same prefix, extension and digit count, numbers without
// gaps) loads the whole series; naming the folder loads every image in it. Within a slice, voxel
// (i, j) is pixel (x = i, y = height-1-j): files store the top row first,
// our voxel j axis points up. Images carry no reliable geometry, so the
// affine is diag(voxel size) from vxl_load_options.voxel_size (1 mm when
// unset). Pixel types: 8/16/32-bit integers, half/float/double. RGB and
// RGBA images (3 or more channels: the first 3, or 4 when the 4th is alpha
// or there are exactly 4; the rest left out with a note) make a colour volume
// (colour_volume.h: the scalar is the opacity source, luminance by default,
// beside the RGB8 colour), grey+alpha the grey channel.
//
// Channels (docs/channels.md; vxl_load_options.channels): a TIFF of 2..8
// samples a pixel whose photometric is grey (BlackIsZero or WhiteIsZero,
// no alpha) is a multi-channel volume under AUTO, and any image of 2..8
// samples is under ON. An OME-TIFF (OME-XML in the first page's
// ImageDescription) whose Pixels say SizeC 2..8 with one page a (z, c, t)
// plane, in any DimensionOrder, is read as channels at time point
// vxl_load_options.frame, with each channel's Name and Color. OFF reads
// both as before (the first samples; every page a slice, noted).
//
// Hostile input: the first image's header sizes pass the memory budget
// before any voxel is allocated, every other slice must match it exactly
// (size, channels, type), and OpenImageIO's messages are passed on with the
// file name. Only the helper process voxlight-read-oiio runs this
// (helper_oiio.c, reader_stream.h): libvoxlight.so links no C++.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <dirent.h>
#include <limits>
#include <memory>
#include <string>
#include <sys/stat.h>
#include <vector>

extern "C" {
#include "channel_volume.h"
#include "colour_volume.h"
#include "helper_main.h"
#include "loader_util.h"
#include "ome_xml.h"
}

namespace {

struct Slice {
    std::string path;
    int subimage;
};

std::string lower(std::string s)
{
    for (auto &c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string extension(const std::string &name)
{
    size_t dot = name.rfind('.');
    size_t slash = name.rfind('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    return lower(name.substr(dot));
}

bool is_image_name(const std::string &name)
{
    std::string e = extension(name);
    return e == ".tif" || e == ".tiff" || e == ".png";
}

// Natural order: runs of digits compare by value, so slice_2 < slice_10.
bool natural_less(const std::string &a, const std::string &b)
{
    size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
            size_t i2 = i, j2 = j;
            while (i2 < a.size() && a[i2] == '0') i2++;
            while (j2 < b.size() && b[j2] == '0') j2++;
            size_t ie = i2, je = j2;
            while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ie++;
            while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) je++;
            if (ie - i2 != je - j2) return ie - i2 < je - j2;
            int c = a.compare(i2, ie - i2, b, j2, je - j2);
            if (c) return c < 0;
            i = ie;
            j = je;
        } else {
            if (a[i] != b[j]) return a[i] < b[j];
            i++;
            j++;
        }
    }
    return a.size() - i < b.size() - j;
}

std::string dir_of(const std::string &p)
{
    size_t s = p.rfind('/');
    return s == std::string::npos ? std::string(".") : (s == 0 ? std::string("/") : p.substr(0, s));
}

std::string join(const std::string &dir, const std::string &name)
{
    return dir == "/" ? "/" + name : dir + "/" + name;
}

bool is_regular(const std::string &p)
{
    struct stat st;
    return stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

int list_dir(const std::string &dir, std::vector<std::string> &names, vxl_err *e)
{
    DIR *d = opendir(dir.c_str());
    if (!d) return vxl_fail(e, VXL_ERR_IO, "cannot open folder '%s': %s", dir.c_str(), std::strerror(errno));
    while (struct dirent *ent = readdir(d)) {
        std::string n = ent->d_name;
        if (n.empty() || n[0] == '.') continue;
        names.push_back(n);
    }
    closedir(d);
    return VXL_OK;
}

// Splits "slice_0012.tif" into prefix "slice_", number 12, ext ".tif".
bool split_numbered(const std::string &name, std::string &prefix, unsigned long long &number, std::string &ext,
                    size_t &width)
{
    size_t dot = name.rfind('.');
    if (dot == std::string::npos || dot == 0) return false;
    size_t end = dot, start = dot;
    while (start > 0 && std::isdigit(static_cast<unsigned char>(name[start - 1]))) start--;
    if (start == end || end - start > 9) return false;
    prefix = name.substr(0, start);
    width = end - start;
    number = std::stoull(name.substr(start, end - start));
    ext = lower(name.substr(dot));
    return true;
}

std::unique_ptr<OIIO::ImageInput> open_image(const std::string &path, vxl_err *e, int *rc)
{
    *rc = VXL_OK;
    if (!is_regular(path)) {
        *rc = vxl_fail(e, VXL_ERR_IO, "cannot open '%s': not a readable regular file", path.c_str());
        return nullptr;
    }
    auto in = OIIO::ImageInput::create(path);
    if (!in) {
        std::string msg = OIIO::geterror();
        vxl_one_line(&msg[0]);
        *rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s': no image reader for this file: %s", path.c_str(), msg.c_str());
        return nullptr;
    }
    in->threads(1); // slices are tiny work items: no thread-pool hand-off per read
    OIIO::ImageSpec config, spec;
    config.attribute("oiio:UnassociatedAlpha", 1); // keep grey values of grey+alpha images as stored
    if (!in->open(path, spec, config)) {
        std::string msg = in->geterror();
        vxl_one_line(&msg[0]);
        *rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read image: %s", path.c_str(),
                       msg.empty() ? "unknown error" : msg.c_str());
        return nullptr;
    }
    return in;
}

uint32_t dtype_for(OIIO::TypeDesc t, OIIO::TypeDesc &read_as)
{
    using OIIO::TypeDesc;
    switch (t.basetype) {
    case TypeDesc::UINT8: read_as = TypeDesc::UINT8; return VXL_DTYPE_U8;
    case TypeDesc::INT8: read_as = TypeDesc::INT8; return VXL_DTYPE_I8;
    case TypeDesc::UINT16: read_as = TypeDesc::UINT16; return VXL_DTYPE_U16;
    case TypeDesc::INT16: read_as = TypeDesc::INT16; return VXL_DTYPE_I16;
    case TypeDesc::UINT32: read_as = TypeDesc::UINT32; return VXL_DTYPE_U32;
    case TypeDesc::INT32: read_as = TypeDesc::INT32; return VXL_DTYPE_I32;
    case TypeDesc::HALF:
    case TypeDesc::FLOAT: read_as = TypeDesc::FLOAT; return VXL_DTYPE_F32;
    case TypeDesc::DOUBLE: read_as = TypeDesc::DOUBLE; return VXL_DTYPE_F64;
    default: return 0;
    }
}

// One image's rows (top first, `row` bytes each) into a slice of the
// volume (bottom first): the voxel j axis points up.
void flip_rows(const unsigned char *src, size_t row, size_t h, unsigned char *dst_slice)
{
    for (size_t y = 0; y < h; y++) std::memcpy(dst_slice + (h - 1 - y) * row, src + y * row, row);
}

// The slices of a numbered series that path belongs to; empty when path is
// not numbered. Gaps and duplicate numbers are errors.
int numbered_series(const std::string &path, std::vector<Slice> &slices, vxl_err *e)
{
    std::string dir = dir_of(path);
    size_t slash = path.rfind('/');
    std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
    std::string prefix, ext;
    unsigned long long num;
    size_t width;
    if (!split_numbered(base, prefix, num, ext, width)) return VXL_OK;
    std::vector<std::string> names;
    int rc = list_dir(dir, names, e);
    if (rc) return rc;
    std::vector<std::pair<unsigned long long, std::string>> found;
    for (const auto &n : names) {
        std::string p2, e2;
        unsigned long long k;
        size_t w2;
        // same prefix, extension and digit count (slice_0009, slice_0010):
        // unrelated names such as scan8.png / scan16.png are no series
        if (split_numbered(n, p2, k, e2, w2) && p2 == prefix && e2 == ext && w2 == width) found.emplace_back(k, n);
    }
    if (found.size() < 2) return VXL_OK;
    std::sort(found.begin(), found.end());
    for (size_t i = 1; i < found.size(); i++) {
        if (found[i].first == found[i - 1].first)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s' and '%s' in '%s' have the same slice number %llu",
                            found[i - 1].second.c_str(), found[i].second.c_str(), dir.c_str(), found[i].first);
        if (found[i].first != found[i - 1].first + 1)
            return vxl_fail(e, VXL_ERR_FORMAT,
                            "numbered series '%s*%s' in '%s': missing slices between %llu ('%s') and %llu ('%s')",
                            prefix.c_str(), ext.c_str(), dir.c_str(), found[i - 1].first,
                            found[i - 1].second.c_str(), found[i].first, found[i].second.c_str());
    }
    for (const auto &f : found) slices.push_back({join(dir, f.second), 0});
    return VXL_OK;
}

// keep/keep_path receive the first file, still open, so it is not opened twice.
int collect_slices(const std::string &path, const vxl_load_options *opt, std::vector<Slice> &slices,
                   std::unique_ptr<OIIO::ImageInput> &keep, std::string &keep_path, vxl_err *e)
{
    struct stat st;
    if (stat(path.c_str(), &st) != 0)
        return vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", path.c_str(), std::strerror(errno));
    if (S_ISDIR(st.st_mode)) {
        std::vector<std::string> names;
        int rc = list_dir(path, names, e);
        if (rc) return rc;
        names.erase(std::remove_if(names.begin(), names.end(), [](const std::string &n) { return !is_image_name(n); }),
                    names.end());
        if (names.empty())
            return vxl_fail(e, VXL_ERR_FORMAT, "folder '%s' has no .tif, .tiff or .png images", path.c_str());
        std::sort(names.begin(), names.end(), natural_less);
        for (const auto &n : names) slices.push_back({join(path, n), 0});
        return VXL_OK;
    }
    // A file: all pages of a multi-page TIFF, else its numbered series.
    int rc;
    auto in = open_image(path, e, &rc);
    if (!in) return rc;
    uint32_t max_pages = (opt && opt->max_dim) ? opt->max_dim : VXL_DEFAULT_MAX_DIM;
    int pages = 1;
    while (in->seek_subimage(pages, 0)) {
        if (static_cast<uint32_t>(pages) >= max_pages)
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s' has more than %u pages, the per-axis limit", path.c_str(),
                            max_pages);
        pages++;
    }
    (void)in->geterror(); // seeking past the last page is not an error
    keep = std::move(in);
    keep_path = path;
    if (pages > 1) {
        for (int s = 0; s < pages; s++) slices.push_back({path, s});
        return VXL_OK;
    }
    rc = numbered_series(path, slices, e);
    if (rc) return rc;
    if (slices.empty()) slices.push_back({path, 0});
    return VXL_OK;
}

// OpenImageIO converts a page in chunks of whole strips (about 64 MiB,
// rounded up to a multiple of RowsPerStrip) or of whole tiles, allocating
// one chunk up front. A corrupt strip or tile size makes that chunk absurd:
// a 288-byte TIFF with 1,986,356,271 rows per strip asked for 31 GB, which
// ends the helper process (or, in-process, any caller) before OpenImageIO
// reads a byte. Strips of more rows than the page has, tiles larger than the
// page, and rows larger than the memory budget are corruption: refused here,
// before the read, with the numbers.
constexpr uint64_t kReadChunkBytes = 64ull << 20; // OpenImageIO's chunk target

int check_read_geometry(const OIIO::ImageSpec &spec, const std::string &name, uint64_t budget, vxl_err *e)
{
    const uint64_t row = spec.scanline_bytes(true); // native type, every channel
    const uint64_t page = row * static_cast<uint64_t>(spec.height);
    if (row > budget)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': one row of %d channels needs %llu bytes, over the %llu-byte memory budget",
                        name.c_str(), spec.nchannels, static_cast<unsigned long long>(row),
                        static_cast<unsigned long long>(budget));
    if (spec.tile_width > 0) {
        const uint64_t tile = static_cast<uint64_t>(spec.tile_width) * static_cast<uint64_t>(spec.tile_height) *
                              static_cast<uint64_t>(spec.tile_depth > 0 ? spec.tile_depth : 1) * spec.pixel_bytes(true);
        if (tile > std::max(kReadChunkBytes, 4 * page))
            return vxl_fail(e, VXL_ERR_FORMAT,
                            "'%s': corrupt TIFF: %dx%d tiles in a %dx%d image (reading one tile would need %llu bytes)",
                            name.c_str(), spec.tile_width, spec.tile_height, spec.width, spec.height,
                            static_cast<unsigned long long>(tile));
        return VXL_OK;
    }
    const int rps = spec.get_int_attribute("tiff:RowsPerStrip", 0);
    if (rps > spec.height && static_cast<uint64_t>(rps) * row > std::max(kReadChunkBytes, page))
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s': corrupt TIFF: %d rows per strip in a %d-row image (reading it would need %llu bytes)",
                        name.c_str(), rps, spec.height, static_cast<unsigned long long>(rps) * row);
    return VXL_OK;
}

std::string slice_name(const Slice &s)
{
    return s.subimage ? s.path + " (page " + std::to_string(s.subimage + 1) + ")" : s.path;
}

// What an OME-TIFF's OME-XML made of its pages: `channels` planes of
// `slices` (channel slowest, then z), or 0 when the pages are read as
// before; `samples_meta` when each page holds the channels as samples.
struct OmePlan {
    uint32_t channels = 0;
    bool samples_meta = false;
    uint32_t frame_count = 1, frame = 0;
    vxl_ome_pixels px{};
    std::string notes;
};

// Reorders a multi-page file's slices into channel-major planar order when
// its OME-XML says SizeC 2..8 with a page per plane (OmePlan).
int plan_ome(const char *path, std::vector<Slice> &slices, OIIO::ImageInput *in, uint32_t mode,
             const vxl_load_options *opt, OmePlan &plan, vxl_err *e)
{
    if (!in || slices.size() < 2 || slices.back().subimage == 0 || !in->seek_subimage(0, 0)) return VXL_OK;
    const std::string desc = in->spec().get_string_attribute("ImageDescription");
    vxl_ome_pixels &px = plan.px;
    if (!vxl_ome_xml_parse(desc.c_str(), desc.size(), &px) || px.size[1] < 2) return VXL_OK;
    const uint64_t nz = px.size[0], nc = px.size[1], nt = px.size[2], pages = slices.size();
    const uint64_t frame = vxl_load_frame(opt);
    const bool sane = nz <= pages && nc <= pages && nt <= pages; // no product below overflows
    const bool planar = sane && nz * nc * nt == pages, interleaved = sane && nz * nt == pages;
    if (mode == VXL_CHANNELS_OFF || (!planar && !interleaved) || (nc > VXL_MAX_CHANNELS && mode == VXL_CHANNELS_AUTO)) {
        plan.notes = "OME-XML's SizeC=" + std::to_string(nc) + " not used (" +
                     (mode == VXL_CHANNELS_OFF ? std::string("channels off")
                      : !planar && !interleaved ? "its sizes do not match the " + std::to_string(pages) + " pages"
                                                : "over the " + std::to_string(VXL_MAX_CHANNELS) + " channels of a volume") +
                     "): every page is a slice";
        return VXL_OK;
    }
    if (nc > VXL_MAX_CHANNELS)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': OME-XML says %llu channels, over the %d a multi-channel volume holds",
                        path, static_cast<unsigned long long>(nc), VXL_MAX_CHANNELS);
    if (frame >= nt)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': frame %llu asked for, the OME-TIFF has %llu time points",
                        path, static_cast<unsigned long long>(frame), static_cast<unsigned long long>(nt));
    if (px.channels != 0 && px.channels != nc)
        plan.notes = "OME-XML lists " + std::to_string(px.channels) + " <Channel> for SizeC=" + std::to_string(nc) +
                     ": names and colours not used";
    if (px.channels != nc) std::memset(px.meta, 0, sizeof px.meta);
    if (px.notes[0]) plan.notes += (plan.notes.empty() ? "" : "; ") + std::string(px.notes);
    std::vector<Slice> chosen;
    if (planar) {
        for (uint64_t c = 0; c < nc; c++)
            for (uint64_t z = 0; z < nz; z++) chosen.push_back(slices[vxl_ome_page(&px, z, c, frame)]);
        plan.channels = static_cast<uint32_t>(nc);
    } else { // the channels are each page's samples: its z planes at t
        for (uint64_t z = 0; z < nz; z++) chosen.push_back(slices[vxl_ome_page(&px, z, 0, frame)]);
        plan.samples_meta = true;
    }
    slices.swap(chosen);
    plan.frame_count = static_cast<uint32_t>(nt);
    plan.frame = static_cast<uint32_t>(frame);
    return VXL_OK;
}

// Whether an image of nch samples is read as channels (see the top).
bool samples_are_channels(const OIIO::ImageSpec &spec, int nch, uint32_t mode)
{
    if (nch < 2 || nch > static_cast<int>(VXL_MAX_CHANNELS) || mode == VXL_CHANNELS_OFF) return false;
    if (mode == VXL_CHANNELS_ON) return true;
    const int photometric = spec.get_int_attribute("tiff:PhotometricInterpretation", -1);
    return (photometric == 0 || photometric == 1) && spec.alpha_channel < 0;
}

} // namespace

extern "C" int vxl_image_stack_read(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    if (!out) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = nullptr;
    if (!path || !*path) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path is empty");
    try {
        std::vector<Slice> slices;
        std::unique_ptr<OIIO::ImageInput> in;
        std::string open_path;
        int rc = collect_slices(path, opt, slices, in, open_path, e);
        if (rc) return rc;
        uint32_t max_dim = (opt && opt->max_dim) ? opt->max_dim : VXL_DEFAULT_MAX_DIM;
        uint32_t mode, scalar_channel;
        if ((rc = vxl_load_channels_mode(opt, &mode, &scalar_channel, e))) return rc;
        OmePlan ome;
        if ((rc = plan_ome(path, slices, in.get(), mode, opt, ome, e))) return rc;
        const uint32_t planes = ome.channels ? ome.channels : 1; // OME-TIFF channels: planar, slices per channel
        if (slices.size() / planes > max_dim)
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s': %zu slices exceed the per-axis limit of %u", path,
                            slices.size() / planes, max_dim);

        std::vector<unsigned char> raw, tmp;
        uint32_t dims[3] = {0, 0, static_cast<uint32_t>(slices.size() / planes)};
        uint32_t dtype = 0, channels = ome.channels; // samples as channels: set by the first page
        int nch = 0, nread = 0;
        OIIO::TypeDesc read_as;
        std::string first;
        size_t es = 0, slice_bytes = 0;
        for (size_t k = 0; k < slices.size(); k++) {
            const Slice &s = slices[k];
            if (!in || open_path != s.path) {
                if (in) in->close();
                in = open_image(s.path, e, &rc);
                if (!in) return rc;
                open_path = s.path;
            }
            if (!in->seek_subimage(s.subimage, 0)) {
                std::string msg = in->geterror();
                vxl_one_line(&msg[0]);
                return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read page %d: %s", s.path.c_str(), s.subimage + 1,
                                msg.c_str());
            }
            const OIIO::ImageSpec &spec = in->spec();
            std::string name = slice_name(s);
            if (spec.deep)
                return vxl_fail(e, VXL_ERR_FORMAT, "'%s': deep images are not supported", name.c_str());
            if (spec.width < 1 || spec.height < 1 || spec.depth != 1 || spec.nchannels < 1)
                return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unsupported image size %dx%dx%d with %d channels",
                                name.c_str(), spec.width, spec.height, spec.depth, spec.nchannels);
            if (k == 0) {
                dtype = dtype_for(spec.format, read_as);
                if (!dtype)
                    return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unsupported pixel type %s", name.c_str(),
                                    spec.format.c_str());
                dims[0] = static_cast<uint32_t>(spec.width);
                dims[1] = static_cast<uint32_t>(spec.height);
                nch = spec.nchannels;
                if (ome.channels && nch != 1)
                    return vxl_fail(e, VXL_ERR_FORMAT, "'%s': OME-TIFF pages of %d samples with a page per channel "
                                    "are not supported", name.c_str(), nch);
                if (ome.samples_meta && static_cast<uint64_t>(nch) != ome.px.size[1])
                    return vxl_fail(e, VXL_ERR_FORMAT, "'%s': OME-XML says SizeC=%llu, the pages have %d samples",
                                    name.c_str(), static_cast<unsigned long long>(ome.px.size[1]), nch);
                if ((ome.channels || ome.samples_meta) && (ome.px.size_x != dims[0] || ome.px.size_y != dims[1]))
                    return vxl_fail(e, VXL_ERR_FORMAT, "'%s': OME-XML says %llux%llu, the pages are %ux%u", name.c_str(),
                                    static_cast<unsigned long long>(ome.px.size_x),
                                    static_cast<unsigned long long>(ome.px.size_y), dims[0], dims[1]);
                if (!channels && samples_are_channels(spec, nch, mode)) channels = static_cast<uint32_t>(nch);
                // RGBA: 4 channels, or more whose 4th is the image's alpha;
                // further channels (microscopy's) are left out with a note
                nread = channels && !ome.channels ? nch : nch >= 3 ? (nch == 4 || spec.alpha_channel == 3 ? 4 : 3) : 1;
                first = name;
                uint64_t nbytes = 0;
                rc = channels    ? vxl_plan_channel_voxels(path, dims, dtype, channels, opt, &nbytes, e)
                     : nread > 1 ? vxl_plan_colour_voxels(path, dims, dtype, uint32_t(nread), opt, &nbytes, e)
                                 : vxl_plan_voxels(path, dims, dtype, opt, &nbytes, e);
                if (rc) return rc;
                if (channels) nbytes *= channels; // one channel's bytes: every channel is read
                es = vxl_dtype_size(dtype);
                slice_bytes = static_cast<size_t>(dims[0]) * dims[1] * es * static_cast<size_t>(nread);
                raw.resize(static_cast<size_t>(nbytes));
                tmp.resize(slice_bytes);
            } else if (static_cast<uint32_t>(spec.width) != dims[0] || static_cast<uint32_t>(spec.height) != dims[1] ||
                       spec.nchannels != nch) {
                return vxl_fail(e, VXL_ERR_FORMAT,
                                "mixed slices: '%s' is %dx%d with %d channels, but '%s' is %ux%u with %d channels",
                                name.c_str(), spec.width, spec.height, spec.nchannels, first.c_str(), dims[0], dims[1],
                                nch);
            }
            OIIO::TypeDesc rt;
            if (dtype_for(spec.format, rt) != dtype)
                return vxl_fail(e, VXL_ERR_FORMAT, "mixed slices: '%s' has pixel type %s, unlike '%s'", name.c_str(),
                                spec.format.c_str(), first.c_str());
            rc = check_read_geometry(spec, name, vxl_load_budget(opt), e);
            if (rc) return rc;
            if (!in->read_image(s.subimage, 0, 0, nread, read_as, tmp.data())) {
                std::string msg = in->geterror();
                vxl_one_line(&msg[0]);
                return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read pixels: %s", name.c_str(),
                                msg.empty() ? "unknown error" : msg.c_str());
            }
            flip_rows(tmp.data(), slice_bytes / dims[1], dims[1], raw.data() + k * slice_bytes);
        }
        if (in) in->close();
        double vs[3];
        vxl_load_voxel_size(opt, vs);
        std::vector<unsigned char>().swap(tmp);
        vxl_err inner = {};
        if (channels) // OME planes: planar; samples: interleaved
            rc = vxl_volume_build_channels(raw.data(), dtype, channels, !ome.channels, dims, vs, nullptr, 0.0, 0.0, opt,
                                           ome.channels || ome.samples_meta ? "OME-TIFF SizeC" : "TIFF samples", out,
                                           &inner);
        else if (nread > 1)
            rc = vxl_volume_build_colour(raw.data(), dtype, uint32_t(nread), 0, dims, vs, nullptr, 0.0, 0.0, opt,
                                         nread == 3 ? "TIFF/PNG RGB" : "TIFF/PNG RGBA", out, &inner);
        else
            rc = vxl_volume_build(raw.data(), dtype, dims, vs, nullptr, 0.0, 0.0, opt, out, &inner);
        if (rc) return vxl_fail_in(e, path, &inner);
        if (!channels && nread > 1 && nch == nread + 1) vxl_volume_note(*out, "channel %d of %d left out", nch, nch);
        else if (!channels && nread > 1 && nch > nread)
            vxl_volume_note(*out, "channels %d to %d of %d left out", nread + 1, nch, nch);
        if (channels && (ome.channels || ome.samples_meta))
            std::memcpy((*out)->ch_meta, ome.px.meta, sizeof ome.px.meta[0] * channels);
        if (ome.frame_count > 1 && (ome.channels || ome.samples_meta)) {
            (*out)->frame_count = ome.frame_count;
            (*out)->frame = ome.frame;
        }
        if (!ome.notes.empty()) vxl_volume_note(*out, "%s", ome.notes.c_str());
        return VXL_OK;
    } catch (const std::bad_alloc &) {
        // the helper's address-space cap (helper_main.c) turns an absurd
        // allocation inside OpenImageIO into this, not into a dead process
        return vxl_fail(e, VXL_ERR_NO_MEMORY,
                        "'%s': the image reader ran out of memory: the file is corrupt, or larger than the memory budget",
                        path);
    } catch (const std::exception &x) {
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %s", path, x.what());
    } catch (...) {
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unexpected error while reading images", path);
    }
}
