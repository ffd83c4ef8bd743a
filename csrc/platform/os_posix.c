/* os_posix.c - os.h on POSIX systems. */
#include "os.h"

const char *vxl_os_name(void) { return "posix"; }
