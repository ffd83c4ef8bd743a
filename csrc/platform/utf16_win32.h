/* utf16_win32.h - UTF-8 paths (what the library takes everywhere) to and
 * from Windows' UTF-16, for the Windows files of the platform room. */
#ifndef VXL_UTF16_WIN32_H
#define VXL_UTF16_WIN32_H

#include <wchar.h>

/* 1 when s fits into out (size wide characters, NUL included), else 0. */
int vxl_utf8_to_utf16(const char *s, wchar_t *out, int size);
int vxl_utf16_to_utf8(const wchar_t *s, char *out, int size);

/* Room for the longest path Windows takes with the \\?\ prefix. */
#define VXL_WPATH 32768

#endif
