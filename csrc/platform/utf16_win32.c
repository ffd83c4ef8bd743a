/* utf16_win32.c - utf16_win32.h. Invalid UTF-8 is refused, never guessed. */
#include "utf16_win32.h"

#include <windows.h>

int vxl_utf8_to_utf16(const char *s, wchar_t *out, int size)
{
    return MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, s, -1, out, size) > 0;
}

int vxl_utf16_to_utf8(const wchar_t *s, char *out, int size)
{
    return WideCharToMultiByte(CP_UTF8, 0, s, -1, out, size, NULL, NULL) > 0;
}
