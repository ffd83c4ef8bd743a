/* zarr_store.c - OME-Zarr metadata: the group's "multiscales" (OME-NGFF
 * v0.4 in .zattrs on Zarr v2, v0.5 under attributes.ome in zarr.json on
 * Zarr v3) and each level's array metadata (.zarray, or zarr.json with its
 * codec chain). Everything is parsed by json.c under its size and depth
 * caps; every value is checked before use, and every error names the file. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "channel_meta.h"
#include "json.h"
#include "files.h"
#include "loader_util.h"
#include "zarr.h"

#define ZARR_MAX_EXTENT (1ull << 40) /* any axis of an array: absurd beyond this */

int vxl_zarr_read_file(const char *path, uint64_t max, char **text, size_t *len, uint64_t *size, vxl_err *e)
{
    vxl_path_info st;
    if (vxl_path_stat(path, &st)) {
        if (errno == ENOENT || errno == ENOTDIR) return VXL_ZARR_FILE_MISSING;
        return vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    }
    if (st.kind != VXL_PATH_FILE) return vxl_fail(e, VXL_ERR_FORMAT, "'%s' is not a regular file", path);
    *size = st.size;
    if (*size > max) return VXL_ZARR_FILE_TOO_LARGE;
    FILE *f = vxl_fopen(path, "rb");
    if (!f) return vxl_fail(e, VXL_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    char *buf = malloc((size_t)st.size + 1);
    if (!buf) {
        fclose(f);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory", path);
    }
    size_t n = fread(buf, 1, (size_t)st.size, f);
    fclose(f);
    if (n != (size_t)st.size) {
        free(buf);
        return vxl_fail(e, VXL_ERR_IO, "'%s': short read", path);
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return 0;
}

static int parse_doc(const char *text, size_t len, const char *name, vxl_json_doc *d, vxl_err *e)
{
    char err[160];
    if (vxl_json_parse(text, len, d, err, sizeof err))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': not valid JSON (%s)", name, err);
    return VXL_OK;
}

/* A JSON number that is a whole number in [lo, hi]. */
static int get_u64(const vxl_json *v, uint64_t lo, uint64_t hi, uint64_t *out)
{
    if (!v || v->type != VXL_JSON_NUMBER || !v->is_integer || v->num < (double)lo || v->num > (double)hi) return 0;
    *out = (uint64_t)v->num;
    return 1;
}

/* An array of n whole numbers in [1, ZARR_MAX_EXTENT]. */
static int get_extents(const vxl_json_doc *d, const vxl_json *arr, int n, uint64_t *out)
{
    if (!arr || arr->type != VXL_JSON_ARRAY || arr->count != (uint32_t)n) return 0;
    int i = 0;
    for (int32_t k = arr->first; k >= 0; k = d->nodes[k].next, i++)
        if (!get_u64(&d->nodes[k], 1, ZARR_MAX_EXTENT, &out[i])) return 0;
    return 1;
}

/* An array of n finite numbers. */
static int get_numbers(const vxl_json_doc *d, const vxl_json *arr, int n, double *out)
{
    if (!arr || arr->type != VXL_JSON_ARRAY || arr->count != (uint32_t)n) return 0;
    int i = 0;
    for (int32_t k = arr->first; k >= 0; k = d->nodes[k].next, i++) {
        if (d->nodes[k].type != VXL_JSON_NUMBER) return 0;
        out[i] = d->nodes[k].num;
    }
    return 1;
}

/* fill_value: a number, null (0), or "NaN"/"Infinity"/"-Infinity". */
static int get_fill(const vxl_json *v, double *out)
{
    if (!v || v->type == VXL_JSON_NULL) *out = 0.0;
    else if (v->type == VXL_JSON_NUMBER) *out = v->num;
    else if (v->type == VXL_JSON_TRUE || v->type == VXL_JSON_FALSE) *out = v->type == VXL_JSON_TRUE;
    else if (v->type == VXL_JSON_STRING && !strcmp(v->str, "NaN")) *out = NAN;
    else if (v->type == VXL_JSON_STRING && !strcmp(v->str, "Infinity")) *out = INFINITY;
    else if (v->type == VXL_JSON_STRING && !strcmp(v->str, "-Infinity")) *out = -INFINITY;
    else return 0;
    return 1;
}

/* Applies one list of coordinateTransformations (scale, then an optional
 * translation) to scale/translation: world = s * index + t. */
static int apply_transforms(const vxl_json_doc *d, const vxl_json *list, int ndim, double *scale,
                            double *translation, const char *name, vxl_err *e)
{
    if (!list) return VXL_OK;
    if (list->type != VXL_JSON_ARRAY)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': coordinateTransformations is not a list", name);
    for (int32_t k = list->first; k >= 0; k = d->nodes[k].next) {
        const vxl_json *t = &d->nodes[k];
        const char *type = vxl_json_string(vxl_json_get(d, t, "type"));
        double v[VXL_ZARR_MAX_NDIM];
        if (type && !strcmp(type, "identity")) continue;
        if (!type || (strcmp(type, "scale") && strcmp(type, "translation")))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unsupported coordinate transformation '%s' (scale and "
                            "translation are read)", name, type ? type : "?");
        if (vxl_json_get(d, t, "path"))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': transformations stored in a file are not supported", name);
        int is_scale = !strcmp(type, "scale");
        if (!get_numbers(d, vxl_json_get(d, t, type), ndim, v))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': a %s needs %d numbers", name, type, ndim);
        for (int i = 0; i < ndim; i++) {
            if (is_scale) {
                if (!(v[i] > 0) || !isfinite(v[i]))
                    return vxl_fail(e, VXL_ERR_FORMAT, "'%s': scale %g is not positive", name, v[i]);
                scale[i] *= v[i];
                translation[i] *= v[i];
            } else {
                translation[i] += v[i];
            }
        }
    }
    return VXL_OK;
}

static int role_of(const char *name)
{
    static const char *names[VXL_ZARR_ROLES] = {"t", "c", "z", "y", "x"};
    for (int r = 0; r < VXL_ZARR_ROLES; r++)
        if (!strcmp(name, names[r])) return r;
    return -1;
}

/* The factor from an NGFF length unit to mm; 0 for a unit that is not a
 * length this reader knows (kept as written). */
static double unit_to_mm(const char *unit)
{
    static const struct { const char *name; double mm; } map[] = {
        {"meter", 1e3}, {"decimeter", 1e2}, {"centimeter", 10}, {"millimeter", 1}, {"micrometer", 1e-3},
        {"nanometer", 1e-6}, {"picometer", 1e-9}, {"angstrom", 1e-7}, {"femtometer", 1e-12}, {"kilometer", 1e6},
        {"inch", 25.4}, {"foot", 304.8}, {"yard", 914.4}, {"mile", 1609344},
    };
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (!strcmp(unit, map[i].name)) return map[i].mm;
    return 0;
}

static int parse_axes(const vxl_json_doc *d, const vxl_json *axes, const char *name, vxl_zarr_store *s, vxl_err *e)
{
    if (axes && axes->type == VXL_JSON_ARRAY && axes->count < 3)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %u axes: 2D images are not volumes (z, y and x are needed)", name,
                        axes->count);
    if (!axes || axes->type != VXL_JSON_ARRAY || axes->count > VXL_ZARR_MAX_NDIM)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': multiscales needs \"axes\" with 3 to %d entries (z, y, x; "
                        "optionally t and c)", name, VXL_ZARR_MAX_NDIM);
    for (int r = 0; r < VXL_ZARR_ROLES; r++) s->axis[r] = -1;
    s->ndim = (int)axes->count;
    int i = 0;
    for (int32_t k = axes->first; k >= 0; k = d->nodes[k].next, i++) {
        const vxl_json *a = &d->nodes[k];
        /* v0.4 and later: {"name", "type", "unit"}; v0.3: a bare name */
        const char *an = a->type == VXL_JSON_STRING ? a->str : vxl_json_string(vxl_json_get(d, a, "name"));
        int r = an ? role_of(an) : -1;
        if (r < 0)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': axis '%s' is not one of t, c, z, y, x", name, an ? an : "?");
        if (s->axis[r] >= 0) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': axis '%s' appears twice", name, an);
        s->axis[r] = i;
        const char *unit = vxl_json_string(vxl_json_get(d, a, "unit"));
        if (r == VXL_ZARR_X && unit) snprintf(s->unit, sizeof s->unit, "%s", unit);
        const double mm = unit && r >= VXL_ZARR_Z ? unit_to_mm(unit) : 0;
        s->to_mm[i] = mm > 0 ? mm : 1.0;
    }
    if (s->axis[VXL_ZARR_Z] < 0 || s->axis[VXL_ZARR_Y] < 0 || s->axis[VXL_ZARR_X] < 0)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the axes lack z, y or x (2D images are not volumes)", name);
    return VXL_OK;
}

