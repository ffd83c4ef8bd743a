/* os_win32.c - os.h on Windows. */
#include "os.h"

const char *vxl_os_name(void) { return "windows"; }
