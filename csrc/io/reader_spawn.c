/* reader_spawn.c - vxl_reader_run: one command of a reader helper process.
 *
 * The readers that need OpenImageIO or dcmtk run in helper processes found
 * next to libvoxlight.so (reader_stream.h): the library then links only the
 * C runtime, a missing library breaks only its own formats, and a reader
 * that crashes (Debian's libopenvdb aborts on some corrupt files,
 * tests/fuzz/upstream/README.md) cannot end the host's (Blender's) session.
 * The helper is started as a child process (platform/process.h) and
 * streams a header and a body over a pipe. Here
 * the header is checked and a volume's size passes the memory budget
 * before anything is allocated, a short stream is an error, a crash becomes
 * a message naming the signal, a library the dynamic loader cannot find
 * becomes a message naming it and its Debian package, a hung helper is
 * killed after a time limit scaled with the input's size, and the child is
 * always reaped. Nothing is ever written to the child, so SIGPIPE cannot
 * reach this process. There is no in-process fallback. */
#include "reader_spawn.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "channel_volume.h"
#include "colour_volume.h"
#include "dynlib.h"
#include "files.h"
#include "os.h"
#include "process.h"
#include "loader_util.h"

#define STDERR_KEEP 600          /* the tail of the helper's stderr quoted in errors */
#define MAX_SERIES 100000u       /* dicom.cpp scans at most this many files */
#define LOADER_SAYS "error while loading shared libraries: "

int vxl_reader_runs_here(const vxl_reader *r) { return !r->linux_only || vxl_os_has_debian_libraries(); }

static int helper_path(const vxl_reader *r, const char *path, char *out, size_t n, vxl_err *e)
{
    const char *env = getenv(r->env);
    if (env && *env) {
        if (snprintf(out, n, "%s", env) >= (int)n)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "%s is too long", r->env);
    } else {
        if (!vxl_reader_runs_here(r))
            return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s are not read on Windows yet: their reader needs %s, "
                            "which has no Windows build here (Windows reads NIfTI, NRRD, MetaImage, OME-Zarr, DICOM "
                            "and uncompressed multi-page TIFF, streamed)", path, r->formats, r->library);
        char self[4096];
        if (vxl_dynlib_path_of((const void *)&vxl_reader_run, self, sizeof self))
            return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': cannot locate libvoxlight to find %s", path,
                            r->helper);
        /* the helper sits beside the library */
        const char *slash = vxl_path_last_separator(self);
        int dir_len = slash ? (int)(slash - self) : 1;
        if (snprintf(out, n, "%.*s/%s%s", dir_len, slash ? self : ".", r->helper, vxl_program_suffix()) >= (int)n)
            return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': the path of %s is too long", path, r->helper);
    }
    vxl_path_info st;
    if (vxl_path_stat(out, &st) != 0)
        return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': %s are read by the helper program %s, which is missing "
                        "(it belongs next to the library: reinstall the add-on)", path, r->formats, out);
    if (!vxl_is_program(out))
        return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': the helper program %s that reads %s is not executable "
                        "(chmod +x it)", path, out, r->formats);
    return VXL_OK;
}

/* Seconds the helper may take: generous (OpenVDB decompresses every grid, a
 * DICOM folder is parsed file by file), one minute plus a second per 4 MiB
 * of input. */
static double time_limit(uint64_t input_bytes)
{
    const char *env = getenv(VXL_READER_TIMEOUT_ENV);
    if (env && *env) {
        char *end;
        double s = strtod(env, &end);
        if (!*end && isfinite(s) && s > 0) return s;
    }
    return 60.0 + (double)(input_bytes >> 22);
}

/* What came back over the two pipes. */
typedef struct reply {
    vxl_reader_header h;
    size_t h_got;
    char *body;            /* the message or the body, once the header passed */
    uint64_t body_len, body_got;
    uint8_t *colour;       /* a colour volume's RGB8, after the body */
    uint64_t colour_len, colour_got;
    uint16_t *channels;    /* a multi-channel volume's packed channels, after the colour */
    uint64_t channels_len, channels_got;
    int extra;             /* bytes after the announced end */
    char err_tail[STDERR_KEEP + 1];
    size_t err_len;
} reply;

