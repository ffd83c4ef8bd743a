// dicom_syntax.cpp - the transfer syntaxes by UID (dicom_dataset.hpp): the
// name a message gives each (PS3.6 Table A-1), and whether its PixelData
// is encapsulated. Ours rather than a parser's, so that both backends say
// the same.
#include "dicom_dataset.hpp"

namespace vxl_dicom {

namespace {

struct Known {
    const char *uid, *name;
};

const Known kSyntaxes[] = {
    {syntax::ImplicitLittle, "Implicit VR Little Endian"},
    {syntax::ExplicitLittle, "Explicit VR Little Endian"},
    {syntax::Deflated, "Deflated Explicit VR Little Endian"},
    {syntax::ExplicitBig, "Explicit VR Big Endian"},
    {syntax::JpegBaseline, "JPEG Baseline (Process 1)"},
    {syntax::JpegExtended, "JPEG Extended (Process 2 & 4)"},
    {syntax::JpegLossless14, "JPEG Lossless, Non-Hierarchical (Process 14)"},
    {syntax::JpegLosslessSV1, "JPEG Lossless, Non-Hierarchical, First-Order Prediction (Process 14, SV1)"},
    {syntax::JpegLsLossless, "JPEG-LS Lossless"},
    {syntax::JpegLsNearLossless, "JPEG-LS Lossy (Near-Lossless)"},
    {syntax::J2kLossless, "JPEG 2000 (Lossless Only)"},
    {syntax::J2k, "JPEG 2000"},
    {syntax::Htj2kLossless, "HTJ2K Lossless"},
    {syntax::Htj2kRpclLossless, "HTJ2K with RPCL Options Lossless"},
    {syntax::Htj2k, "HTJ2K"},
    {syntax::Rle, "RLE Lossless"},
};

} // namespace

std::string syntax_name(const std::string &uid)
{
    for (const Known &k : kSyntaxes)
        if (uid == k.uid) return k.name;
    return uid.empty() ? "unknown" : uid;
}

bool syntax_encapsulated(const std::string &uid)
{
    return !(uid == syntax::ImplicitLittle || uid == syntax::ExplicitLittle || uid == syntax::Deflated ||
             uid == syntax::ExplicitBig);
}

} // namespace vxl_dicom
