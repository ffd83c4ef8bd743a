// environment_exr.cpp - an OpenEXR World map through OpenImageIO, for
// vxl_environment_image_load: OpenEXR's codecs (PIZ, ZIP, DWA, B44, ...) are
// a large library that OpenImageIO already brings into the voxlight-read-oiio
// helper, so the library keeps its own Radiance reader and hands .exr files
// to the helper (reader_stream.h, VXL_REPLY_IMAGE).
//
// What it returns: the first image's first three channels as linear float
// RGB (a one- or two-channel image's first channel as grey), row 0 at the
// bottom as hdr_read.c returns Radiance files. A map is radiance, so a
// negative value (which resampling filters leave beside bright pixels) is
// light that cannot exist and is read as 0; NaN or infinity is an error
// naming how many, since no value stands in for it. Sizes are checked
// against max_pixels before any pixel is allocated.
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

extern "C" {
#include "helper_main.h"
#include "loader_util.h"
}

extern "C" int vxl_environment_exr_read(const char *path, uint64_t max_pixels, float **rgb, uint32_t *width,
                                        uint32_t *height, vxl_err *e)
{
    *rgb = nullptr;
    *width = *height = 0;
    try {
        auto in = OIIO::ImageInput::open(path);
        if (!in) {
            std::string msg = OIIO::geterror();
            vxl_one_line(&msg[0]);
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %s", path, msg.empty() ? "cannot be opened" : msg.c_str());
        }
        const OIIO::ImageSpec &spec = in->spec();
        if (spec.deep || spec.depth != 1 || spec.width < 1 || spec.height < 1 || spec.nchannels < 1)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': not a flat 2D image (%dx%dx%d, %d channels%s)", path,
                            spec.width, spec.height, spec.depth, spec.nchannels, spec.deep ? ", deep" : "");
        const uint64_t n = static_cast<uint64_t>(spec.width) * static_cast<uint64_t>(spec.height);
        if (n > max_pixels)
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s': %dx%d pixels, more than an environment map may have (%llu)",
                            path, spec.width, spec.height, static_cast<unsigned long long>(max_pixels));
        const int nread = spec.nchannels >= 3 ? 3 : 1;
        std::vector<float> px(static_cast<size_t>(n) * static_cast<size_t>(nread));
        if (!in->read_image(0, 0, 0, nread, OIIO::TypeDesc::FLOAT, px.data())) {
            std::string msg = in->geterror();
            vxl_one_line(&msg[0]);
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': cannot read pixels: %s", path,
                            msg.empty() ? "unknown error" : msg.c_str());
        }
        in->close();
        float *out = static_cast<float *>(std::malloc(static_cast<size_t>(n) * 3 * sizeof(float)));
        if (!out) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': no memory for %llu pixels", path,
                                  static_cast<unsigned long long>(n));
        const size_t w = static_cast<size_t>(spec.width), h = static_cast<size_t>(spec.height);
        uint64_t bad = 0;
        for (size_t y = 0; y < h; y++)
            for (size_t x = 0; x < w; x++)
                for (size_t c = 0; c < 3; c++) {
                    // files store the top row first; the map's row 0 is the bottom
                    float v = px[((h - 1 - y) * w + x) * nread + (nread == 3 ? c : 0)];
                    if (!std::isfinite(v)) bad++;
                    out[(y * w + x) * 3 + c] = v > 0.0f ? v : 0.0f;
                }
        if (bad) {
            std::free(out);
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %llu values are NaN or infinite; an environment map holds "
                            "radiance, which is finite", path, static_cast<unsigned long long>(bad));
        }
        *rgb = out;
        *width = static_cast<uint32_t>(spec.width);
        *height = static_cast<uint32_t>(spec.height);
        return VXL_OK;
    } catch (const std::bad_alloc &) {
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': the image reader ran out of memory", path);
    } catch (const std::exception &x) {
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %s", path, x.what());
    }
}
