/* zarr_read.c - vxl_zarr_read: one multiscale level of an OME-Zarr image,
 * at one time point and channel, into a volume; or, for a c axis of
 * 2..VXL_MAX_CHANNELS, every channel into a multi-channel volume with the
 * omero metadata's names, colours and windows (docs/channels.md).
 *
 * The path is the image's folder, optionally with "#level=N&c=N" (the load
 * options have no field for either, and the public structs stay as they
 * are): level 0 is the finest; without one the finest level whose volume
 * fits the memory budget and the per-axis limit is read. The time point is
 * vxl_load_options.frame, as for 4D NIfTI; frame_count is the t extent.
 * Voxel (i, j, k) is array element [.., z=k, y=j, x=i] and the affine is
 * the level's scale and translation on x, y, z, converted from the axes'
 * units to mm (zarr_store.c; docs/zarr.md). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "channel_volume.h"
#include "files.h"
#include "loader_util.h"
#include "loaders.h"
#include "zarr.h"

/* Splits "folder#level=1&c=0" into the folder and the choices. */
int vxl_zarr_parse_path(const char *path, char *folder, size_t size, vxl_zarr_choice *ch, vxl_err *e)
{
    ch->level = -1;
    ch->c_given = 0;
    ch->c = 0;
    const char *hash = strrchr(path, '#');
    size_t n = hash ? (size_t)(hash - path) : strlen(path);
    if (n >= size) return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': path too long", path);
    memcpy(folder, path, n);
    folder[n] = '\0';
    while (n > 1 && vxl_path_is_separator(folder[n - 1])) folder[--n] = '\0';
    char *slash = (char *)vxl_path_last_separator(folder); /* a metadata file picked inside the store: its folder */
    if (slash && vxl_zarr_metadata_name(slash + 1)) *slash = '\0';
    if (!hash) return VXL_OK;
    char opts[256];
    if (snprintf(opts, sizeof opts, "%s", hash + 1) >= (int)sizeof opts)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': the options after '#' are too long", path);
    char *save = NULL;
    for (char *tok = strtok_r(opts, "&", &save); tok; tok = strtok_r(NULL, "&", &save)) {
        uint64_t v;
        char *eq = strchr(tok, '=');
        if (!eq || vxl_parse_u64s(eq + 1, &v, 1, 1u << 30) != 1)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': '%s' is not NAME=NUMBER (level, c)", path, tok);
        *eq = '\0';
        if (!strcmp(tok, "level")) ch->level = (int)(v < VXL_ZARR_MAX_LEVELS ? v : VXL_ZARR_MAX_LEVELS);
        else if (!strcmp(tok, "c")) {
            ch->c = v;
            ch->c_given = 1;
        }
        else return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': unknown option '%s' (level, c)", path, tok);
    }
    return VXL_OK;
}

int vxl_zarr_select(const char *path, const vxl_zarr_store *s, int level, const vxl_load_options *opt,
                    const vxl_zarr_choice *ch, uint64_t sel[VXL_ZARR_ROLES], uint64_t *nt, vxl_err *e)
{
    if (level < 0 || level >= s->nlevels)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': level %d asked for, the image has %d (0 to %d)", path,
                        level, s->nlevels, s->nlevels - 1);
    const vxl_zarr_array *a = &s->level[level];
    memset(sel, 0, VXL_ZARR_ROLES * sizeof *sel);
    sel[VXL_ZARR_T] = vxl_load_frame(opt);
    sel[VXL_ZARR_C] = ch->c;
    *nt = s->axis[VXL_ZARR_T] >= 0 ? a->shape[s->axis[VXL_ZARR_T]] : 1;
    const uint64_t nc = s->axis[VXL_ZARR_C] >= 0 ? a->shape[s->axis[VXL_ZARR_C]] : 1;
    if (sel[VXL_ZARR_T] >= *nt)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': frame %llu asked for, the image has %llu time points",
                        path, (unsigned long long)sel[VXL_ZARR_T], (unsigned long long)*nt);
    if (sel[VXL_ZARR_C] >= nc)
        return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': channel %llu asked for, the image has %llu channels",
                        path, (unsigned long long)sel[VXL_ZARR_C], (unsigned long long)nc);
    return VXL_OK;
}