/* omero.channels[c].window: "min"/"max" (the data's range), else
 * "start"/"end"; a channel without two finite, ordered numbers has none. */
static void parse_windows(const vxl_json_doc *d, const vxl_json *omero, vxl_zarr_store *s)
{
    const vxl_json *ch = vxl_json_get(d, omero, "channels");
    if (!ch || ch->type != VXL_JSON_ARRAY) return;
    int c = 0;
    for (int32_t k = ch->first; k >= 0 && c < VXL_ZARR_MAX_WINDOWS; k = d->nodes[k].next, c++) {
        const vxl_json *w = vxl_json_get(d, &d->nodes[k], "window");
        static const char *keys[2][2] = {{"min", "max"}, {"start", "end"}};
        for (int pair = 0; pair < 2 && !s->window_set[c]; pair++) {
            const vxl_json *lo = vxl_json_get(d, w, keys[pair][0]), *hi = vxl_json_get(d, w, keys[pair][1]);
            if (lo && hi && lo->type == VXL_JSON_NUMBER && hi->type == VXL_JSON_NUMBER && isfinite(lo->num) &&
                isfinite(hi->num) && lo->num < hi->num) {
                s->window[c][0] = lo->num;
                s->window[c][1] = hi->num;
                s->window_set[c] = 1;
            }
        }
    }
    s->window_count = c;
}

