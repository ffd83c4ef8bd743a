// dicom_dataset.hpp - the DICOM reader's one seam to a Part 10 parser: a
// file's data set, its elements by tag, a sequence's items, and PixelData as
// native values or as encapsulated fragments. Two backends implement it, one
// file each, and the Makefile links one per target (docs/dicom.md "Two
// parsers"):
//   dicom_dataset_dcmtk.cpp  dcmtk's parser and its JPEG and JPEG-LS codecs
//                            (Linux: voxlight-read-dicom)
//   dicom_dataset_own.cpp    our own parser (Windows: voxlight-read-dicom.exe,
//                            where dcmtk has no build; on Linux the test
//                            helper voxlight-read-dicom-own, which the DICOM
//                            tests compare with the dcmtk one)
// Nothing above this header names dcmtk.
#ifndef VXL_DICOM_DATASET_HPP
#define VXL_DICOM_DATASET_HPP

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

extern "C" {
#include "error.h"
#include "voxlight.h"
}

namespace vxl_dicom {

// A data element's tag, group in the high 16 bits.
using Tag = uint32_t;
constexpr Tag tag(uint16_t group, uint16_t element) { return Tag(group) << 16 | element; }

// The tags the reader's rooms look up (PS3.6).
namespace tags {
constexpr Tag TransferSyntaxUID = tag(0x0002, 0x0010);
constexpr Tag Modality = tag(0x0008, 0x0060);
constexpr Tag SeriesDescription = tag(0x0008, 0x103E);
constexpr Tag SliceThickness = tag(0x0018, 0x0050);
constexpr Tag SpacingBetweenSlices = tag(0x0018, 0x0088);
constexpr Tag TriggerTime = tag(0x0018, 0x1060);
constexpr Tag SeriesInstanceUID = tag(0x0020, 0x000E);
constexpr Tag AcquisitionNumber = tag(0x0020, 0x0012);
constexpr Tag InstanceNumber = tag(0x0020, 0x0013);
constexpr Tag ImagePositionPatient = tag(0x0020, 0x0032);
constexpr Tag ImageOrientationPatient = tag(0x0020, 0x0037);
constexpr Tag TemporalPositionIdentifier = tag(0x0020, 0x0100);
constexpr Tag StackID = tag(0x0020, 0x9056);
constexpr Tag FrameContentSequence = tag(0x0020, 0x9111);
constexpr Tag PlanePositionSequence = tag(0x0020, 0x9113);
constexpr Tag PlaneOrientationSequence = tag(0x0020, 0x9116);
constexpr Tag TemporalPositionIndex = tag(0x0020, 0x9128);
constexpr Tag SamplesPerPixel = tag(0x0028, 0x0002);
constexpr Tag PhotometricInterpretation = tag(0x0028, 0x0004);
constexpr Tag PlanarConfiguration = tag(0x0028, 0x0006);
constexpr Tag NumberOfFrames = tag(0x0028, 0x0008);
constexpr Tag Rows = tag(0x0028, 0x0010);
constexpr Tag Columns = tag(0x0028, 0x0011);
constexpr Tag PixelSpacing = tag(0x0028, 0x0030);
constexpr Tag BitsAllocated = tag(0x0028, 0x0100);
constexpr Tag BitsStored = tag(0x0028, 0x0101);
constexpr Tag PixelRepresentation = tag(0x0028, 0x0103);
constexpr Tag RescaleIntercept = tag(0x0028, 0x1052);
constexpr Tag RescaleSlope = tag(0x0028, 0x1053);
constexpr Tag RedPaletteDescriptor = tag(0x0028, 0x1101);
constexpr Tag GreenPaletteDescriptor = tag(0x0028, 0x1102);
constexpr Tag BluePaletteDescriptor = tag(0x0028, 0x1103);
constexpr Tag RedPaletteData = tag(0x0028, 0x1201);
constexpr Tag GreenPaletteData = tag(0x0028, 0x1202);
constexpr Tag BluePaletteData = tag(0x0028, 0x1203);
constexpr Tag SegmentedRedPaletteData = tag(0x0028, 0x1221);
constexpr Tag SegmentedGreenPaletteData = tag(0x0028, 0x1222);
constexpr Tag SegmentedBluePaletteData = tag(0x0028, 0x1223);
constexpr Tag PixelMeasuresSequence = tag(0x0028, 0x9110);
constexpr Tag PixelValueTransformationSequence = tag(0x0028, 0x9145);
constexpr Tag GridFrameOffsetVector = tag(0x3004, 0x000C);
constexpr Tag SharedFunctionalGroupsSequence = tag(0x5200, 0x9229);
constexpr Tag PerFrameFunctionalGroupsSequence = tag(0x5200, 0x9230);
constexpr Tag PixelData = tag(0x7FE0, 0x0010);
} // namespace tags

// Element values longer than this stay on disk when a file's header is
// parsed: a folder scan reads headers only; such a value is read when asked
// for (PixelData when a frame is).
constexpr uint32_t kHeaderReadLength = 4096;

// An item of the data set (the data set itself, or a sequence's item):
// the backend's own type, used only through Dataset.
struct Item;

// The fragments of an encapsulated PixelData (the items after the basic
// offset table), with their byte offsets as the table counts them. The
// pointers stay valid while the Dataset lives.
struct Fragments {
    std::vector<std::pair<const uint8_t *, size_t>> items;
    std::vector<uint64_t> at;  // offset of each item's tag from the first fragment's
    std::vector<uint32_t> bot; // the basic offset table (empty when the encoder left it empty)
};

class Dataset {
public:
    Dataset();
    ~Dataset();
    Dataset(const Dataset &) = delete;
    Dataset &operator=(const Dataset &) = delete;

