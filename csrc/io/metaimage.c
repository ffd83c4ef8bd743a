/* metaimage.c - MetaImage reader (.mha with local data, .mhd with an
 * ElementDataFile), raw or zlib-compressed (CompressedData = True).
 *
 * Our own reader: Debian has no MetaIO library outside ITK/VTK, and the
 * format is "Key = Value" text followed by raw or zlib data. The same
 * hostile-input rules as the NIfTI and NRRD readers apply: counts must match
 * NDims, sizes pass vxl_volume_check_limits before any allocation, data files
 * must be regular files, and raw sizes are checked against the file.
 *
 * Geometry: MetaImage (as written by ITK) lives in LPS; each consecutive
 * triple of TransformMatrix is the direction of one voxel axis. The affine
 * is Offset + sum_i index_i * ElementSpacing_i * direction_i, then converted
 * to RAS (x and y negated) so MetaImage and NIfTI share one world frame.
 *
 * ElementNumberOfChannels (each voxel's channels together, as MetaIO writes
 * them) follows NRRD's channel axis rule (vxl_load_options.channels,
 * docs/channels.md): 3 or 4 is RGB or RGBA, a colour volume read whole
 * (colour_volume.h), unless channels is ON; 2 and 5..8 are channels
 * (channel_volume.h) unless channels is OFF, which refuses them as before. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "channel_volume.h"
#include "colour_volume.h"
#include "hash.h"
#include "loader_util.h"
#include "stream_load.h"
#include "loaders.h"

#define MHA_MAX_DIM 4

typedef struct mha_hdr {
    int ndims;
    int ndimsize;
    uint64_t dimsize[MHA_MAX_DIM];
    uint32_t dtype;
    int nspacing;
    double spacing[MHA_MAX_DIM];
    int nsize; /* ElementSize: fallback for spacing */
    double size[MHA_MAX_DIM];
    int norigin;
    double origin[MHA_MAX_DIM];
    int nmatrix;
    double matrix[MHA_MAX_DIM * MHA_MAX_DIM];
    int msb;          /* 1: big-endian data */
    int compressed;
    uint32_t channels;   /* ElementNumberOfChannels: 1 (0 unset) .. VXL_MAX_CHANNELS */
    int64_t header_size; /* -1: raw data ends the file; 0 default */
    const char *data_file; /* NULL or "LOCAL" = follows the header */
    uint64_t data_offset;
} mha_hdr;

static uint32_t dtype_from_name(const char *t)
{
    static const struct { const char *name; uint32_t dtype; } map[] = {
        {"MET_UCHAR", VXL_DTYPE_U8}, {"MET_CHAR", VXL_DTYPE_I8},
        {"MET_USHORT", VXL_DTYPE_U16}, {"MET_SHORT", VXL_DTYPE_I16},
        {"MET_UINT", VXL_DTYPE_U32}, {"MET_INT", VXL_DTYPE_I32},
        {"MET_ULONG", VXL_DTYPE_U32}, {"MET_LONG", VXL_DTYPE_I32}, /* 4 bytes in MetaIO */
        {"MET_FLOAT", VXL_DTYPE_F32}, {"MET_DOUBLE", VXL_DTYPE_F64},
    };
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (!strcasecmp(t, map[i].name)) return map[i].dtype;
    return 0;
}

static int parse_bool(const char *v, int *out)
{
    if (!strcasecmp(v, "true") || !strcmp(v, "1")) *out = 1;
    else if (!strcasecmp(v, "false") || !strcmp(v, "0")) *out = 0;
    else return 0;
    return 1;
}

static int bad(vxl_err *e, const char *path, int line, const char *key, const char *problem)
{
    return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage header line %d: bad '%s': %s", path, line, key, problem);
}

