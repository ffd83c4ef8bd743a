// image_io.cpp - vxl_write_image through OpenImageIO: the one C++ file, kept
// behind an extern "C" function so the rest of the library stays C11.
#include <OpenImageIO/imageio.h>

#include <cctype>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

extern "C" {
#include "voxlight.h"
int vxl_fail(struct vxl_err *e, int code, const char *fmt, ...);
}

static bool ends_with(const std::string &s, const char *suffix)
{
    size_t n = std::strlen(suffix);
    if (s.size() < n) return false;
    for (size_t i = 0; i < n; i++)
        if (std::tolower(static_cast<unsigned char>(s[s.size() - n + i])) != suffix[i]) return false;
    return true;
}

extern "C" VXL_API int vxl_write_image(const char *path, const float *rgba, const float *depth, uint32_t w,
                                       uint32_t h)
{
    if (!path || !rgba || w == 0 || h == 0 || w > 65536 || h > 65536)
        return vxl_fail(nullptr, VXL_ERR_INVALID_ARGUMENT, "write_image: bad path, buffer or size");
    std::string p(path);
    bool exr = ends_with(p, ".exr");
    if (!exr && !ends_with(p, ".png"))
        return vxl_fail(nullptr, VXL_ERR_INVALID_ARGUMENT, "write_image: %s: use a .png or .exr name", path);
    int channels = exr && depth ? 5 : 4;
    // Files are stored top row first; our buffers are bottom row first.
    std::vector<float> px(static_cast<size_t>(w) * h * channels);
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            const float *s = rgba + (static_cast<size_t>(h - 1 - y) * w + x) * 4;
            float *d = px.data() + (static_cast<size_t>(y) * w + x) * channels;
            float a = s[3];
            for (int c = 0; c < 4; c++) d[c] = std::isfinite(s[c]) ? s[c] : 0.0f;
            if (!exr && a > 0) // PNG holds straight alpha
                for (int c = 0; c < 3; c++) d[c] = std::fmin(1.0f, d[c] / a);
            if (channels == 5) d[4] = depth[static_cast<size_t>(h - 1 - y) * w + x];
        }
    }
    auto out = OIIO::ImageOutput::create(p);
    if (!out) return vxl_fail(nullptr, VXL_ERR_IO, "write_image: no writer for %s", path);
    OIIO::ImageSpec spec(static_cast<int>(w), static_cast<int>(h), channels,
                         exr ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8);
    spec.alpha_channel = 3;
    if (channels == 5) {
        spec.channelnames = {"R", "G", "B", "A", "Z"};
        spec.z_channel = 4;
        spec.channelformats = {OIIO::TypeDesc::HALF, OIIO::TypeDesc::HALF, OIIO::TypeDesc::HALF,
                               OIIO::TypeDesc::HALF, OIIO::TypeDesc::FLOAT};
    }
    if (exr) spec.attribute("oiio:UnassociatedAlpha", 0);
    if (!out->open(p, spec)) return vxl_fail(nullptr, VXL_ERR_IO, "write_image: cannot open %s for writing", path);
    bool ok = out->write_image(OIIO::TypeDesc::FLOAT, px.data());
    ok = out->close() && ok;
    if (!ok) return vxl_fail(nullptr, VXL_ERR_IO, "write_image: writing %s failed", path);
    return VXL_OK;
}