int vxl_zarr_channels(const char *path, const vxl_zarr_store *s, const vxl_zarr_choice *ch,
                      const vxl_load_options *opt, uint32_t *channels, vxl_err *e)
{
    *channels = 0;
    uint32_t mode, scalar;
    int rc = vxl_load_channels_mode(opt, &mode, &scalar, e);
    if (rc) return rc;
    if (s->axis[VXL_ZARR_C] < 0 || ch->c_given || mode == VXL_CHANNELS_OFF) return VXL_OK;
    const uint64_t nc = s->level[0].shape[s->axis[VXL_ZARR_C]];
    if (nc >= 2 && nc <= VXL_MAX_CHANNELS) *channels = (uint32_t)nc;
    else if (nc > VXL_MAX_CHANNELS && mode == VXL_CHANNELS_ON)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': %llu channels, over the %d a multi-channel volume holds (pick one "
                        "with #c=N, or channels auto reads channel 0)", path, (unsigned long long)nc,
                        VXL_MAX_CHANNELS);
    return VXL_OK;
}

/* The level's volume dims (x, y, z). */
static void level_dims(const vxl_zarr_store *s, int l, uint32_t dims[3])
{
    const vxl_zarr_array *a = &s->level[l];
    const uint64_t x = a->shape[s->axis[VXL_ZARR_X]], y = a->shape[s->axis[VXL_ZARR_Y]],
                   z = a->shape[s->axis[VXL_ZARR_Z]];
    dims[0] = x > UINT32_MAX ? UINT32_MAX : (uint32_t)x;
    dims[1] = y > UINT32_MAX ? UINT32_MAX : (uint32_t)y;
    dims[2] = z > UINT32_MAX ? UINT32_MAX : (uint32_t)z;
}

/* extra_bytes: what a voxel costs beyond its texel (a multi-channel read's
 * 16-bit channels). */
static int pick_level(const char *path, const vxl_zarr_store *s, const vxl_zarr_choice *ch,
                      const vxl_load_options *opt, uint32_t extra_bytes, int *level, vxl_err *e)
{
    if (ch->level >= 0) {
        if (ch->level >= s->nlevels)
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT, "'%s': level %d asked for, the image has %d (0 to %d)",
                            path, ch->level, s->nlevels, s->nlevels - 1);
        *level = ch->level;
        return VXL_OK;
    }
    vxl_err ignore = {0};
    for (int l = 0; l < s->nlevels; l++) {
        uint32_t dims[3];
        level_dims(s, l, dims);
        if (!vxl_volume_check_limits(dims, vxl_texture_bits_for(s->level[l].dtype) / 8 + extra_bytes, opt,
                                     &ignore)) {
            *level = l;
            return VXL_OK;
        }
    }
    *level = s->nlevels - 1; /* none fits: the coarsest, whose check names its size */
    return VXL_OK;
}

/* Copies the part of a decoded chunk inside the selected (t, c) into the
 * volume (x fastest). origin: the chunk's first element per dimension. */
static void copy_chunk(const vxl_zarr_store *s, const vxl_zarr_array *a, const uint64_t *origin,
                       const unsigned char *chunk, const uint64_t *sel, unsigned char *vol, const uint32_t dims[3])
{
    const size_t elem = vxl_dtype_size(a->dtype);
    const int ax = s->axis[VXL_ZARR_X], ay = s->axis[VXL_ZARR_Y], az = s->axis[VXL_ZARR_Z];
    uint64_t stride[VXL_ZARR_MAX_NDIM]; /* element strides inside the chunk, C order */
    uint64_t st = 1;
    for (int i = a->ndim - 1; i >= 0; i--) {
        stride[i] = st;
        st *= a->chunks[i];
    }
    uint64_t base = 0; /* the selected t and c inside the chunk */
    for (int r = VXL_ZARR_T; r <= VXL_ZARR_C; r++)
        if (s->axis[r] >= 0) base += (sel[r] - origin[s->axis[r]]) * stride[s->axis[r]];
    const uint64_t nx = origin[ax] + a->chunks[ax] > dims[0] ? dims[0] - origin[ax] : a->chunks[ax];
    const uint64_t ny = origin[ay] + a->chunks[ay] > dims[1] ? dims[1] - origin[ay] : a->chunks[ay];
    const uint64_t nz = origin[az] + a->chunks[az] > dims[2] ? dims[2] - origin[az] : a->chunks[az];
    for (uint64_t k = 0; k < nz; k++)
        for (uint64_t j = 0; j < ny; j++) {
            const uint64_t src = base + k * stride[az] + j * stride[ay];
            const uint64_t dst = ((origin[az] + k) * dims[1] + origin[ay] + j) * dims[0] + origin[ax];
            if (stride[ax] == 1) {
                memcpy(vol + dst * elem, chunk + src * elem, nx * elem);
            } else { /* x is not the last axis: element by element */
                for (uint64_t i = 0; i < nx; i++)
                    memcpy(vol + (dst + i) * elem, chunk + (src + i * stride[ax]) * elem, elem);
            }
        }
}