    // Process-wide set-up, once before any thread parses a file (dcmtk's
    // logging and codec registry); safe to call again.
    static void prepare();

    // Parses the file at path; VXL_OK, or a vxl_fail naming the file.
    int open(const std::string &path, vxl_err *e);

    const Item *root() const;
    // The transfer syntax's UID (the meta header's, else the one the data
    // set was found to be in).
    std::string syntax() const;

    bool has(const Item *it, Tag t) const;
    // The first value of a string element, padding trimmed; false if absent.
    bool string(const Item *it, Tag t, std::string &out) const;
    // Value i of a numeric element (DS, IS, FD, SL, UL); false if absent,
    // unreadable or not finite.
    bool number(const Item *it, Tag t, unsigned long i, double &out) const;
    // Value i of a US (unsigned) or SS (signed) element.
    bool us(const Item *it, Tag t, unsigned long i, unsigned &out) const;
    bool ss(const Item *it, Tag t, unsigned long i, int &out) const;
    // A sequence's items: how many, and item i (nullptr past the end).
    size_t items(const Item *it, Tag seq) const;
    const Item *item(const Item *it, Tag seq, size_t i) const;
    // An OW (or US) element's 16-bit words in this machine's byte order.
    bool words(const Item *it, Tag t, std::vector<uint16_t> &out) const;

    // Bytes of uncompressed PixelData as the file states them, before any
    // is read (0 when absent or encapsulated).
    size_t pixel_length() const;
    // Uncompressed PixelData: values of bits_alloc bits in this machine's
    // byte order, len bytes in all. VXL_OK or a vxl_fail naming the file.
    int pixels(unsigned bits_alloc, const uint8_t *&data, size_t &len, vxl_err *e);
    // Encapsulated PixelData; VXL_OK or a vxl_fail naming the file.
    int fragments(Fragments &out, vxl_err *e);

    // Whether this backend has its own codec for the transfer syntax (with
    // `samples` samples a pixel), for what our C does not decode.
    static bool has_codec(const std::string &uid, unsigned samples);
    // Frame f through that codec into dst (room bytes); start_fragment: 0,
    // or where the previous frame's read left off; model: the colour model
    // it decoded into. VXL_OK or a vxl_fail naming the file and frame.
    int decode_frame(unsigned f, uint32_t &start_fragment, void *dst, size_t room, std::string &model, vxl_err *e);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The transfer syntaxes by UID (dicom_syntax.cpp): their names for
// messages, and which of them hold encapsulated (compressed) PixelData.
namespace syntax {
constexpr const char *ImplicitLittle = "1.2.840.10008.1.2";
constexpr const char *ExplicitLittle = "1.2.840.10008.1.2.1";
constexpr const char *Deflated = "1.2.840.10008.1.2.1.99";
constexpr const char *ExplicitBig = "1.2.840.10008.1.2.2";
constexpr const char *JpegBaseline = "1.2.840.10008.1.2.4.50";
constexpr const char *JpegExtended = "1.2.840.10008.1.2.4.51";
constexpr const char *JpegLossless14 = "1.2.840.10008.1.2.4.57";
constexpr const char *JpegLosslessSV1 = "1.2.840.10008.1.2.4.70";
constexpr const char *JpegLsLossless = "1.2.840.10008.1.2.4.80";
constexpr const char *JpegLsNearLossless = "1.2.840.10008.1.2.4.81";
constexpr const char *J2kLossless = "1.2.840.10008.1.2.4.90";
constexpr const char *J2k = "1.2.840.10008.1.2.4.91";
constexpr const char *Htj2kLossless = "1.2.840.10008.1.2.4.201";
constexpr const char *Htj2kRpclLossless = "1.2.840.10008.1.2.4.202";
constexpr const char *Htj2k = "1.2.840.10008.1.2.4.203";
constexpr const char *Rle = "1.2.840.10008.1.2.5";
} // namespace syntax

// The syntax's name ("JPEG Baseline"), or its UID when unknown here.
std::string syntax_name(const std::string &uid);
// Whether PixelData is encapsulated (every syntax but the four
// uncompressed ones).
bool syntax_encapsulated(const std::string &uid);

} // namespace vxl_dicom

#endif
