/* os_posix.c - os.h on POSIX systems. */
#include <stdlib.h>
#include <unistd.h>

#include "os.h"

const char *vxl_os_name(void) { return "posix"; }
int vxl_os_has_debian_libraries(void) { return 1; }
const char *vxl_os_zlib_name(void) { return "libz.so.1"; }
const char *vxl_os_openjpeg_name(void) { return "libopenjp2.so.7"; }

int vxl_os_utf8_args(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    return 0; /* the bytes the shell passed are the file system's names */
}

int vxl_os_is_terminal(FILE *f) { return isatty(fileno(f)); }

int vxl_os_set_env(const char *name, const char *value)
{
    return value ? setenv(name, value, 1) : unsetenv(name);
}
