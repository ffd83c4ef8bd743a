// dicom_series.hpp - what the DICOM reader's rooms share: one image (a
// file's frame) as its header describes it, a series of them, and the few
// string helpers every room uses. The rooms, in pipeline order:
//   dicom_header.cpp  one file's header -> one Image per frame (single-frame
//                     files, classic multi-frame, enhanced functional groups)
//   dicom_geometry.cpp a series' images -> their order, time points, affine
//                     and the resampling plan for uneven spacing
//   dicom_pixels.cpp  one file's frames -> pixels (our C for RLE, lossless
//                     JPEG and JPEG 2000; the backend's codecs for the rest)
//   dicom_palette.cpp PALETTE COLOR indices -> their colours (RGB)
//   dicom.cpp         folder scan, series choice, the parallel load
// Each reads files through the data set seam (dicom_dataset.hpp), whose
// backend (dcmtk's parser, or our own) the Makefile picks per target.
// Only the helper process voxlight-read-dicom runs these: libvoxlight links
// no C++.
#ifndef VXL_DICOM_SERIES_HPP
#define VXL_DICOM_SERIES_HPP

#include "dicom_dataset.hpp"

#include <cstdint>
#include <string>
#include <vector>

extern "C" {
#include "error.h"
}

namespace vxl_dicom {

inline void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

inline double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// One 2D image: frame `frame` (0-based) of the file at `path`.
struct Image {
    std::string path, uid, modality, description, photometric;
    std::string stack; // StackID of an enhanced file that holds several stacks ("" otherwise): a series each
    unsigned frame = 0;
    long file_frames = 1; // NumberOfFrames of the file
    unsigned rows = 0, cols = 0, bits_alloc = 0, bits_stored = 0, pixel_rep = 0, samples = 1;
    unsigned planar = 0; // PlanarConfiguration of colour: 0 samples of a pixel together, 1 planes
    bool has_ipp = false, has_iop = false, has_spacing = false, encapsulated = false;
    std::string syntax; // the transfer syntax's UID
    std::string xfer;   // its name, for messages
    double ipp[3] = {0, 0, 0}, iop[6] = {1, 0, 0, 0, 1, 0}, ps[2] = {1, 1};
    double slope = 1, inter = 0, thickness = 0, between = 0; // SliceThickness, SpacingBetweenSlices
    double tkey = 0;       // time order (TemporalPosition*, TriggerTime, AcquisitionNumber, InstanceNumber)
    double instance = 0;   // InstanceNumber: the order of last resort
    std::string geometry;  // how a classic multi-frame's frame positions were found ("" = from its own header)
    double dist = 0;       // position along the slice normal (geometry room)
};

// One output slice: a blend of two input positions (b == a when exact).
struct Sample {
    size_t a = 0, b = 0;
    double t = 0; // weight of b
};

struct Series {
    std::vector<Image> images; // after analyse(): sorted by position, then time; image t of position k is
                               // images[k * frames + t]
    size_t frames = 1;         // time points (4D: several images at every position)
    std::vector<Sample> plan;  // the output slices, from positions (plan.size() slices)
    double tilt_deg = 0;
    double affine[16] = {0};
    double spacing[3] = {1, 1, 1};
    std::vector<std::string> notes; // decisions the user must hear about (vxl_volume.notes)
    std::string problem;            // empty when loadable
};

std::string format(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
std::string basename_of(const std::string &p);
std::string dirname_of(const std::string &p);

enum class Parse { ok, not_dicom, bad };
// A file's images (one per frame). not_dicom: no SeriesInstanceUID/Rows/
// Columns (a README in the folder); bad: claims to be DICOM but cannot be
// parsed, which is an error rather than a silently missing slice.
Parse read_header(const std::string &path, std::vector<Image> &out, std::string &why);

// Sorts and checks a series, derives its geometry and plan; sets
// s.problem when it cannot become one volume.
void analyse(Series &s);

// Three samples per pixel in a photometric interpretation the reader turns
// into colour (RGB, YBR_FULL, YBR_FULL_422, YBR_ICT, YBR_RCT).
bool is_colour(const Image &im);

// Samples a decoded pixel has (read_frames): 3 (RGB) for colour and
// PALETTE COLOR, else 1.
unsigned components_of(const Image &im);

// One bits-stored index per pixel into red, green and blue lookup tables
// (dicom_palette.cpp).
bool is_palette(const Image &im);

// A PALETTE COLOR image's tables, as 16-bit entries.
struct Palette {
    std::vector<uint16_t> rgb[3];
    long first = 0; // the stored value of entry 0
};
// Reads the tables of a file's data set; VXL_OK or a vxl_fail naming the file.
int read_palette(const Dataset &ds, const Image &im, Palette &pal, vxl_err *e);
// A frame of indices (as read_frames unpacks grey pixels) in the first
// rows*cols values of `frame`, in place, into their colours: 3 values a
// pixel (R, G, B together) in the frame's own type, so `frame` has room for
// 3 rows*cols; 8-bit indices give 8-bit colour (the entries rounded from 16
// bits), 16-bit ones the entries as they are.
void rgb_of_palette(const Image &s, const Palette &pal, void *frame);

// Whether the pixels of this image can be decoded here; "" or the reason.
std::string decodable(const Image &im);
// Reads the frames `which` of one file (all images share the path), each
// into dst[i] (rows*cols*components_of values of bits_alloc, native byte
// order, masked to BitsStored and sign-extended; colour as RGB, the samples
// of a pixel together). VXL_OK or a vxl_fail naming the file.
int read_frames(const std::vector<const Image *> &which, const std::vector<void *> &dst, vxl_err *e);

} // namespace vxl_dicom

#endif
