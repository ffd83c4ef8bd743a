/* files_win32.c - files.h on Windows: every path goes from UTF-8 to UTF-16
 * and through the wide-character calls, so C:\Users\José\Scans opens; no
 * descriptor or FILE is inherited by child processes. */
#include "files.h"

#include <errno.h>
#include <fcntl.h>
#include <io.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <windows.h>

#include "utf16_win32.h"

/* A path's UTF-16 form in a buffer of VXL_WPATH, or NULL (errno). */
static wchar_t *wide(const char *path)
{
    wchar_t *w = malloc(VXL_WPATH * sizeof *w);
    if (!w) {
        errno = ENOMEM;
        return NULL;
    }
    if (!vxl_utf8_to_utf16(path, w, VXL_WPATH)) {
        free(w);
        errno = EINVAL;
        return NULL;
    }
    return w;
}

static void fill(const struct _stat64 *st, vxl_path_info *out)
{
    out->kind = (st->st_mode & _S_IFMT) == _S_IFREG   ? VXL_PATH_FILE
                : (st->st_mode & _S_IFMT) == _S_IFDIR ? VXL_PATH_DIR
                                                      : VXL_PATH_OTHER;
    out->size = st->st_size > 0 ? (uint64_t)st->st_size : 0;
    out->mtime_ns = (int64_t)st->st_mtime * 1000000000;
}

int vxl_path_stat(const char *path, vxl_path_info *out)
{
    memset(out, 0, sizeof *out);
    wchar_t *w = wide(path);
    if (!w) return -1;
    struct _stat64 st;
    int rc = _wstat64(w, &st);
    free(w);
    if (rc != 0) return -1;
    fill(&st, out);
    return 0;
}

int vxl_file_open_read(const char *path, int nonblock)
{
    (void)nonblock; /* Windows has no FIFOs in the file system */
    wchar_t *w = wide(path);
    if (!w) return -1;
    int fd = _wopen(w, _O_RDONLY | _O_BINARY | _O_NOINHERIT);
    free(w);
    return fd;
}

int vxl_file_stat(int fd, vxl_path_info *out)
{
    memset(out, 0, sizeof *out);
    struct _stat64 st;
    if (_fstat64(fd, &st) != 0) return -1;
    fill(&st, out);
    return 0;
}

void vxl_file_close(int fd)
{
    if (fd >= 0) _close(fd);
}

int64_t vxl_file_pread(int fd, void *buf, size_t n, uint64_t offset)
{
    HANDLE h = (HANDLE)_get_osfhandle(fd);
    if (h == INVALID_HANDLE_VALUE) {
        errno = EBADF;
        return -1;
    }
    OVERLAPPED ov;
    memset(&ov, 0, sizeof ov);
    ov.Offset = (DWORD)offset;
    ov.OffsetHigh = (DWORD)(offset >> 32);
    DWORD got = 0;
    const DWORD want = n > (1u << 30) ? (1u << 30) : (DWORD)n;
    if (!ReadFile(h, buf, want, &got, &ov)) {
        if (GetLastError() == ERROR_HANDLE_EOF) return 0;
        errno = EIO;
        return -1;
    }
    return (int64_t)got;
}

int vxl_file_data_extent(int fd, uint64_t from, uint64_t *data, uint64_t *hole)
{
    (void)fd;
    (void)from;
    (void)data;
    (void)hole;
    return 0; /* read it all: the sparse files this skips are a Linux scanner's */
}

FILE *vxl_fopen(const char *path, const char *mode)
{
    wchar_t m[16];
    char nm[16];
    /* "N": not inherited by child processes */
    if (snprintf(nm, sizeof nm, "%sN", mode) >= (int)sizeof nm || !vxl_utf8_to_utf16(nm, m, 16)) {
        errno = EINVAL;
        return NULL;
    }
    wchar_t *w = wide(path);
    if (!w) return NULL;
    FILE *f = _wfopen(w, m);
    free(w);
    return f;
}

int vxl_fseek(FILE *f, uint64_t offset)
{
    if (offset > (uint64_t)INT64_MAX) {
        errno = EINVAL;
        return -1;
    }
    return _fseeki64(f, (__int64)offset, SEEK_SET);
}

int vxl_fsync(FILE *f) { return fflush(f) != 0 || _commit(_fileno(f)) != 0 ? -1 : 0; }