/* Appends one sentence to s->meta_notes ("; "-joined, dropped when full). */
static void meta_note(vxl_zarr_store *s, const char *what, int c)
{
    const size_t n = strlen(s->meta_notes);
    const int w = snprintf(s->meta_notes + n, sizeof s->meta_notes - n, "%somero channel %d's %s", n ? "; " : "", c,
                           what);
    if (w < 0 || (size_t)w >= sizeof s->meta_notes - n) s->meta_notes[n] = '\0';
}

/* omero.channels[c]: "label", "color" (RRGGBB, sRGB), the display window
 * "start"/"end" and "active", for the channels a multi-channel read keeps.
 * A value of the wrong form is left unknown and noted, never guessed. */
static void parse_channel_meta(const vxl_json_doc *d, const vxl_json *omero, vxl_zarr_store *s)
{
    const vxl_json *ch = vxl_json_get(d, omero, "channels");
    if (!ch || ch->type != VXL_JSON_ARRAY) return;
    int c = 0;
    for (int32_t k = ch->first; k >= 0 && c < VXL_MAX_CHANNELS; k = d->nodes[k].next, c++) {
        const vxl_json *o = &d->nodes[k];
        vxl_channel_meta *m = &s->meta[c];
        const vxl_json *label = vxl_json_get(d, o, "label"), *color = vxl_json_get(d, o, "color");
        if (label) {
            const int r = label->type == VXL_JSON_STRING ? vxl_channel_meta_name(m, label->str) : VXL_META_REFUSED;
            if (r == VXL_META_CUT) meta_note(s, "label cut to 63 bytes", c);
            else if (r == VXL_META_REFUSED) meta_note(s, "label ignored (not a line of text)", c);
        }
        if (color && (color->type != VXL_JSON_STRING || vxl_channel_meta_hex(m, color->str) != VXL_META_TAKEN))
            meta_note(s, "color ignored (not RRGGBB)", c);
        const vxl_json *w = vxl_json_get(d, o, "window");
        const vxl_json *lo = vxl_json_get(d, w, "start"), *hi = vxl_json_get(d, w, "end");
        if (lo && hi) {
            if (lo->type == VXL_JSON_NUMBER && hi->type == VXL_JSON_NUMBER && isfinite(lo->num) &&
                isfinite(hi->num) && lo->num < hi->num) {
                m->window[0] = lo->num;
                m->window[1] = hi->num;
                m->has_window = 1;
            } else {
                meta_note(s, "window ignored (start is not below end)", c);
            }
        }
        const vxl_json *active = vxl_json_get(d, o, "active");
        if (active && active->type == VXL_JSON_FALSE) m->hidden = 1;
        else if (active && active->type != VXL_JSON_TRUE) meta_note(s, "active ignored (not true or false)", c);
    }
}