static int parse_field(mha_hdr *h, const char *key, char *val, const char *path, int line, vxl_err *e)
{
    if (!strcasecmp(key, "ObjectType")) {
        if (strcasecmp(val, "Image") != 0)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage ObjectType is '%.64s', only 'Image' is supported",
                            path, val);
    } else if (!strcasecmp(key, "NDims")) {
        uint64_t n;
        if (vxl_parse_u64s(val, &n, 1, MHA_MAX_DIM) != 1 || n < 1)
            return bad(e, path, line, key, "must be 1..4");
        h->ndims = (int)n;
    } else if (!strcasecmp(key, "DimSize")) {
        h->ndimsize = vxl_parse_u64s(val, h->dimsize, MHA_MAX_DIM, UINT32_MAX);
        if (h->ndimsize < 1) return bad(e, path, line, key, "expected whole numbers 1..4294967295");
        for (int i = 0; i < h->ndimsize && i < MHA_MAX_DIM; i++)
            if (h->dimsize[i] == 0) return bad(e, path, line, key, "every axis needs at least 1 voxel");
    } else if (!strcasecmp(key, "ElementType")) {
        h->dtype = dtype_from_name(val);
        if (!h->dtype)
            return vxl_fail(e, VXL_ERR_FORMAT,
                            "'%s': unsupported MetaImage ElementType '%.64s' (supported: MET_[U]CHAR, "
                            "MET_[U]SHORT, MET_[U]INT, MET_[U]LONG, MET_FLOAT, MET_DOUBLE)", path, val);
    } else if (!strcasecmp(key, "ElementSpacing")) {
        h->nspacing = vxl_parse_doubles(val, h->spacing, MHA_MAX_DIM);
        if (h->nspacing < 1) return bad(e, path, line, key, "expected finite numbers");
    } else if (!strcasecmp(key, "ElementSize")) {
        h->nsize = vxl_parse_doubles(val, h->size, MHA_MAX_DIM);
        if (h->nsize < 1) return bad(e, path, line, key, "expected finite numbers");
    } else if (!strcasecmp(key, "Offset") || !strcasecmp(key, "Position") || !strcasecmp(key, "Origin")) {
        h->norigin = vxl_parse_doubles(val, h->origin, MHA_MAX_DIM);
        if (h->norigin < 1) return bad(e, path, line, key, "expected finite numbers");
    } else if (!strcasecmp(key, "TransformMatrix") || !strcasecmp(key, "Rotation") ||
               !strcasecmp(key, "Orientation")) {
        h->nmatrix = vxl_parse_doubles(val, h->matrix, MHA_MAX_DIM * MHA_MAX_DIM);
        if (h->nmatrix < 1) return bad(e, path, line, key, "expected finite numbers");
    } else if (!strcasecmp(key, "BinaryDataByteOrderMSB") || !strcasecmp(key, "ElementByteOrderMSB")) {
        if (!parse_bool(val, &h->msb)) return bad(e, path, line, key, "must be True or False");
    } else if (!strcasecmp(key, "CompressedData")) {
        if (!parse_bool(val, &h->compressed)) return bad(e, path, line, key, "must be True or False");
    } else if (!strcasecmp(key, "BinaryData")) {
        int b;
        if (!parse_bool(val, &b)) return bad(e, path, line, key, "must be True or False");
        if (!b)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage with BinaryData = False (ASCII voxels) is not "
                            "supported", path);
    } else if (!strcasecmp(key, "ElementNumberOfChannels")) {
        uint64_t c;
        if (vxl_parse_u64s(val, &c, 1, 1u << 20) != 1 || c < 1) return bad(e, path, line, key, "must be >= 1");
        if (c > VXL_MAX_CHANNELS)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage with %llu channels per voxel is not supported "
                            "(1, 3 and 4 as RGB and RGBA colour, or 2 to %d channels)", path, (unsigned long long)c,
                            VXL_MAX_CHANNELS);
        h->channels = (uint32_t)c;
    } else if (!strcasecmp(key, "HeaderSize")) {
        uint64_t b;
        if (!strcmp(val, "-1")) h->header_size = -1;
        else if (vxl_parse_u64s(val, &b, 1, 1ull << 40) == 1) h->header_size = (int64_t)b;
        else return bad(e, path, line, key, "must be -1 or a whole number");
    } else if (!strcasecmp(key, "ElementDataFile")) {
        if (!*val) return bad(e, path, line, key, "empty file name");
        if (!strncasecmp(val, "LIST", 4) || strchr(val, '%'))
            return vxl_fail(e, VXL_ERR_FORMAT,
                            "'%s': MetaImage data split over several files ('%.64s') is not supported", path, val);
        h->data_file = strcasecmp(val, "LOCAL") ? val : NULL;
    }
    /* Comment, AnatomicalOrientation, CenterOfRotation, ElementMin/Max,
     * CompressedDataSize, ... do not change the voxels. */
    return VXL_OK;
}