static void keep_stderr(reply *r, const char *buf, size_t n)
{
    if (n >= STDERR_KEEP) {
        memcpy(r->err_tail, buf + n - STDERR_KEEP, STDERR_KEEP);
        r->err_len = STDERR_KEEP;
    } else {
        size_t drop = r->err_len + n > STDERR_KEEP ? r->err_len + n - STDERR_KEEP : 0;
        memmove(r->err_tail, r->err_tail + drop, r->err_len - drop);
        memcpy(r->err_tail + r->err_len - drop, buf, n);
        r->err_len += n - drop;
    }
    r->err_tail[r->err_len] = '\0';
}

static int all_finite(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* The notes reach a terminal and Blender's UI: terminated inside the array
 * and free of control characters (UTF-8's bytes above 0x7f pass). */
static int notes_ok(const char *notes, size_t cap)
{
    const char *end = memchr(notes, 0, cap);
    if (!end) return 0;
    for (const char *c = notes; c < end; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f) return 0;
    return 1;
}

/* A channel's metadata: a terminated name of text, a colour in [0, 1], an
 * ordered finite window, flags 0 or 1. */
static int channel_meta_ok(const vxl_channel_meta *m)
{
    if (!notes_ok(m->name, sizeof m->name) || m->has_color > 1 || m->has_window > 1 || m->hidden > 1 || m->reserved)
        return 0;
    for (int k = 0; k < 3; k++)
        if (!(m->color_srgb[k] >= 0.0f && m->color_srgb[k] <= 1.0f)) return 0;
    return all_finite(m->window, 2) && (!m->has_window || m->window[0] < m->window[1]);
}

/* A multi-channel volume's part of the header: 0 or 2..VXL_MAX_CHANNELS
 * channels, the scalar among them, their ranges and metadata sane, and
 * exactly 2 bytes a channel a voxel; unused slots all zero. */
static int check_channel_header(const vxl_reader *r, const char *path, const vxl_reader_header *h, uint64_t voxels,
                                vxl_err *e)
{
    const uint32_t n = h->channel_count;
    int ok = n == 0 ? h->scalar_channel == 0 && h->channel_bytes == 0
                    : n >= 2 && n <= VXL_MAX_CHANNELS && h->scalar_channel < n && h->components == 1 &&
                          h->channel_bytes == voxels * n * VXL_CHANNEL_BYTES;
    static const vxl_channel_meta none;
    for (uint32_t c = 0; ok && c < VXL_MAX_CHANNELS; c++) {
        const double range[4] = {h->ch_tex_lo[c], h->ch_tex_hi[c], h->ch_min[c], h->ch_max[c]};
        if (c >= n) ok = !memcmp(&h->ch_meta[c], &none, sizeof none) && !range[0] && !range[1] && !range[2] &&
                         !range[3];
        else ok = all_finite(range, 4) && range[2] <= range[3] && channel_meta_ok(&h->ch_meta[c]);
    }
    if (!ok)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent an inconsistent multi-channel header "
                        "(%u channels, scalar %u, %llu channel bytes)", path, r->name, n, h->scalar_channel,
                        (unsigned long long)h->channel_bytes);
    return VXL_OK;
}

/* A volume header: every field the rebuilt vxl_volume will hold. */
static int check_volume_header(const vxl_reader *r, const char *path, const vxl_reader_header *h,
                               const vxl_load_options *opt, vxl_err *e)
{
    if (!vxl_dtype_size(h->src_dtype) || h->texture_bits != vxl_texture_bits_for(h->src_dtype))
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent data type %u with %u-bit texels", path,
                        r->name, h->src_dtype, h->texture_bits);
    /* a colour volume: RGB or RGBA whose scalar is the opacity source asked
     * for, and 3 bytes a voxel of colour, charged to the budget with the
     * texels as vxl_volume_build_colour charges them in process */
    const int colour = h->components != 1;
    uint32_t source, channel;
    vxl_load_opacity_source(opt, &source, &channel);
    if (colour ? (h->components != 3 && h->components != 4) || h->opacity_source != source
               : h->opacity_source != 0 || h->colour_bytes != 0)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent %u components with opacity source %u "
                        "(asked for %u) and %llu colour bytes", path, r->name, h->components, h->opacity_source,
                        source, (unsigned long long)h->colour_bytes);
    vxl_err inner = {0};
    /* everything the volume will hold, before any of it is allocated (a
     * channel count over the limit is refused below, after dims are sane) */
    const uint32_t channel_voxel_bytes =
        h->channel_count <= VXL_MAX_CHANNELS ? h->channel_count * VXL_CHANNEL_BYTES : 0;
    if (vxl_volume_check_limits(h->dims, h->texture_bits / 8 + (colour ? VXL_COLOUR_BYTES_PER_VOXEL : 0) +
                                             channel_voxel_bytes, opt, &inner))
        return vxl_fail_in(e, path, &inner);
    const uint64_t voxels = (uint64_t)h->dims[0] * h->dims[1] * h->dims[2];
    int rc = check_channel_header(r, path, h, voxels, e);
    if (rc) return rc;
    const uint64_t nbytes = voxels * (h->texture_bits / 8);
    if (colour && h->colour_bytes != voxels * VXL_COLOUR_BYTES_PER_VOXEL)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s announced %llu colour bytes for %ux%ux%u voxels",
                        path, r->name, (unsigned long long)h->colour_bytes, h->dims[0], h->dims[1], h->dims[2]);
    if (h->nbytes != nbytes || h->storage_bytes != nbytes)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s announced %llu bytes for %ux%ux%u voxels of %u bits",
                        path, r->name, (unsigned long long)h->nbytes, h->dims[0], h->dims[1], h->dims[2],
                        h->texture_bits);
    if (!all_finite(h->affine, 16))
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the volume's transform is not finite", path);
    const double range[4] = {h->tex_lo, h->tex_hi, h->value_min, h->value_max};
    int spacing_ok = all_finite(h->spacing, 3) && h->spacing[0] > 0 && h->spacing[1] > 0 && h->spacing[2] > 0;
    if (!spacing_ok || !all_finite(range, 4) || !(h->value_min <= h->value_max) || h->frame_count == 0 ||
        h->frame >= h->frame_count || h->affine_source > 2 || h->nifti_version > 2 ||
        h->nan_count + h->inf_count < h->nan_count || h->nan_count + h->inf_count > nbytes)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent an inconsistent volume header", path, r->name);
    if (!notes_ok(h->notes, sizeof h->notes))
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent notes that are not one terminated line of "
                        "text", path, r->name);
    return VXL_OK;
}

