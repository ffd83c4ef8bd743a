/* os.h - which operating system the platform room was built for: tests and
 * messages that must name a system library or rule (os_posix.c, or the
 * Windows file). */
#ifndef VXL_OS_H
#define VXL_OS_H

/* "posix" or "windows". */
const char *vxl_os_name(void);

#endif