/* Reads every chunk of level a that holds voxels of the selected (t, c)
 * into raw (the volume in the array's type, native order). */
static int read_level(const char *path, const vxl_zarr_store *s, const vxl_zarr_array *a, const uint64_t *sel,
                      const uint32_t dims[3], const vxl_load_options *opt, unsigned char *raw, vxl_err *e)
{
    uint64_t lo[VXL_ZARR_MAX_NDIM], hi[VXL_ZARR_MAX_NDIM], total = 1;
    for (int i = 0; i < a->ndim; i++) {
        lo[i] = 0;
        hi[i] = (a->shape[i] + a->chunks[i] - 1) / a->chunks[i];
    }
    for (int r = VXL_ZARR_T; r <= VXL_ZARR_C; r++)
        if (s->axis[r] >= 0) {
            lo[s->axis[r]] = sel[r] / a->chunks[s->axis[r]];
            hi[s->axis[r]] = lo[s->axis[r]] + 1;
        }
    for (int i = 0; i < a->ndim; i++) {
        total *= hi[i] - lo[i];
        if (total > VXL_ZARR_MAX_CHUNKS)
            return vxl_fail(e, VXL_ERR_LIMIT, "'%s': over %llu chunks to read for one volume (chunks of %llu "
                            "elements are too small for this shape)", a->path,
                            (unsigned long long)VXL_ZARR_MAX_CHUNKS, (unsigned long long)a->chunks[i]);
    }
    const uint64_t cbytes = vxl_zarr_chunk_bytes(a);
    const uint64_t budget = vxl_load_budget(opt);
    if (cbytes > budget) /* the chunk buffer comes on top of the volume: never past the budget */
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': one chunk needs %.1f MiB, over the memory budget of %.1f MiB",
                        a->path, cbytes / 1048576.0, budget / 1048576.0);
    unsigned char *chunk = malloc((size_t)cbytes);
    vxl_zarr_codecs *codecs = vxl_zarr_codecs_new();
    if (!chunk || !codecs) {
        free(chunk);
        vxl_zarr_codecs_free(codecs);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for a chunk of %llu bytes", path,
                        (unsigned long long)cbytes);
    }
    uint64_t idx[VXL_ZARR_MAX_NDIM], origin[VXL_ZARR_MAX_NDIM];
    memcpy(idx, lo, sizeof idx);
    int rc = VXL_OK;
    for (uint64_t n = 0; n < total && !rc; n++) {
        for (int i = 0; i < a->ndim; i++) origin[i] = idx[i] * a->chunks[i];
        rc = vxl_zarr_read_chunk(a, idx, codecs, chunk, e);
        if (!rc) copy_chunk(s, a, origin, chunk, sel, raw, dims);
        for (int i = a->ndim - 1; i >= 0; i--) { /* next index, last dimension fastest */
            if (++idx[i] < hi[i]) break;
            idx[i] = lo[i];
        }
    }
    free(chunk);
    vxl_zarr_codecs_free(codecs);
    return rc;
}