/* A part of the body after the texels (colour, channels): *buf of len
 * bytes, or NULL for none. */
static int make_room(const char *path, uint64_t len, const char *what, void **buf, uint64_t *buf_len, vxl_err *e)
{
    *buf_len = len;
    if (!len) return VXL_OK;
    *buf = malloc((size_t)len);
    if (!*buf)
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "cannot read '%s': out of memory for %llu bytes of %s", path,
                        (unsigned long long)len, what);
    return VXL_OK;
}

/* Checks a complete header and makes room for what follows it. */
static int accept_header(const vxl_reader *r, const char *path, reply *rp, uint32_t kind,
                         const vxl_load_options *opt, vxl_err *e)
{
    const vxl_reader_header *h = &rp->h;
    if (memcmp(h->magic, VXL_READER_MAGIC, sizeof VXL_READER_MAGIC))
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent no valid header", path, r->name);
    if (h->status != VXL_OK) {
        if (h->msg_len == 0 || h->msg_len > VXL_READER_MSG_MAX)
            return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s failed (code %u) with a bad message length %u",
                            path, r->name, h->status, h->msg_len);
        rp->body_len = h->msg_len;
    } else if (h->kind != kind) {
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent a reply of kind %u, not %u", path, r->name,
                        h->kind, kind);
    } else if (kind == VXL_REPLY_VOLUME) {
        int rc = check_volume_header(r, path, h, opt, e);
        if (rc) return rc;
        rp->body_len = h->nbytes;
        void *colour = NULL, *channels = NULL;
        if ((rc = make_room(path, h->colour_bytes, "colour", &colour, &rp->colour_len, e))) return rc;
        rp->colour = colour;
        if ((rc = make_room(path, h->channel_bytes, "channels", &channels, &rp->channels_len, e))) return rc;
        rp->channels = channels;
    } else if (kind == VXL_REPLY_IMAGE) {
        /* the budget the library asked for is the image's bytes */
        const uint64_t pixels = (uint64_t)h->dims[0] * h->dims[1];
        if (h->dims[0] == 0 || h->dims[1] == 0 || h->dims[2] != 1 || h->components != 3 || h->colour_bytes ||
            h->channel_count || h->channel_bytes ||
            pixels > vxl_load_budget(opt) / (3 * sizeof(float)) || h->nbytes != pixels * 3 * sizeof(float))
            return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s announced a %ux%ux%u image of %u components "
                            "in %llu bytes", path, r->name, h->dims[0], h->dims[1], h->dims[2], h->components,
                            (unsigned long long)h->nbytes);
        rp->body_len = h->nbytes;
    } else {
        if (h->record_size != sizeof(vxl_dicom_series) || h->count > MAX_SERIES ||
            h->nbytes != (uint64_t)h->count * sizeof(vxl_dicom_series))
            return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s announced %u series of %u bytes in %llu bytes",
                            path, r->name, h->count, h->record_size, (unsigned long long)h->nbytes);
        rp->body_len = h->nbytes;
    }
    rp->body = malloc(rp->body_len ? (size_t)rp->body_len : 1);
    if (!rp->body)
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "cannot read '%s': out of memory for %llu bytes", path,
                        (unsigned long long)rp->body_len);
    return VXL_OK;
}