int vxl_zarr_parse_group(const char *text, size_t len, int is_v3, const char *name, vxl_zarr_store *s,
                         vxl_err *e)
{
    vxl_json_doc d;
    int rc = parse_doc(text, len, name, &d, e);
    if (rc) return rc;
    const vxl_json *root = &d.nodes[0], *attrs = root;
    if (is_v3) {
        uint64_t fmt = 0;
        if (!get_u64(vxl_json_get(&d, root, "zarr_format"), 3, 3, &fmt)) {
            rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s': zarr_format is not 3", name);
            goto done;
        }
        const char *node = vxl_json_string(vxl_json_get(&d, root, "node_type"));
        if (node && !strcmp(node, "array")) {
            rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s' is a Zarr array, not an OME-Zarr image group: open the "
                          "folder holding the multiscales", name);
            goto done;
        }
        attrs = vxl_json_get(&d, vxl_json_get(&d, root, "attributes"), "ome");
    }
    const vxl_json *ms = vxl_json_get(&d, attrs, "multiscales");
    if (!ms || ms->type != VXL_JSON_ARRAY || ms->count < 1) {
        rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s' has no OME-Zarr \"multiscales\"%s", name,
                      vxl_json_get(&d, attrs, "plate") || vxl_json_get(&d, attrs, "bioformats2raw.layout")
                          ? " (a plate or a bioformats2raw container: open one image's folder)" : "");
        goto done;
    }
    const vxl_json *m = vxl_json_at(&d, ms, 0); /* the first multiscale image */
    if ((rc = parse_axes(&d, vxl_json_get(&d, m, "axes"), name, s, e))) goto done;
    const vxl_json *ds = vxl_json_get(&d, m, "datasets");
    if (!ds || ds->type != VXL_JSON_ARRAY || ds->count < 1 || ds->count > VXL_ZARR_MAX_LEVELS) {
        rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s': multiscales needs 1 to %d \"datasets\"", name, VXL_ZARR_MAX_LEVELS);
        goto done;
    }
    s->nlevels = (int)ds->count;
    int i = 0;
    for (int32_t k = ds->first; k >= 0; k = d.nodes[k].next, i++) {
        const vxl_json *level = &d.nodes[k];
        const char *p = vxl_json_string(vxl_json_get(&d, level, "path"));
        /* a level's path stays inside the store: no "..", no absolute path */
        if (!p || !*p || p[0] == '/' || strstr(p, "..") || strlen(p) > 255) {
            rc = vxl_fail(e, VXL_ERR_FORMAT, "'%s': dataset %d has no usable \"path\"", name, i);
            goto done;
        }
        snprintf(s->level[i].path, sizeof s->level[i].path, "%s", p);
        for (int a = 0; a < s->ndim; a++) {
            s->scale[i][a] = 1.0;
            s->translation[i][a] = 0.0;
        }
        if ((rc = apply_transforms(&d, vxl_json_get(&d, level, "coordinateTransformations"), s->ndim, s->scale[i],
                                   s->translation[i], name, e)))
            goto done;
        if ((rc = apply_transforms(&d, vxl_json_get(&d, m, "coordinateTransformations"), s->ndim, s->scale[i],
                                   s->translation[i], name, e)))
            goto done;
        for (int a = 0; a < s->ndim; a++) { /* the axes' units to mm */
            s->scale[i][a] *= s->to_mm[a];
            s->translation[i][a] *= s->to_mm[a];
        }
    }
    parse_windows(&d, vxl_json_get(&d, attrs, "omero"), s);
    parse_channel_meta(&d, vxl_json_get(&d, attrs, "omero"), s);
done:
    vxl_json_free(&d);
    return rc;
}

/* Zarr v2 dtype strings ("<u2", ">f4", "|u1"). */
static int v2_dtype(const char *t, uint32_t *dtype, int *big)
{
    static const struct { const char *code; uint32_t dtype; } map[] = {
        {"u1", VXL_DTYPE_U8}, {"i1", VXL_DTYPE_I8}, {"u2", VXL_DTYPE_U16}, {"i2", VXL_DTYPE_I16},
        {"u4", VXL_DTYPE_U32}, {"i4", VXL_DTYPE_I32}, {"f4", VXL_DTYPE_F32}, {"f8", VXL_DTYPE_F64},
    };
    if (!t || strlen(t) != 3 || (t[0] != '<' && t[0] != '>' && t[0] != '|')) return 0;
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (!strcmp(t + 1, map[i].code)) {
            *dtype = map[i].dtype;
            *big = t[0] == '>';
            /* '|' (no byte order) only for one-byte types */
            return t[0] != '|' || vxl_dtype_size(map[i].dtype) == 1;
        }
    return 0;
}

