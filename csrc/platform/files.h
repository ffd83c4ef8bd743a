/* files.h - files and folders by UTF-8 path: the library's one seam to the
 * OS's file system (files_posix.c). Failures return -1 (or NULL) with errno
 * set, so callers report strerror(errno) as with the C library. Nothing
 * else calls open, stat, pread, lseek, mkstemp, rename, opendir or
 * realpath. */
#ifndef VXL_FILES_H
#define VXL_FILES_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

enum { VXL_PATH_NONE = 0, VXL_PATH_FILE = 1, VXL_PATH_DIR = 2, VXL_PATH_OTHER = 3 };

typedef struct vxl_path_info {
    int kind;          /* VXL_PATH_* */
    uint64_t size;     /* bytes, for a file */
    int64_t mtime_ns;  /* last modification, nanoseconds since 1970 */
} vxl_path_info;

/* What is at path (following links); -1 when nothing is (errno). */
int vxl_path_stat(const char *path, vxl_path_info *out);
/* 1 when path is a regular file, a folder respectively; 0 otherwise. */
int vxl_is_file(const char *path);
int vxl_is_dir(const char *path);

/* A descriptor for positioned reads, not inherited by child processes;
 * nonblock: opening a FIFO in a file's place does not wait for a writer. */
int vxl_file_open_read(const char *path, int nonblock);
int vxl_file_stat(int fd, vxl_path_info *out);
void vxl_file_close(int fd);
/* Up to n bytes at offset; the count read (0 at the end), or -1. */
int64_t vxl_file_pread(int fd, void *buf, size_t n, uint64_t offset);
/* The next data extent at or after `from` of a file with holes: 1 with
 * [*data, *hole) (*hole UINT64_MAX when the system cannot say where it
 * ends), -1 when only a hole follows, 0 when the file system cannot tell
 * (read it all). */
int vxl_file_data_extent(int fd, uint64_t from, uint64_t *data, uint64_t *hole);

/* fopen with a UTF-8 path; not inherited by child processes. */
FILE *vxl_fopen(const char *path, const char *mode);
/* fseek to a 64-bit offset from the start; 0 or -1. */
int vxl_fseek(FILE *f, uint64_t offset);
/* The written data on the disk (fflush, then the OS's sync); 0 or -1. */
int vxl_fsync(FILE *f);

/* A new file for writing named after tmpl ("...XXXXXX", the X's replaced
 * in place), readable by all, or NULL. */
FILE *vxl_temp_file(char *tmpl);
/* Renames from to to, replacing to (atomically where the OS can). */
int vxl_rename(const char *from, const char *to);
int vxl_remove(const char *path);
/* A folder; 0 when made or already there. */
int vxl_mkdir(const char *path);
/* 1 when the process may create files in folder. */
int vxl_dir_writable(const char *folder);
/* The absolute, resolved form of path into out; NULL when it cannot. */
char *vxl_real_path(const char *path, char *out, size_t size);

/* The last folder separator of path, '/' or '\\' (Windows takes both), or
 * NULL when it has none. */
const char *vxl_path_last_separator(const char *path);
/* 1 when c separates folders ('/', and '\\' too: Windows takes both). */
int vxl_path_is_separator(char c);
/* 1 when path names a file without a base folder: "/a" on POSIX; "C:\\a",
 * "C:/a", "\\\\server\\a" or "\\a" on Windows. */
int vxl_path_is_absolute(const char *path);
/* The per-user folder for Voxlight's caches into out (no trailing
 * separator): $XDG_CACHE_HOME/voxlight or $HOME/.cache/voxlight on POSIX,
 * %LOCALAPPDATA%\\voxlight on Windows. 0, or -1 when the OS names none. */
int vxl_user_cache_dir(char *out, size_t size);

/* A folder's entries, "." and ".." left out. */
typedef struct vxl_dir vxl_dir;
vxl_dir *vxl_dir_open(const char *path);
const char *vxl_dir_next(vxl_dir *d); /* NULL at the end */
void vxl_dir_close(vxl_dir *d);

#endif