FILE *vxl_temp_file(char *tmpl)
{
    const size_t n = strlen(tmpl);
    if (n < 6 || strcmp(tmpl + n - 6, "XXXXXX")) {
        errno = EINVAL;
        return NULL;
    }
    static const char digits[] = "0123456789abcdefghijklmnopqrstuvwxyz";
    unsigned long long seed = GetTickCount64() ^ ((unsigned long long)GetCurrentProcessId() << 32) ^ (uintptr_t)tmpl;
    for (int attempt = 0; attempt < 100; attempt++) {
        for (int i = 0; i < 6; i++) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            tmpl[n - 6 + i] = digits[(seed >> 33) % 36];
        }
        wchar_t *w = wide(tmpl);
        if (!w) return NULL;
        int fd = _wopen(w, _O_CREAT | _O_EXCL | _O_WRONLY | _O_BINARY | _O_NOINHERIT, _S_IREAD | _S_IWRITE);
        free(w);
        if (fd < 0 && errno == EEXIST) continue;
        if (fd < 0) return NULL;
        FILE *f = _fdopen(fd, "wb");
        if (!f) {
            int err = errno;
            _close(fd);
            vxl_remove(tmpl);
            errno = err;
        }
        return f;
    }
    errno = EEXIST;
    return NULL;
}

int vxl_rename(const char *from, const char *to)
{
    wchar_t *a = wide(from), *b = a ? wide(to) : NULL;
    int ok = a && b && MoveFileExW(a, b, MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH);
    if (a && b && !ok) errno = EACCES;
    free(a);
    free(b);
    return ok ? 0 : -1;
}

int vxl_remove(const char *path)
{
    wchar_t *w = wide(path);
    if (!w) return -1;
    int rc = _wunlink(w);
    free(w);
    return rc;
}

int vxl_mkdir(const char *path)
{
    wchar_t *w = wide(path);
    if (!w) return -1;
    int rc = _wmkdir(w);
    free(w);
    if (rc == 0 || errno == EEXIST) return vxl_is_dir(path) ? 0 : -1;
    return -1;
}

int vxl_dir_writable(const char *folder)
{
    wchar_t *w = wide(folder);
    if (!w) return 0;
    int ok = _waccess(w, 2) == 0;
    free(w);
    return ok;
}

int vxl_path_is_absolute(const char *path)
{
    if (!path || !path[0]) return 0;
    if (vxl_path_is_separator(path[0])) return 1; /* \\server\\share or the current drive's root */
    const char c = (char)(path[0] | 32);
    return c >= 'a' && c <= 'z' && path[1] == ':' && vxl_path_is_separator(path[2]);
}

int vxl_user_cache_dir(char *out, size_t size)
{
    /* read in UTF-16: a user name outside the ANSI code page stays whole */
    const wchar_t *local = _wgetenv(L"LOCALAPPDATA");
    if (!local || !local[0] || !vxl_utf16_to_utf8(local, out, (int)size)) return -1;
    const size_t n = strlen(out);
    if (n + sizeof "\\voxlight" > size) return -1;
    memcpy(out + n, "\\voxlight", sizeof "\\voxlight");
    return 0;
}

char *vxl_real_path(const char *path, char *out, size_t size)
{
    wchar_t *w = wide(path), *full = w ? malloc(VXL_WPATH * sizeof *full) : NULL;
    char *r = NULL;
    if (full && _wfullpath(full, w, VXL_WPATH) && vxl_utf16_to_utf8(full, out, (int)size)) r = out;
    free(w);
    free(full);
    return r;
}

struct vxl_dir {
    HANDLE h;
    WIN32_FIND_DATAW entry;
    int first; /* entry holds the first name, not yet returned */
    char name[MAX_PATH * 4];
};

vxl_dir *vxl_dir_open(const char *path)
{
    char pattern[4200];
    if (snprintf(pattern, sizeof pattern, "%s\\*", path) >= (int)sizeof pattern) {
        errno = ENAMETOOLONG;
        return NULL;
    }
    wchar_t *w = wide(pattern);
    if (!w) return NULL;
    vxl_dir *d = calloc(1, sizeof *d);
    if (d) d->h = FindFirstFileW(w, &d->entry);
    free(w);
    if (!d) {
        errno = ENOMEM;
        return NULL;
    }
    if (d->h == INVALID_HANDLE_VALUE) {
        free(d);
        errno = ENOENT;
        return NULL;
    }
    d->first = 1;
    return d;
}

const char *vxl_dir_next(vxl_dir *d)
{
    for (;;) {
        if (!d->first && !FindNextFileW(d->h, &d->entry)) return NULL;
        d->first = 0;
        if (!wcscmp(d->entry.cFileName, L".") || !wcscmp(d->entry.cFileName, L"..")) continue;
        if (vxl_utf16_to_utf8(d->entry.cFileName, d->name, (int)sizeof d->name)) return d->name;
    }
}

void vxl_dir_close(vxl_dir *d)
{
    if (!d) return;
    FindClose(d->h);
    free(d);
}