static int v3_dtype(const char *t, uint32_t *dtype)
{
    static const struct { const char *name; uint32_t dtype; } map[] = {
        {"uint8", VXL_DTYPE_U8}, {"int8", VXL_DTYPE_I8}, {"uint16", VXL_DTYPE_U16}, {"int16", VXL_DTYPE_I16},
        {"uint32", VXL_DTYPE_U32}, {"int32", VXL_DTYPE_I32}, {"float32", VXL_DTYPE_F32}, {"float64", VXL_DTYPE_F64},
    };
    for (size_t i = 0; t && i < sizeof map / sizeof map[0]; i++)
        if (!strcmp(t, map[i].name)) {
            *dtype = map[i].dtype;
            return 1;
        }
    return 0;
}

/* A compressor's or codec's name as ours; -1 unknown. */
static int codec_of(const char *id)
{
    if (!id) return -1;
    if (!strcmp(id, "gzip") || !strcmp(id, "zlib")) return VXL_ZARR_ZLIB;
    if (!strcmp(id, "zstd")) return VXL_ZARR_ZSTD;
    if (!strcmp(id, "blosc")) return VXL_ZARR_BLOSC;
    return -1;
}

static int parse_v2(const vxl_json_doc *d, const char *name, vxl_zarr_array *a, vxl_err *e)
{
    const vxl_json *root = &d->nodes[0];
    uint64_t fmt;
    if (!get_u64(vxl_json_get(d, root, "zarr_format"), 2, 2, &fmt))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': zarr_format is not 2", name);
    const vxl_json *shape = vxl_json_get(d, root, "shape");
    a->ndim = shape && shape->type == VXL_JSON_ARRAY ? (int)shape->count : 0;
    if (a->ndim < 1 || a->ndim > VXL_ZARR_MAX_NDIM || !get_extents(d, shape, a->ndim, a->shape) ||
        !get_extents(d, vxl_json_get(d, root, "chunks"), a->ndim, a->chunks))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': \"shape\" and \"chunks\" need 1 to %d positive whole numbers "
                        "each, as many of one as of the other", name, VXL_ZARR_MAX_NDIM);
    const char *dt = vxl_json_string(vxl_json_get(d, root, "dtype"));
    if (!v2_dtype(dt, &a->dtype, &a->big_endian))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unsupported dtype '%s' (u1/i1/u2/i2/u4/i4/f4/f8 are read)", name,
                        dt ? dt : "?");
    const char *order = vxl_json_string(vxl_json_get(d, root, "order"));
    if (order && strcmp(order, "C"))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': order '%s' is not supported (only \"C\")", name, order);
    const vxl_json *filters = vxl_json_get(d, root, "filters");
    if (filters && !(filters->type == VXL_JSON_NULL || (filters->type == VXL_JSON_ARRAY && filters->count == 0)))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': filters are not supported", name);
    const vxl_json *comp = vxl_json_get(d, root, "compressor");
    if (!comp || comp->type == VXL_JSON_NULL) a->codec = VXL_ZARR_RAW;
    else {
        const char *id = vxl_json_string(vxl_json_get(d, comp, "id"));
        if ((a->codec = codec_of(id)) < 0)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': compressor '%s' is not supported (blosc, zstd, gzip, zlib "
                            "or none)", name, id ? id : "?");
    }
    if (!get_fill(vxl_json_get(d, root, "fill_value"), &a->fill))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unsupported fill_value", name);
    const char *sep = vxl_json_string(vxl_json_get(d, root, "dimension_separator"));
    if (sep && strcmp(sep, ".") && strcmp(sep, "/"))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': dimension_separator must be \".\" or \"/\"", name);
    a->separator = sep ? sep[0] : '.';
    a->key_prefix = 0;
    a->zarr_format = 2;
    return VXL_OK;
}

