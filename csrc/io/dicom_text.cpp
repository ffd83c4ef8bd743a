// dicom_text.cpp - the string helpers the DICOM reader's rooms share
// (dicom_series.hpp): printf into a std::string, and a path's parts.
#include "dicom_series.hpp"

#include <cstdarg>
#include <cstdio>

extern "C" {
#include "error.h"
#include "files.h"
}

namespace vxl_dicom {

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
    const char *s = vxl_path_last_separator(p.c_str());
    return s ? std::string(s + 1) : p;
}

std::string dirname_of(const std::string &p)
{
    const char *s = vxl_path_last_separator(p.c_str());
    if (!s) return ".";
    return s == p.c_str() ? p.substr(0, 1) : p.substr(0, size_t(s - p.c_str()));
}

} // namespace vxl_dicom