static int parse_header(char *text, size_t len, uint64_t file_size, const char *path, mha_hdr *h, vxl_err *e)
{
    memset(h, 0, sizeof *h);
    size_t pos = 0;
    int nl = 0, line = 0, done = 0, any = 0;
    char *s;
    while ((s = vxl_next_line(text, len, &pos, &nl)) != NULL) {
        line++;
        char *t = vxl_trim(s);
        if (!*t) continue;
        char *eq = strchr(t, '=');
        if (!eq) {
            if (!any)
                return vxl_fail(e, VXL_ERR_FORMAT, "'%s' is not a MetaImage file: line 1 is not 'Key = Value'",
                                path);
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage header line %d is not 'Key = Value'", path, line);
        }
        *eq = '\0';
        char *key = vxl_trim(t), *val = vxl_trim(eq + 1);
        any = 1;
        int rc = parse_field(h, key, val, path, line, e);
        if (rc) return rc;
        if (!strcasecmp(key, "ElementDataFile")) {
            done = 1; /* always the last field; data follows */
            break;
        }
        if (!nl) break;
    }
    if (!done) {
        if (len >= VXL_HEADER_MAX && file_size > len)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage header longer than %u bytes", path, VXL_HEADER_MAX);
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage header has no ElementDataFile field (it must be the "
                        "last line)", path);
    }
    h->data_offset = pos;
    if (!h->ndims) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage header has no NDims field", path);
    if (h->ndimsize != h->ndims)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage DimSize has %d entries, NDims is %d", path, h->ndimsize,
                        h->ndims);
    if (!h->dtype) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage header has no ElementType field", path);
    if (h->nspacing && h->nspacing != h->ndims)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage ElementSpacing has %d entries, NDims is %d", path,
                        h->nspacing, h->ndims);
    if (h->nsize && h->nsize != h->ndims)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage ElementSize has %d entries, NDims is %d", path,
                        h->nsize, h->ndims);
    if (h->norigin && h->norigin != h->ndims)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage Offset has %d entries, NDims is %d", path, h->norigin,
                        h->ndims);
    if (h->nmatrix && h->nmatrix != h->ndims * h->ndims)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage TransformMatrix has %d entries, expected %d", path,
                        h->nmatrix, h->ndims * h->ndims);
    if (h->header_size < 0 && h->compressed)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage HeaderSize = -1 is only valid for uncompressed data",
                        path);
    return VXL_OK;
}

/* ElementNumberOfChannels under the channels mode: *channels (2..8) or
 * *components (3, 4 colour), the other 0/1; OFF refuses what cannot be
 * colour, as MetaImage was read before channels. */
static int choose_channels(const mha_hdr *h, const vxl_load_options *opt, uint32_t *components, uint32_t *channels,
                           const char *path, vxl_err *e)
{
    uint32_t mode, scalar;
    int rc = vxl_load_channels_mode(opt, &mode, &scalar, e);
    if (rc) return rc;
    const uint32_t n = h->channels ? h->channels : 1, colour = n == 3 || n == 4;
    *components = 1;
    *channels = 0;
    if (n == 1) return VXL_OK;
    if (mode == VXL_CHANNELS_ON || (mode == VXL_CHANNELS_AUTO && !colour)) *channels = n;
    else if (colour) *components = n;
    else
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage with %u channels per voxel and channels off (only 3 and "
                        "4 are read as colour; --channel-axis auto or on reads them as channels)", path, n);
    return VXL_OK;
}

static int geometry(const mha_hdr *h, double sp[3], double A[16], const char *path, vxl_err *e)
{
    int n = h->ndims;
    double dir[3][3] = {{0}}, org[3] = {0, 0, 0};
    for (int a = 0; a < 3; a++) {
        double s = 1.0;
        if (a < n && h->nspacing) s = h->spacing[a];
        else if (a < n && h->nsize) s = h->size[a];
        s = fabs(s);
        sp[a] = (isfinite(s) && s > 0) ? s : 1.0;
        if (a < n && h->norigin) org[a] = h->origin[a];
    }
    for (int a = 0; a < 3; a++) {
        for (int r = 0; r < 3; r++) {
            double m = r == a ? 1.0 : 0.0;
            if (h->nmatrix && a < n && r < n) m = h->matrix[a * n + r];
            dir[a][r] = m * sp[a];
        }
    }
    /* LPS -> RAS */
    for (int a = 0; a < 3; a++) {
        dir[a][0] = -dir[a][0];
        dir[a][1] = -dir[a][1];
    }
    org[0] = -org[0];
    org[1] = -org[1];
    if (!vxl_affine_from(dir, org, A))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': MetaImage TransformMatrix is singular", path);
    return VXL_OK;
}

