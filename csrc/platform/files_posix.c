/* files_posix.c - files.h on POSIX systems. Paths are bytes, which on Linux
 * is UTF-8 as Blender passes them. */
#include "files.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static void fill(const struct stat *st, vxl_path_info *out)
{
    out->kind = S_ISREG(st->st_mode) ? VXL_PATH_FILE : S_ISDIR(st->st_mode) ? VXL_PATH_DIR : VXL_PATH_OTHER;
    out->size = st->st_size > 0 ? (uint64_t)st->st_size : 0;
    out->mtime_ns = (int64_t)st->st_mtim.tv_sec * 1000000000 + st->st_mtim.tv_nsec;
}

int vxl_path_stat(const char *path, vxl_path_info *out)
{
    struct stat st;
    memset(out, 0, sizeof *out);
    if (stat(path, &st) != 0) return -1;
    fill(&st, out);
    return 0;
}

int vxl_file_open_read(const char *path, int nonblock)
{
    return open(path, O_RDONLY | O_CLOEXEC | (nonblock ? O_NONBLOCK : 0));
}

int vxl_file_stat(int fd, vxl_path_info *out)
{
    struct stat st;
    memset(out, 0, sizeof *out);
    if (fstat(fd, &st) != 0) return -1;
    fill(&st, out);
    return 0;
}

void vxl_file_close(int fd)
{
    if (fd >= 0) close(fd);
}

int64_t vxl_file_pread(int fd, void *buf, size_t n, uint64_t offset)
{
    if (offset > (uint64_t)INT64_MAX) {
        errno = EINVAL;
        return -1;
    }
    return (int64_t)pread(fd, buf, n, (off_t)offset);
}

int vxl_file_data_extent(int fd, uint64_t from, uint64_t *data, uint64_t *hole)
{
    if (from > (uint64_t)INT64_MAX) return 0;
    off_t d = lseek(fd, (off_t)from, SEEK_DATA);
    if (d < 0) return errno == ENXIO ? -1 : 0;
    off_t h = lseek(fd, d, SEEK_HOLE);
    *data = (uint64_t)d;
    *hole = h < d ? UINT64_MAX : (uint64_t)h;
    return 1;
}

FILE *vxl_fopen(const char *path, const char *mode)
{
    char m[16];
    /* "e": O_CLOEXEC, so a reader helper started meanwhile inherits nothing */
    if (snprintf(m, sizeof m, "%se", mode) >= (int)sizeof m) return NULL;
    return fopen(path, m);
}

int vxl_fseek(FILE *f, uint64_t offset)
{
    if (offset > (uint64_t)INT64_MAX) {
        errno = EINVAL;
        return -1;
    }
    return fseeko(f, (off_t)offset, SEEK_SET);
}

int vxl_fsync(FILE *f) { return fflush(f) != 0 || fsync(fileno(f)) != 0 ? -1 : 0; }

FILE *vxl_temp_file(char *tmpl)
{
    int fd = mkstemp(tmpl);
    if (fd < 0) return NULL;
    fchmod(fd, 0644);
    fcntl(fd, F_SETFD, FD_CLOEXEC);
    FILE *f = fdopen(fd, "wb");
    if (!f) {
        int err = errno;
        close(fd);
        unlink(tmpl);
        errno = err;
    }
    return f;
}

int vxl_rename(const char *from, const char *to) { return rename(from, to); }
int vxl_remove(const char *path) { return unlink(path); }

int vxl_mkdir(const char *path)
{
    if (mkdir(path, 0755) == 0 || errno == EEXIST) return vxl_is_dir(path) ? 0 : -1;
    return -1;
}

int vxl_dir_writable(const char *folder) { return access(folder, W_OK) == 0; }

int vxl_path_is_absolute(const char *path) { return path && path[0] == '/'; }

int vxl_user_cache_dir(char *out, size_t size)
{
    const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    int n;
    if (xdg && xdg[0] == '/') n = snprintf(out, size, "%s/voxlight", xdg);
    else if (home && home[0]) n = snprintf(out, size, "%s/.cache/voxlight", home);
    else return -1;
    return n > 0 && (size_t)n < size ? 0 : -1;
}

char *vxl_real_path(const char *path, char *out, size_t size)
{
    char *r = realpath(path, NULL);
    if (!r) return NULL;
    const int fits = strlen(r) < size;
    if (fits) memcpy(out, r, strlen(r) + 1);
    free(r);
    return fits ? out : NULL;
}

struct vxl_dir {
    DIR *d;
};

vxl_dir *vxl_dir_open(const char *path)
{
    DIR *d = opendir(path);
    if (!d) return NULL;
    vxl_dir *v = malloc(sizeof *v);
    if (!v) {
        closedir(d);
        errno = ENOMEM;
        return NULL;
    }
    v->d = d;
    return v;
}

const char *vxl_dir_next(vxl_dir *v)
{
    struct dirent *e;
    while ((e = readdir(v->d)) != NULL)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) return e->d_name;
    return NULL;
}

void vxl_dir_close(vxl_dir *v)
{
    if (!v) return;
    closedir(v->d);
    free(v);
}