/* What a header cannot say: float texels in [0, 1], an image's radiance
 * finite and not negative, series records with terminated strings and sane
 * fields. */
static int check_body(const vxl_reader *r, const char *path, const reply *rp, vxl_err *e)
{
    const vxl_reader_header *h = &rp->h;
    if (h->kind == VXL_REPLY_VOLUME) {
        if (h->texture_bits != 32) return VXL_OK;
        const float *t = (const float *)rp->body;
        for (uint64_t i = 0; i < h->nbytes / sizeof(float); i++)
            if (!(t[i] >= 0.0f && t[i] <= 1.0f))
                return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent a texel outside [0, 1] at voxel "
                                "%llu", path, r->name, (unsigned long long)i);
        return VXL_OK;
    }
    if (h->kind == VXL_REPLY_IMAGE) {
        const float *p = (const float *)rp->body;
        for (uint64_t i = 0; i < h->nbytes / sizeof(float); i++)
            if (!(p[i] >= 0.0f && p[i] <= FLT_MAX))
                return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent a pixel value that is negative or not "
                                "finite at %llu", path, r->name, (unsigned long long)i);
        return VXL_OK;
    }
    const vxl_dicom_series *s = (const vxl_dicom_series *)rp->body;
    for (uint32_t i = 0; i < h->count; i++) {
        int ok = s[i].struct_size == sizeof s[i] && s[i].loadable <= 1 && isfinite(s[i].gantry_tilt_deg) &&
                 memchr(s[i].uid, 0, sizeof s[i].uid) && memchr(s[i].modality, 0, sizeof s[i].modality) &&
                 memchr(s[i].description, 0, sizeof s[i].description) &&
                 memchr(s[i].problem, 0, sizeof s[i].problem);
        if (!ok)
            return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent a malformed series record %u", path,
                            r->name, i);
    }
    return VXL_OK;
}

