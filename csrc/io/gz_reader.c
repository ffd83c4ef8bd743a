/* gz_reader.c - gz_reader.h: positioned reads of the file (vxl_file_pread)
 * feed inflate with gzip framing (windowBits 16 + 15); a file without the
 * gzip magic is read as it is. */
#include "gz_reader.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "files.h"
#include "zlib_api.h"

#define DEFAULT_BUFFER (64u * 1024u)
#define SKIP_CHUNK (64u * 1024u)
/* inflate's avail_out is an unsigned int: one call never asks for more. */
#define MAX_STEP (1u << 30)

struct vxl_gz {
    const vxl_zlib *z; /* NULL for a plain file */
    int fd;
    char *path;
    z_stream s;
    int stream_ready;  /* inflateInit2 done */
    int at_end;        /* the last member ended and nothing follows */
    unsigned char *in; /* compressed input */
    size_t in_size;
    uint64_t file_pos; /* next compressed byte to fetch */
    int file_done;     /* the file has no more bytes */
    uint64_t pos;      /* position in the uncompressed stream */
};

static const unsigned char gzip_magic[2] = {0x1f, 0x8b};

static int read_error(vxl_gz *f, vxl_err *e)
{
    return vxl_fail(e, VXL_ERR_IO, "read error in '%s': %s", f->path, strerror(errno));
}

static int corrupt(vxl_gz *f, const char *why, vxl_err *e)
{
    return vxl_fail(e, VXL_ERR_FORMAT, "corrupt compressed data in '%s': %s", f->path, why);
}

/* Moves the unread input to the front and appends from the file. */
static int fill(vxl_gz *f, vxl_err *e)
{
    if (f->file_done) return VXL_OK;
    if (f->s.avail_in && f->s.next_in != f->in) memmove(f->in, f->s.next_in, f->s.avail_in);
    f->s.next_in = f->in;
    size_t room = f->in_size - f->s.avail_in;
    int64_t got = vxl_file_pread(f->fd, f->in + f->s.avail_in, room, f->file_pos);
    if (got < 0) return read_error(f, e);
    if (got == 0) f->file_done = 1;
    f->file_pos += (uint64_t)got;
    f->s.avail_in += (unsigned)got;
    return VXL_OK;
}

/* Back to the start of the stream. */
static int restart(vxl_gz *f, vxl_err *e)
{
    f->pos = 0;
    f->at_end = 0;
    if (!f->z) return VXL_OK;
    f->file_pos = 0;
    f->file_done = 0;
    f->s.next_in = f->in;
    f->s.avail_in = 0;
    if (f->stream_ready) {
        if (f->z->inflateReset(&f->s) != Z_OK) return corrupt(f, "cannot reset the stream", e);
    } else {
        if (VXL_INFLATE_INIT2(f->z, &f->s, 16 + MAX_WBITS) != Z_OK)
            return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory inflating '%s'", f->path);
        f->stream_ready = 1;
    }
    return VXL_OK;
}

vxl_gz *vxl_gz_open(const char *path, size_t buffer_bytes, vxl_err *e)
{
    vxl_gz *f = calloc(1, sizeof *f);
    size_t n = strlen(path) + 1;
    if (!f || !(f->path = malloc(n))) {
        free(f);
        vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory opening '%s'", path);
        return NULL;
    }
    memcpy(f->path, path, n);
    f->fd = vxl_file_open_read(path, 1);
    if (f->fd < 0) {
        vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
        free(f->path);
        free(f);
        return NULL;
    }
    unsigned char head[2];
    int64_t got = vxl_file_pread(f->fd, head, sizeof head, 0);
    int rc = got < 0 ? read_error(f, e) : VXL_OK;
    if (!rc && got == 2 && !memcmp(head, gzip_magic, 2)) {
        f->in_size = buffer_bytes ? buffer_bytes : DEFAULT_BUFFER;
        if (!(f->z = vxl_zlib_api(e))) rc = VXL_ERR_IO;
        else if (!(f->in = malloc(f->in_size)))
            rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory opening '%s'", path);
        else rc = restart(f, e);
    }
    if (rc) {
        vxl_gz_close(f);
        return NULL;
    }
    return f;
}

/* One inflate step into out[0..n), *made bytes (0 only at the end). */
static int inflate_some(vxl_gz *f, unsigned char *out, size_t n, size_t *made, vxl_err *e)
{
    *made = 0;
    while (!f->at_end) {
        int rc = f->s.avail_in == 0 ? fill(f, e) : VXL_OK;
        if (rc) return rc;
        if (f->s.avail_in == 0 && f->file_done)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': truncated file: it ends inside its compressed data", f->path);
        f->s.next_out = out;
        f->s.avail_out = (unsigned)(n > MAX_STEP ? MAX_STEP : n);
        int z = f->z->inflate(&f->s, Z_NO_FLUSH);
        *made = (size_t)(f->s.next_out - out);
        if (z == Z_STREAM_END) {
            /* another gzip member may follow (gzip's concatenation); anything
             * else after the end is ignored, as gzip itself does */
            if (f->s.avail_in < 2 && (rc = fill(f, e))) return rc;
            if (f->s.avail_in >= 2 && !memcmp(f->s.next_in, gzip_magic, 2)) {
                if (f->z->inflateReset(&f->s) != Z_OK) return corrupt(f, "cannot reset the stream", e);
            } else {
                f->at_end = 1;
            }
        } else if (z == Z_MEM_ERROR) {
            return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory inflating '%s'", f->path);
        } else if (z != Z_OK && z != Z_BUF_ERROR) {
            return corrupt(f, f->s.msg ? f->s.msg : "invalid data", e);
        }
        if (*made) break;
    }
    return VXL_OK;
}

int vxl_gz_read(vxl_gz *f, void *buf, size_t n, size_t *got, vxl_err *e)
{
    unsigned char *out = buf;
    *got = 0;
    while (*got < n) {
        size_t made = 0;
        if (!f->z) {
            int64_t r = vxl_file_pread(f->fd, out + *got, n - *got, f->pos);
            if (r < 0) return read_error(f, e);
            made = (size_t)r;
        } else {
            int rc = inflate_some(f, out + *got, n - *got, &made, e);
            if (rc) return rc;
        }
        if (made == 0) break;
        *got += made;
        f->pos += made;
    }
    return VXL_OK;
}

int vxl_gz_seek(vxl_gz *f, uint64_t offset, vxl_err *e)
{
    if (!f->z) {
        f->pos = offset;
        return VXL_OK;
    }
    int rc = offset < f->pos ? restart(f, e) : VXL_OK;
    unsigned char *scratch = NULL;
    if (!rc && f->pos < offset && !(scratch = malloc(SKIP_CHUNK)))
        rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory reading '%s'", f->path);
    while (!rc && f->pos < offset) {
        uint64_t left = offset - f->pos;
        size_t got;
        rc = vxl_gz_read(f, scratch, left < SKIP_CHUNK ? (size_t)left : SKIP_CHUNK, &got, e);
        if (!rc && got == 0) break; /* past the end: the next read is short */
    }
    free(scratch);
    return rc;
}

int vxl_gz_direct(const vxl_gz *f) { return f->z == NULL; }

void vxl_gz_close(vxl_gz *f)
{
    if (!f) return;
    if (f->stream_ready) f->z->inflateEnd(&f->s);
    if (f->fd >= 0) vxl_file_close(f->fd);
    free(f->in);
    free(f->path);
    free(f);
}
