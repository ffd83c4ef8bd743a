/* os.h - which operating system the platform room was built for: tests and
 * messages that must name a system library or rule (os_posix.c, or the
 * Windows file). */
#ifndef VXL_OS_H
#define VXL_OS_H

#include <stdio.h>

/* "posix" or "windows". */
const char *vxl_os_name(void);

/* The file name under which this OS's zlib is opened (dynlib.h): the
 * system's libz.so.1, or on Windows, which has none, the zlib1.dll shipped
 * beside voxlight.dll. */
const char *vxl_os_zlib_name(void);

/* The file name under which this OS's OpenJPEG is opened for JPEG 2000
 * frames (io/dicom_j2k.c): Debian's libopenjp2.so.7 (package libopenjp2-7),
 * or openjp2.dll, looked for beside voxlight.dll, on Windows. */
const char *vxl_os_openjpeg_name(void);

/* 1 where the libraries of Debian's packages that some readers link or open
 * (OpenImageIO, dcmtk, libblosc, libzstd) can be present: POSIX systems; 0
 * on Windows, where no build of them is shipped. */
int vxl_os_has_debian_libraries(void);

/* A program's arguments as UTF-8, as every path the library takes is: on
 * Windows main's are in the ANSI code page (José's folder would not open),
 * so they are replaced by the command line's wide characters, converted
 * (kept for the program's life); elsewhere they already are. 0, or -1 when
 * they cannot be converted (argv is then left as it was). For programs'
 * main only. */
int vxl_os_utf8_args(int *argc, char ***argv);

/* 1 when f is a terminal (a console on Windows): progress may then redraw
 * one line. */
int vxl_os_is_terminal(FILE *f);

/* Sets the variable for this process (its C runtime's getenv included);
 * value NULL removes it. 0 or -1. For tests and programs: the library only
 * reads its environment. */
int vxl_os_set_env(const char *name, const char *value);

#endif