/* Reads what is readable on the data stream. */
static int read_data(const vxl_reader *r, const char *path, vxl_child *child, reply *rp, uint32_t kind,
                     const vxl_load_options *opt, vxl_err *e)
{
    char scratch[256];
    void *dst;
    size_t want;
    if (rp->h_got < sizeof rp->h) {
        dst = (char *)&rp->h + rp->h_got;
        want = sizeof rp->h - rp->h_got;
    } else if (rp->body_got < rp->body_len) {
        dst = rp->body + rp->body_got;
        uint64_t left = rp->body_len - rp->body_got;
        want = left > (1u << 24) ? (1u << 24) : (size_t)left;
    } else if (rp->colour_got < rp->colour_len) {
        dst = rp->colour + rp->colour_got;
        uint64_t left = rp->colour_len - rp->colour_got;
        want = left > (1u << 24) ? (1u << 24) : (size_t)left;
    } else if (rp->channels_got < rp->channels_len) {
        dst = (char *)rp->channels + rp->channels_got;
        uint64_t left = rp->channels_len - rp->channels_got;
        want = left > (1u << 24) ? (1u << 24) : (size_t)left;
    } else {
        dst = scratch;
        want = sizeof scratch;
    }
    int64_t n = vxl_child_read(child, VXL_CHILD_OUT, dst, want);
    if (n < 0) {
        if (errno == EINTR || errno == EAGAIN) return VXL_OK;
        return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': reading from %s: %s", path, r->name, strerror(errno));
    }
    if (n == 0) return VXL_OK;
    if (dst == scratch) rp->extra = 1;
    else if (rp->h_got < sizeof rp->h) {
        rp->h_got += (size_t)n;
        if (rp->h_got == sizeof rp->h) return accept_header(r, path, rp, kind, opt, e);
    } else if (rp->body_got < rp->body_len) rp->body_got += (uint64_t)n;
    else if (rp->colour_got < rp->colour_len) rp->colour_got += (uint64_t)n;
    else rp->channels_got += (uint64_t)n;
    return VXL_OK;
}

/* Starts the helper with the load options as argv (reader_stream.h). */
static vxl_child *spawn_helper(const vxl_reader *r, const char *helper, const char *command, const char *path,
                               const vxl_load_options *opt, vxl_err *e)
{
    char max_dim[24], budget[24], vs[3][32], frame[16], source[16], channel[16], channels[16], scalar[16];
    double voxel[3];
    vxl_load_voxel_size(opt, voxel);
    snprintf(max_dim, sizeof max_dim, "%u", opt && opt->max_dim ? opt->max_dim : VXL_DEFAULT_MAX_DIM);
    snprintf(budget, sizeof budget, "%llu",
             (unsigned long long)vxl_load_budget(opt));
    for (int a = 0; a < 3; a++) snprintf(vs[a], sizeof vs[a], "%.17g", voxel[a]);
    snprintf(frame, sizeof frame, "%u", vxl_load_frame(opt));
    const char *series = vxl_load_series(opt);
    uint32_t src, ch;
    vxl_load_opacity_source(opt, &src, &ch);
    snprintf(source, sizeof source, "%u", src);
    snprintf(channel, sizeof channel, "%u", ch);
    uint32_t mode = VXL_CHANNELS_AUTO, scalar_channel = 0;
    vxl_load_channels_mode(opt, &mode, &scalar_channel, NULL); /* checked by vxl_reader_run */
    snprintf(channels, sizeof channels, "%u", mode);
    snprintf(scalar, sizeof scalar, "%u", scalar_channel);
    char *const argv[VXL_HELPER_ARGC + 1] = {(char *)helper, (char *)command, (char *)path, max_dim, budget,
                                             vs[0], vs[1], vs[2], frame, (char *)(series ? series : ""),
                                             source, channel, channels, scalar, NULL};
    vxl_child *c = vxl_child_start(helper, argv);
    if (!c)
        vxl_fail(e, VXL_ERR_IO, "cannot read '%s': cannot start %s (%s): %s", path, r->name, helper,
                 strerror(errno));
    return c;
}