static int parse_v3_codecs(const vxl_json_doc *d, const vxl_json *codecs, const char *name, vxl_zarr_array *a,
                           vxl_err *e)
{
    if (!codecs || codecs->type != VXL_JSON_ARRAY || codecs->count < 1)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': \"codecs\" is missing or empty", name);
    int have_bytes = 0, i = 0;
    a->codec = VXL_ZARR_RAW;
    for (int32_t k = codecs->first; k >= 0; k = d->nodes[k].next, i++) {
        const vxl_json *c = &d->nodes[k];
        const char *cn = vxl_json_string(vxl_json_get(d, c, "name"));
        const vxl_json *cfg = vxl_json_get(d, c, "configuration");
        if (!cn) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': codec %d has no name", name, i);
        if (!strcmp(cn, "sharding_indexed"))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': sharded arrays (sharding_indexed) are not supported yet: "
                            "rewrite the store without shards", name);
        if (!strcmp(cn, "bytes")) {
            if (have_bytes || i != 0)
                return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the \"bytes\" codec must come first, once (array-to-"
                                "array codecs such as transpose are not supported)", name);
            have_bytes = 1;
            const char *endian = vxl_json_string(vxl_json_get(d, cfg, "endian"));
            if (endian && strcmp(endian, "little") && strcmp(endian, "big"))
                return vxl_fail(e, VXL_ERR_FORMAT, "'%s': endian '%s' is neither little nor big", name, endian);
            if (!endian && vxl_dtype_size(a->dtype) > 1)
                return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the bytes codec needs an endian for %u-byte data",
                                name, vxl_dtype_size(a->dtype));
            a->big_endian = endian && !strcmp(endian, "big");
            continue;
        }
        int codec = codec_of(cn);
        if (codec < 0 || !strcmp(cn, "zlib"))
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': codec '%s' is not supported (bytes, then one of blosc, "
                            "zstd, gzip)", name, cn);
        if (!have_bytes || a->codec != VXL_ZARR_RAW)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': codec '%s' must follow \"bytes\", alone", name, cn);
        a->codec = codec;
    }
    if (!have_bytes) return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the codecs lack \"bytes\"", name);
    return VXL_OK;
}

static int parse_v3(const vxl_json_doc *d, const char *name, vxl_zarr_array *a, vxl_err *e)
{
    const vxl_json *root = &d->nodes[0];
    uint64_t fmt;
    if (!get_u64(vxl_json_get(d, root, "zarr_format"), 3, 3, &fmt))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': zarr_format is not 3", name);
    const char *node = vxl_json_string(vxl_json_get(d, root, "node_type"));
    if (!node || strcmp(node, "array")) return vxl_fail(e, VXL_ERR_FORMAT, "'%s' is not a Zarr array", name);
    const vxl_json *shape = vxl_json_get(d, root, "shape");
    a->ndim = shape && shape->type == VXL_JSON_ARRAY ? (int)shape->count : 0;
    const vxl_json *grid = vxl_json_get(d, root, "chunk_grid");
    const char *gn = vxl_json_string(vxl_json_get(d, grid, "name"));
    if (!gn || strcmp(gn, "regular"))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': chunk_grid '%s' is not supported (only \"regular\")", name,
                        gn ? gn : "?");
    if (a->ndim < 1 || a->ndim > VXL_ZARR_MAX_NDIM || !get_extents(d, shape, a->ndim, a->shape) ||
        !get_extents(d, vxl_json_get(d, vxl_json_get(d, grid, "configuration"), "chunk_shape"), a->ndim, a->chunks))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': \"shape\" and \"chunk_shape\" need 1 to %d positive whole numbers "
                        "each, as many of one as of the other", name, VXL_ZARR_MAX_NDIM);
    const char *dt = vxl_json_string(vxl_json_get(d, root, "data_type"));
    if (!v3_dtype(dt, &a->dtype))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unsupported data_type '%s' (uint8/int8/uint16/int16/uint32/int32/"
                        "float32/float64 are read)", name, dt ? dt : "?");
    const vxl_json *keys = vxl_json_get(d, root, "chunk_key_encoding");
    const char *kn = vxl_json_string(vxl_json_get(d, keys, "name"));
    const char *sep = vxl_json_string(vxl_json_get(d, vxl_json_get(d, keys, "configuration"), "separator"));
    if (!kn || (strcmp(kn, "default") && strcmp(kn, "v2")))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': chunk_key_encoding '%s' is not supported (default or v2)", name,
                        kn ? kn : "?");
    a->key_prefix = !strcmp(kn, "default");
    if (sep && strcmp(sep, ".") && strcmp(sep, "/"))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': the chunk key separator must be \".\" or \"/\"", name);
    a->separator = sep ? sep[0] : (a->key_prefix ? '/' : '.');
    if (!get_fill(vxl_json_get(d, root, "fill_value"), &a->fill))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': unsupported fill_value", name);
    if (vxl_json_get(d, root, "storage_transformers") &&
        vxl_json_get(d, root, "storage_transformers")->count)
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s': storage transformers are not supported", name);
    a->zarr_format = 3;
    return parse_v3_codecs(d, vxl_json_get(d, root, "codecs"), name, a, e);
}