int vxl_metaimage_load(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    if (!out) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (!path || !*path) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "path is empty");

    char *text = NULL, *data_path = NULL;
    void *raw = NULL;
    size_t len = 0;
    uint64_t file_size = 0, nbytes = 0, offset = 0;
    mha_hdr h;
    uint32_t dims[3];
    int stream = 0;
    uint32_t components = 1, channels = 0;
    const char *dpath = path;
    int rc = vxl_read_head(path, &text, &len, &file_size, e);
    if (!rc) rc = parse_header(text, len, file_size, path, &h, e);
    if (!rc) rc = choose_channels(&h, opt, &components, &channels, path, e);
    if (!rc) {
        for (int a = 0; a < 3; a++) dims[a] = a < h.ndims ? (uint32_t)h.dimsize[a] : 1;
        /* zlib data streams through a bricked cache, inflated from where it
         * starts; colour and channels are read whole (colour_volume.h,
         * channel_volume.h) */
        if (channels) {
            rc = vxl_plan_channel_voxels(path, dims, h.dtype, channels, opt, &nbytes, e);
            nbytes *= channels; /* interleaved: every channel's samples */
        } else if (components > 1) rc = vxl_plan_colour_voxels(path, dims, h.dtype, components, opt, &nbytes, e);
        else rc = vxl_stream_plan(path, dims, h.dtype, opt, NULL, &stream, &nbytes, e);
    }
    if (!rc && h.data_file) {
        data_path = vxl_sibling_path(path, h.data_file);
        if (!data_path) rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory opening '%s'", path);
        dpath = data_path;
        offset = h.header_size > 0 ? (uint64_t)h.header_size : 0;
    } else if (!rc) {
        offset = h.data_offset + (h.header_size > 0 ? (uint64_t)h.header_size : 0);
    }
    /* a 4th axis: only the first volume is read, so "data ends the file"
     * must count all of them */
    int from_end = 0;
    if (!rc && h.header_size < 0) {
        uint64_t total = nbytes, size = 0;
        if (h.ndims == 4) {
            if (total > UINT64_MAX / h.dimsize[3]) rc = vxl_fail(e, VXL_ERR_LIMIT, "'%s': DimSize overflows", path);
            else total *= h.dimsize[3];
        }
        if (!rc) rc = vxl_regular_file(dpath, &size, e);
        if (!rc && size < total)
            rc = vxl_fail(e, VXL_ERR_FORMAT,
                          "'%s': truncated file: expected %llu bytes of voxel data at the end, the file has %llu",
                          dpath, (unsigned long long)total, (unsigned long long)size);
        if (!rc) offset = size - total;
    }
    if (!rc && stream && !vxl_stream_file_holds(dpath, offset, h.compressed, nbytes, opt)) {
        stream = 0; /* AUTO and a file too short to stream: today's whole-read checks say why */
        rc = vxl_plan_voxels(path, dims, h.dtype, opt, &nbytes, e);
    }
    vxl_raw_layout *l = NULL; /* streamed, the voxels are read on demand (stream_load.h) */
    if (!rc && stream && !(l = malloc(sizeof *l))) rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory opening '%s'", path);
    if (l) {
        double sp[3], A[16];
        rc = geometry(&h, sp, A, path, e);
        if (!rc) rc = vxl_layout_init(l, dpath, h.compressed ? 0 : offset, dims, h.dtype, sp, A, e);
        l->compressed = h.compressed;
        l->compressed_start = h.compressed ? offset : 0; /* the zlib stream starts after the header */
        l->swap = vxl_dtype_size(h.dtype) > 1 && h.msb != vxl_host_big_endian();
        l->affine_source = h.nmatrix || h.norigin ? 2 : 0;
        l->header_hash = vxl_fnv(14695981039346656037ull, text, len);
        if (!rc) rc = vxl_stream_load(l, opt, out, e);
        free(l);
        free(data_path);
        free(text);
        return rc;
    }
    if (!rc) rc = vxl_read_payload(dpath, offset, from_end, h.compressed, 0, nbytes, &raw, e);
    if (!rc) {
        size_t es = vxl_dtype_size(h.dtype);
        if (es > 1 && h.msb != vxl_host_big_endian()) vxl_swap_elements(raw, nbytes / es, es);
        double sp[3], A[16];
        rc = geometry(&h, sp, A, path, e);
        if (!rc) {
            rc = vxl_build_interleaved(path, raw, h.dtype, channels, components, dims, sp, A, opt, "MetaImage",
                                       "ElementNumberOfChannels", vxl_load_streaming(opt) == VXL_STREAMING_ON, out, e);
            if (!rc) (*out)->affine_source = h.nmatrix || h.norigin ? 2 : 0;
        }
    }
    free(raw);
    free(data_path);
    free(text);
    return rc;
}
