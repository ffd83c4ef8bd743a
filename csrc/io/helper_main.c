/* helper_main.c - see helper_main.h. The helper is started by
 * reader_spawn.c with stdin on /dev/null, stdout and stderr on pipes; it
 * is not meant to be run by hand. */
#include "helper_main.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "channel_volume.h"
#include "colour_volume.h"
#include "helper_self.h"
#include "os.h"
#include "reader_stream.h"

static int write_all(int fd, const void *buf, size_t n)
{
    const char *p = buf;
    while (n) {
        int64_t w = vxl_self_write(fd, p, n > (1u << 30) ? (1u << 30) : n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return -1;
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

static int parse_u64(const char *s, unsigned long long *out)
{
    char *end;
    errno = 0;
    *out = strtoull(s, &end, 10);
    return s[0] >= '0' && s[0] <= '9' && !*end && errno == 0;
}

static int parse_double(const char *s, double *out)
{
    char *end;
    *out = strtod(s, &end);
    return *s && !*end && isfinite(*out);
}

/* argv[3..] into options; 0 when malformed. */
static int parse_options(char **argv, vxl_load_options *opt)
{
    unsigned long long max_dim, budget, frame, source, channel, channels, scalar_channel;
    memset(opt, 0, sizeof *opt);
    opt->struct_size = sizeof *opt;
    if (!parse_u64(argv[3], &max_dim) || max_dim > UINT32_MAX || !parse_u64(argv[4], &budget)) return 0;
    for (int a = 0; a < 3; a++)
        if (!parse_double(argv[5 + a], &opt->voxel_size[a])) return 0;
    if (!parse_u64(argv[8], &frame) || frame > UINT32_MAX) return 0;
    opt->max_dim = (uint32_t)max_dim;
    opt->memory_budget_bytes = budget;
    opt->frame = (uint32_t)frame;
    opt->series = argv[9][0] ? argv[9] : NULL;
    /* checked by the colour reader itself (vxl_colour_opacity_source), as
     * in process */
    if (!parse_u64(argv[10], &source) || source > UINT32_MAX || !parse_u64(argv[11], &channel) ||
        channel > UINT32_MAX)
        return 0;
    opt->opacity_source = (uint32_t)source;
    opt->opacity_channel = (uint32_t)channel;
    /* checked by the readers (vxl_load_channels_mode), as in process */
    if (!parse_u64(argv[12], &channels) || channels > UINT32_MAX || !parse_u64(argv[13], &scalar_channel) ||
        scalar_channel > UINT32_MAX)
        return 0;
    opt->channels = (uint32_t)channels;
    opt->scalar_channel = (uint32_t)scalar_channel;
    return 1;
}

/* A third-party reader that asks for an absurd allocation (OpenImageIO
 * sized a buffer by a corrupt strip header: 31 GB for a 288-byte file) must
 * get a failed allocation, which the reader reports as a clear error, not a
 * machine pushed into swap or the OOM killer. So the helper caps its own
 * address space: three times the budget (the source voxels, the volume built
 * from them, a reader's own copy) plus 2 GiB for the libraries, thread
 * stacks and the reader's chunk buffers. Sanitizer builds reserve terabytes
 * of shadow memory up front, so there the cap is left off. */
#if defined(__SANITIZE_ADDRESS__)
#define VXL_HELPER_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VXL_HELPER_SANITIZED 1
#endif
#endif

static void cap_address_space(uint64_t budget)
{
#ifndef VXL_HELPER_SANITIZED
    const uint64_t headroom = 2ull << 30;
    vxl_self_cap_memory(budget > (UINT64_MAX - headroom) / 3 ? UINT64_MAX : 3 * budget + headroom);
#else
    (void)budget;
#endif
}

static void volume_header(const vxl_volume *v, vxl_reader_header *h)
{
    h->kind = VXL_REPLY_VOLUME;
    memcpy(h->dims, v->dims, sizeof h->dims);
    h->src_dtype = v->src_dtype;
    h->texture_bits = v->texture_bits;
    h->nifti_version = v->nifti_version;
    h->affine_source = v->affine_source;
    h->frame_count = v->frame_count ? v->frame_count : 1;
    h->frame = v->frame;
    h->tex_lo = v->tex_lo;
    h->tex_hi = v->tex_hi;
    h->value_min = v->value_min;
    h->value_max = v->value_max;
    memcpy(h->spacing, v->spacing, sizeof h->spacing);
    memcpy(h->affine, v->affine, sizeof h->affine);
    h->nan_count = v->nan_count;
    h->inf_count = v->inf_count;
    h->storage_bytes = v->storage_bytes;
    h->nbytes = v->storage_bytes;
    h->components = v->colour ? v->components : 1;
    h->opacity_source = v->colour ? v->opacity_source : 0;
    h->colour_bytes = vxl_volume_colour_bytes(v);
    /* a reader's notes are terminated; a full array is cut, not sent open */
    snprintf(h->notes, sizeof h->notes, "%s", v->notes);
    if (v->channels) {
        vxl_reader_channel_fields(h, (vxl_volume *)v, 1);
        h->channel_bytes = vxl_volume_channel_bytes(v);
    }
}

int vxl_helper_main(const char *helper, int argc, char **argv, const vxl_helper_command *cmds, int n_cmds)
{
    /* the file's path as the library passed it (UTF-8), not as Windows'
     * ANSI code page spells it */
    if (vxl_os_utf8_args(&argc, &argv)) {
        fprintf(stderr, "%s: the command line cannot be read as UTF-8\n", helper);
        return 2;
    }
    const vxl_helper_command *cmd = NULL;
    for (int i = 0; argc == VXL_HELPER_ARGC && i < n_cmds; i++)
        if (!strcmp(argv[1], cmds[i].name)) cmd = &cmds[i];
    vxl_load_options opt;
    if (!cmd || !parse_options(argv, &opt)) {
        fprintf(stderr, "usage: %s COMMAND FILE MAX_DIM BUDGET_BYTES VOXEL_X VOXEL_Y VOXEL_Z FRAME SERIES "
                "OPACITY_SOURCE OPACITY_CHANNEL CHANNELS SCALAR_CHANNEL "
                "(started by libvoxlight; commands:", helper);
        for (int i = 0; i < n_cmds; i++) fprintf(stderr, " %s", cmds[i].name);
        fputs(")\n", stderr);
        return 2;
    }
    /* Descriptors the host process left open (Blender's, another
     * add-on's), held here, could keep a pipe of the host's open for the
     * helper's whole run. */
    vxl_self_close_inherited();
    /* The stream keeps stdout's pipe to itself: whatever the libraries
     * print goes to stderr instead of into the voxels. */
    int out = vxl_self_take_stdout();
    if (out < 0) {
        perror(helper);
        return 3;
    }
    cap_address_space(opt.memory_budget_bytes);
    const char *path = argv[2];
    vxl_reader_header h;
    memset(&h, 0, sizeof h);
    memcpy(h.magic, VXL_READER_MAGIC, sizeof VXL_READER_MAGIC);
    vxl_err e = {0};
    vxl_volume *v = NULL;
    vxl_dicom_series *list = NULL;
    float *image = NULL;
    const void *body = NULL, *colour = NULL, *channels = NULL;
    if (cmd->read) {
        h.status = (uint32_t)cmd->read(path, &opt, &v, &e);
        if (h.status == VXL_OK) {
            volume_header(v, &h);
            body = v->texels;
            colour = v->colour;
            channels = v->channels;
        }
    } else if (cmd->image) {
        uint32_t w = 0, ht = 0;
        float *rgb = NULL;
        h.status = (uint32_t)cmd->image(path, opt.memory_budget_bytes / (3 * sizeof(float)), &rgb, &w, &ht, &e);
        if (h.status == VXL_OK) {
            h.kind = VXL_REPLY_IMAGE;
            h.dims[0] = w;
            h.dims[1] = ht;
            h.dims[2] = 1;
            h.components = 3;
            h.nbytes = (uint64_t)w * ht * 3 * sizeof(float);
            body = image = rgb;
        }
    } else {
        uint32_t count = 0;
        h.status = (uint32_t)cmd->list(path, &list, &count, &e);
        if (h.status == VXL_OK) {
            h.kind = VXL_REPLY_SERIES;
            h.count = count;
            h.record_size = sizeof *list;
            h.nbytes = (uint64_t)count * sizeof *list;
            body = list;
        }
    }
    int rc;
    if (h.status != VXL_OK) {
        if (!e.msg[0]) snprintf(e.msg, sizeof e.msg, "'%s': the reader failed without a message", path);
        h.msg_len = (uint32_t)strnlen(e.msg, sizeof e.msg);
        rc = write_all(out, &h, sizeof h) || write_all(out, e.msg, h.msg_len) ? 3 : 1;
    } else {
        rc = write_all(out, &h, sizeof h) || write_all(out, body, (size_t)h.nbytes) ||
                     (h.colour_bytes && write_all(out, colour, (size_t)h.colour_bytes)) ||
                     (h.channel_bytes && write_all(out, channels, (size_t)h.channel_bytes))
                 ? 3
                 : 0;
    }
    vxl_volume_destroy(v);
    free(list);
    free(image);
    return rc;
}