int vxl_zarr_parse_array(const char *text, size_t len, int is_v3, const char *name, vxl_zarr_array *a, vxl_err *e)
{
    vxl_json_doc d;
    int rc = parse_doc(text, len, name, &d, e);
    if (rc) return rc;
    rc = is_v3 ? parse_v3(&d, name, a, e) : parse_v2(&d, name, a, e);
    vxl_json_free(&d);
    if (!rc && !vxl_zarr_chunk_bytes(a))
        rc = vxl_fail(e, VXL_ERR_LIMIT, "'%s': a chunk of this array would be over %llu MiB decoded", name,
                      (unsigned long long)(VXL_ZARR_MAX_CHUNK_BYTES >> 20));
    return rc;
}

uint64_t vxl_zarr_chunk_bytes(const vxl_zarr_array *a)
{
    uint64_t n = vxl_dtype_size(a->dtype);
    if (!n || a->ndim < 1 || a->ndim > VXL_ZARR_MAX_NDIM) return 0;
    for (int i = 0; i < a->ndim; i++) {
        if (!a->chunks[i] || a->chunks[i] > VXL_ZARR_MAX_CHUNK_BYTES / n) return 0;
        n *= a->chunks[i];
    }
    return n;
}

static int parse_file(const char *path, int is_v3, int is_group, vxl_zarr_store *s, vxl_zarr_array *a, vxl_err *e)
{
    char *text = NULL;
    size_t len = 0;
    uint64_t size = 0;
    int rc = vxl_zarr_read_file(path, VXL_JSON_MAX_BYTES, &text, &len, &size, e);
    if (rc == VXL_ZARR_FILE_MISSING) return vxl_fail(e, VXL_ERR_FORMAT, "'%s' is missing", path);
    if (rc == VXL_ZARR_FILE_TOO_LARGE)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': %llu bytes of metadata, over the limit of %u", path,
                        (unsigned long long)size, VXL_JSON_MAX_BYTES);
    if (rc) return rc;
    rc = is_group ? vxl_zarr_parse_group(text, len, is_v3, path, s, e)
                  : vxl_zarr_parse_array(text, len, is_v3, path, a, e);
    free(text);
    return rc;
}

int vxl_zarr_open(const char *root, vxl_zarr_store *s, vxl_err *e)
{
    memset(s, 0, sizeof *s);
    char p[4096 + 64];
    vxl_path_info st;
    snprintf(p, sizeof p, "%s/zarr.json", root);
    const int v3 = vxl_path_stat(p, &st) == 0;
    if (!v3) snprintf(p, sizeof p, "%s/.zattrs", root);
    int rc = parse_file(p, v3, 1, s, NULL, e);
    if (rc) return rc;
    s->zarr_format = v3 ? 3 : 2;
    for (int i = 0; i < s->nlevels; i++) {
        vxl_zarr_array *a = &s->level[i];
        char rel[256];
        snprintf(rel, sizeof rel, "%s", a->path);
        if (snprintf(a->path, sizeof a->path, "%s/%s", root, rel) >= (int)sizeof a->path)
            return vxl_fail(e, VXL_ERR_IO, "'%s': path too long", root);
        snprintf(p, sizeof p, "%s/%s", a->path, v3 ? "zarr.json" : ".zarray");
        char keep[4096];
        memcpy(keep, a->path, sizeof keep);
        if ((rc = parse_file(p, v3, 0, NULL, a, e))) return rc;
        memcpy(a->path, keep, sizeof keep);
        if (a->ndim != s->ndim)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': %d dimensions, but the multiscales name %d axes", p, a->ndim,
                            s->ndim);
    }
    return VXL_OK;
}