int vxl_zarr_read(const char *path, const vxl_load_options *opt, vxl_volume **out, vxl_err *e)
{
    *out = NULL;
    char folder[4096];
    vxl_zarr_choice ch;
    int rc = vxl_zarr_parse_path(path, folder, sizeof folder, &ch, e);
    if (rc) return rc;
    vxl_zarr_store *s = calloc(1, sizeof *s);
    if (!s) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory");
    if ((rc = vxl_zarr_open(folder, s, e))) goto done;
    uint32_t channels = 0;
    if ((rc = vxl_zarr_channels(path, s, &ch, opt, &channels, e))) goto done;
    int l = 0;
    if ((rc = pick_level(path, s, &ch, opt, channels * VXL_CHANNEL_BYTES, &l, e))) goto done;
    const vxl_zarr_array *a = &s->level[l];
    uint64_t sel[VXL_ZARR_ROLES], nt;
    if ((rc = vxl_zarr_select(path, s, l, opt, &ch, sel, &nt, e))) goto done;
    if (channels && a->shape[s->axis[VXL_ZARR_C]] != channels) {
        rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s': level %d has %llu channels, level 0 has %u", path, l,
                      (unsigned long long)a->shape[s->axis[VXL_ZARR_C]], channels);
        goto done;
    }
    uint32_t dims[3];
    level_dims(s, l, dims);
    uint64_t nbytes;
    char where[4096 + 32];
    snprintf(where, sizeof where, "%s (level %d)", folder, l);
    /* channels: every one's raw plane at once (planar), charged to the budget
     * with the volume's 16-bit channels before anything is allocated */
    if (channels) rc = vxl_plan_channel_voxels(where, dims, a->dtype, channels, opt, &nbytes, e);
    else rc = vxl_plan_voxels(where, dims, a->dtype, opt, &nbytes, e);
    if (rc) goto done;
    unsigned char *raw = malloc((size_t)(nbytes * (channels ? channels : 1)));
    if (!raw) {
        rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for %llu bytes", path,
                      (unsigned long long)(nbytes * (channels ? channels : 1)));
        goto done;
    }
    rc = read_level(path, s, a, sel, dims, opt, raw, e);
    /* channel by channel, each into its plane: a chunk that spans several
     * channels is decoded once for each (simple, and only the whole read
     * runs this; the chunk buffer stays one chunk) */
    for (uint32_t c = 1; c < channels && !rc; c++) { /* channel 0 was sel's */
        sel[VXL_ZARR_C] = c;
        rc = read_level(path, s, a, sel, dims, opt, raw + c * nbytes, e);
    }
    if (!rc) {
        const int ix = s->axis[VXL_ZARR_X], iy = s->axis[VXL_ZARR_Y], iz = s->axis[VXL_ZARR_Z];
        const double sp[3] = {s->scale[l][ix], s->scale[l][iy], s->scale[l][iz]};
        const double dir[3][3] = {{sp[0], 0, 0}, {0, sp[1], 0}, {0, 0, sp[2]}};
        const double org[3] = {s->translation[l][ix], s->translation[l][iy], s->translation[l][iz]};
        double A[16];
        vxl_err inner = {0};
        if (!vxl_affine_from(dir, org, A)) {
            rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s': level %d's scale and translation make no affine", path, l);
        } else if ((rc = channels ? vxl_volume_build_channels(raw, a->dtype, channels, 0, dims, sp, A, 0.0, 0.0, opt,
                                                              "OME-Zarr c axis", out, &inner)
                                  : vxl_volume_build(raw, a->dtype, dims, sp, A, 0.0, 0.0, opt, out, &inner))) {
            rc = vxl_fail_in(e, path, &inner);
        } else {
            (*out)->affine_source = 2; /* a full affine from the file, as NRRD's and MetaImage's */
            (*out)->frame_count = (uint32_t)(nt > UINT32_MAX ? UINT32_MAX : nt);
            (*out)->frame = (uint32_t)sel[VXL_ZARR_T];
            if (channels) {
                memcpy((*out)->ch_meta, s->meta, sizeof s->meta[0] * channels);
                if (s->meta_notes[0]) vxl_volume_note(*out, "%s", s->meta_notes);
            }
        }
    }
    free(raw);
done:
    free(s);
    return rc;
}