/* Collects the helper's output until both pipes close, the time limit
 * passes (*timed_out) or the stream is bad (an error: the caller kills). */
static int collect(const vxl_reader *r, const char *path, vxl_child *child, double limit, uint32_t kind,
                   const vxl_load_options *opt, reply *rp, int *timed_out, vxl_err *e)
{
    const double deadline = vxl_monotonic_s() + limit;
    while (vxl_child_open(child, VXL_CHILD_OUT) || vxl_child_open(child, VXL_CHILD_ERR)) {
        double left = deadline - vxl_monotonic_s();
        if (left <= 0) {
            *timed_out = 1;
            return VXL_OK;
        }
        int ready;
        if (vxl_child_wait(child, left > 1e6 ? 1000000000 : (int)(left * 1000.0) + 1, &ready))
            return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': waiting for %s: %s", path, r->name, strerror(errno));
        if (ready & (1 << VXL_CHILD_OUT)) {
            int rc = read_data(r, path, child, rp, kind, opt, e);
            if (rc) return rc;
        }
        if (ready & (1 << VXL_CHILD_ERR)) {
            char buf[4096];
            int64_t k = vxl_child_read(child, VXL_CHILD_ERR, buf, sizeof buf);
            if (k > 0) keep_stderr(rp, buf, (size_t)k);
        }
    }
    return VXL_OK;
}

/* The last non-empty line of the helper's stderr, for error messages. */
static const char *last_line(reply *rp)
{
    char *s = rp->err_tail;
    size_t n = strlen(s);
    while (n && (s[n - 1] == '\n' || s[n - 1] == '\r' || s[n - 1] == ' ')) s[--n] = '\0';
    char *nl = strrchr(s, '\n');
    return nl ? nl + 1 : s;
}

/* The dynamic loader could not start the helper (exit 127 with "error while
 * loading shared libraries: X: cannot open shared object file"): names X,
 * the library the format needs and the package that brings both. */
static int missing_library(const vxl_reader *r, const char *path, const reply *rp, vxl_err *e)
{
    const char *at = strstr(rp->err_tail, LOADER_SAYS);
    if (!at) return VXL_OK;
    at += strlen(LOADER_SAYS);
    int len = (int)strcspn(at, ":\n");
    if (len > 200) len = 200;
    if (r->package[0])
        return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': %s need %s (Debian package %s), and %.*s is missing: "
                        "apt-get install %s", path, r->formats, r->library, r->package, len, at, r->package);
    return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': %s need %s (%s), and %.*s is missing: install the package "
                    "that provides %s", path, r->formats, r->library, r->soname, len, at, r->soname);
}

/* The dynamic loader refused the helper because it needs a newer C library
 * than this system has ("...: version `GLIBC_2.34' not found (required by
 * ...)"): the OpenImageIO and dcmtk helpers link Debian's libraries, so they
 * run only on a Linux as new as the one that built them, while the library
 * itself needs only glibc 2.28. VXL_OK when that is not what happened. */
static int too_new_for_this_system(const vxl_reader *r, const char *path, const reply *rp, vxl_err *e)
{
    const char *at = strstr(rp->err_tail, "version `");
    if (!at || !strstr(at, "' not found")) return VXL_OK;
    at += strlen("version `");
    int len = (int)strcspn(at, "'\n");
    if (len > 64) len = 64;
    return vxl_fail(e, VXL_ERR_IO, "cannot read '%s': %s need %s, and the helper %s was built for a newer Linux "
                    "than this one (it needs %.*s): these formats are read on Debian 12 or 13 with %s installed",
                    path, r->formats, r->library, r->helper, len, at, r->package[0] ? r->package : r->soname);
}

/* Turns how the helper ended and what it sent into our result. */
static int verdict(const vxl_reader *r, const char *path, const char *helper, const vxl_child_end *end,
                   int timed_out, double limit, reply *rp, vxl_err *e)
{
    if (timed_out)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s took longer than %.0f s and was stopped", path,
                        r->name, limit);
    if (end->exited && end->code == 127 && rp->h_got == 0) {
        int rc = missing_library(r, path, rp, e);
        if (rc) return rc;
    }
    if (end->exited && end->code != 0 && rp->h_got == 0) {
        int rc = too_new_for_this_system(r, path, rp, e);
        if (rc) return rc;
    }
    const char *said = last_line(rp);
    if (end->signaled) {
        int sig = end->signal;
        const char *abbrev = vxl_signal_name(sig);
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s crashed (signal %d: SIG%s) - the file is corrupt "
                        "or unsupported%s%s%s", path, r->name, sig, abbrev ? abbrev : "?", *said ? " (" : "", said,
                        *said ? ")" : "");
    }
    const int complete = rp->h_got == sizeof rp->h && rp->body && rp->body_got == rp->body_len &&
                         rp->colour_got == rp->colour_len && rp->channels_got == rp->channels_len;
    if (complete && rp->h.status != VXL_OK) {
        int code = rp->h.status >= VXL_ERR_INVALID_ARGUMENT && rp->h.status <= VXL_ERR_STATE ? (int)rp->h.status
                                                                                             : VXL_ERR_FORMAT;
        return vxl_fail(e, code, "%.*s", (int)rp->body_len, rp->body);
    }
    if (end->exited && end->code != 0)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s (%s) failed (exit %d)%s%s", path, r->name, helper,
                        end->code, *said ? ": " : "", said);
    if (!complete)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': the output of %s was cut short (%llu of %llu bytes)",
                        path, r->name,
                        (unsigned long long)(rp->h_got + rp->body_got + rp->colour_got + rp->channels_got),
                        (unsigned long long)(sizeof rp->h + rp->body_len + rp->colour_len + rp->channels_len));
    if (rp->extra)
        return vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent more than it announced", path, r->name);
    return check_body(r, path, rp, e);
}

int vxl_reader_run(const vxl_reader *r, const char *command, const char *path, const vxl_load_options *opt,
                   uint32_t kind, uint64_t input_bytes, vxl_reader_header *h, void **body, uint8_t **colour,
                   uint16_t **channels, vxl_err *e)
{
    *body = NULL;
    if (colour) *colour = NULL;
    if (channels) *channels = NULL;
    uint32_t mode, scalar_channel; /* an unknown channels mode is refused here, before a helper starts */
    int rc = vxl_load_channels_mode(opt, &mode, &scalar_channel, e);
    if (rc) return rc;
    char helper[4096];
    if ((rc = helper_path(r, path, helper, sizeof helper, e))) return rc;
    vxl_child *child = spawn_helper(r, helper, command, path, opt, e);
    if (!child) return VXL_ERR_IO;
    reply rp;
    memset(&rp, 0, sizeof rp);
    int timed_out = 0;
    const double limit = time_limit(input_bytes);
    rc = collect(r, path, child, limit, kind, opt, &rp, &timed_out, e);
    if (rc || timed_out) vxl_child_kill(child);
    vxl_child_end end;
    vxl_child_finish(child, &end); /* not reaped: the host reaps children itself, the stream alone decides */
    if (!rc) rc = verdict(r, path, helper, &end, timed_out, limit, &rp, e);
    if (!rc && rp.colour && !colour) /* a caller that takes no colour never asked for a volume */
        rc = vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent colour where none was expected", path, r->name);
    if (!rc && rp.channels && !channels)
        rc = vxl_fail(e, VXL_ERR_FORMAT, "cannot read '%s': %s sent channels where none were expected", path,
                      r->name);
    if (rc) {
        free(rp.body);
        free(rp.colour);
        free(rp.channels);
        return rc;
    }
    *h = rp.h;
    *body = rp.body;
    if (colour) *colour = rp.colour;
    if (channels) *channels = rp.channels;
    return VXL_OK;
}
