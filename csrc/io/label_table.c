/* label_table.c - vxl_label_table_load: label names and colours from the
 * common lookup files (docs/labels.md has every decision):
 *   FreeSurfer LUT      `id name R G B T`, T = 255 - alpha (FreeSurfer's own reader)
 *   3D Slicer .ctbl     `id name R G B A`, A = opacity 0..255
 *   ITK-SNAP labels     `IDX R G B A VIS MSH "LABEL"`, A = opacity 0..1
 *   MRIcron pair        .lut: 768 bytes, 256 reds then 256 greens then 256
 *                       blues; names from `index name` lines in the .txt of
 *                       the same stem (either file may be the one opened)
 * The format comes from the content: a 768-byte palette, then the header
 * comments and the first data line; the extension only separates Slicer
 * from FreeSurfer (same columns, opposite alpha) when no comment says which.
 * Every file is read whole under a size cap, every line under a length cap;
 * numbers are parsed strictly, ids are int32, a repeated id is an error
 * naming both lines, names are cut to valid UTF-8 of at most 63 bytes. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "error.h"
#include "files.h"
#include "loader_util.h"
#include "voxlight.h"

#define LABEL_LINE_MAX 1024u        /* bytes per line; real lines are < 200 */
#define LABEL_ENTRIES_MAX 65536u    /* labels per table */
#define MRICRON_LUT_BYTES 768u      /* 256 x R, then G, then B */
#define NAME_BYTES 63u              /* vxl_label_entry.name minus its NUL */

typedef enum { FMT_FREESURFER, FMT_SLICER, FMT_ITKSNAP, FMT_NAMES, FMT_UNKNOWN } label_format;

static const char *const format_names[] = {"FreeSurfer LUT", "3D Slicer colour table", "ITK-SNAP label description",
                                           "MRIcron label names"};

/* One parsed entry and the line it came from (for duplicate messages). */
typedef struct label_row {
    vxl_label_entry e;
    uint32_t line;
} label_row;

typedef struct label_rows {
    label_row *v;
    uint32_t n, cap;
} label_rows;

/* ------------------------------------------------------------ helpers */

/* Whether path names a regular file; unlike vxl_regular_file it records no
 * error, since a missing companion file is not one. */
static int is_regular_file(const char *path) { return vxl_is_file(path); }

static int has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcasecmp(s + n - k, suffix) == 0;
}

/* path with its last extension (".lut"/".txt") replaced; malloc'd. */
static char *swap_extension(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.'), *slash = vxl_path_last_separator(path);
    size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - path) : strlen(path);
    char *p = malloc(stem + strlen(ext) + 1);
    if (!p) return NULL;
    memcpy(p, path, stem);
    strcpy(p + stem, ext);
    return p;
}

/* Length of the valid UTF-8 sequence at s (n bytes left), 0 if invalid
 * (overlong forms, surrogates and code points past U+10FFFF included). */
static size_t utf8_sequence(const unsigned char *s, size_t n)
{
    if (s[0] < 0x80) return 1;
    size_t len = s[0] >= 0xC2 && s[0] <= 0xDF ? 2 : s[0] >= 0xE0 && s[0] <= 0xEF ? 3 : s[0] >= 0xF0 && s[0] <= 0xF4 ? 4 : 0;
    if (!len || len > n) return 0;
    for (size_t i = 1; i < len; i++)
        if ((s[i] & 0xC0) != 0x80) return 0;
    if ((s[0] == 0xE0 && s[1] < 0xA0) || (s[0] == 0xED && s[1] > 0x9F) || (s[0] == 0xF0 && s[1] < 0x90) ||
        (s[0] == 0xF4 && s[1] > 0x8F))
        return 0;
    return len;
}

/* Copies a name into dst[64]: valid UTF-8 only (an invalid byte or a
 * control character becomes '?'), cut before the character that would pass
 * 63 bytes, so the result is always valid UTF-8 and NUL-terminated. */
static void copy_name(char dst[64], const char *src, size_t n)
{
    const unsigned char *s = (const unsigned char *)src;
    size_t o = 0;
    for (size_t i = 0; i < n;) {
        size_t len = utf8_sequence(s + i, n - i);
        if (len == 1 && (s[i] < 0x20 || s[i] == 0x7F)) len = 0;
        size_t out = len ? len : 1;
        if (o + out > NAME_BYTES) break;
        if (len) memcpy(dst + o, s + i, len);
        else dst[o] = '?';
        o += out;
        i += len ? len : 1;
    }
    dst[o] = '\0';
}

/* Whitespace-separated tokens of a line: the next one at *s, or 0 at the end. */
static size_t next_token(const char **s, const char **tok)
{
    const char *p = *s;
    while (*p == ' ' || *p == '\t' || *p == '\v' || *p == '\f') p++;
    *tok = p;
    while (*p && *p != ' ' && *p != '\t' && *p != '\v' && *p != '\f') p++;
    *s = p;
    return (size_t)(p - *tok);
}

/* A decimal integer token (optional sign) within [lo, hi]. */
static int parse_int(const char *tok, size_t len, long long lo, long long hi, long long *out)
{
    size_t i = 0;
    int neg = 0;
    if (i < len && (tok[i] == '-' || tok[i] == '+')) neg = tok[i++] == '-';
    if (i == len) return 0;
    long long v = 0;
    for (; i < len; i++) {
        if (tok[i] < '0' || tok[i] > '9') return 0;
        v = v * 10 + (tok[i] - '0');
        if (v > 4294967296LL) return 0; /* far past int32 either way: stop before overflow */
    }
    v = neg ? -v : v;
    if (v < lo || v > hi) return 0;
    *out = v;
    return 1;
}

/* A finite decimal number token within [lo, hi]. */
static int parse_real(const char *tok, size_t len, double lo, double hi, double *out)
{
    char buf[64];
    if (len == 0 || len >= sizeof buf) return 0;
    memcpy(buf, tok, len);
    buf[len] = '\0';
    char *end = NULL;
    errno = 0;
    double v = strtod(buf, &end);
    if (end != buf + len || !isfinite(v) || v < lo || v > hi) return 0;
    *out = v;
    return 1;
}

/* The default colour of a label with none in its file: hues spaced by the
 * golden ratio (neighbouring ids far apart on the colour wheel), saturation
 * 0.65, value 0.95. Deterministic; docs/labels.md states the formula. */
static void default_color(int32_t id, float rgba[4])
{
    double h = fmod((double)id * 0.6180339887498949, 1.0);
    if (h < 0) h += 1.0;
    const double s = 0.65, v = 0.95;
    double f = h * 6.0;
    int sector = (int)f % 6;
    double frac = f - floor(f);
    double p = v * (1 - s), q = v * (1 - s * frac), t = v * (1 - s * (1 - frac));
    double r = v, g = t, b = p;
    switch (sector) {
    case 1: r = q, g = v, b = p; break;
    case 2: r = p, g = v, b = t; break;
    case 3: r = p, g = q, b = v; break;
    case 4: r = t, g = p, b = v; break;
    case 5: r = v, g = p, b = q; break;
    default: break;
    }
    rgba[0] = (float)r;
    rgba[1] = (float)g;
    rgba[2] = (float)b;
    rgba[3] = 1.0f;
}

static int add_row(label_rows *rows, const char *path, const label_row *row, vxl_err *e)
{
    if (rows->n == LABEL_ENTRIES_MAX)
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s': more than %u labels (line %u)", path, LABEL_ENTRIES_MAX, row->line);
    if (rows->n == rows->cap) {
        uint32_t cap = rows->cap ? rows->cap * 2 : 64;
        label_row *v = realloc(rows->v, cap * sizeof *v);
        if (!v) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory for %u labels", path, cap);
        rows->v = v;
        rows->cap = cap;
    }
    rows->v[rows->n++] = *row;
    return VXL_OK;
}

/* --------------------------------------------------------- line parsers */

/* Each parser reads one data line (comments and blank lines never reach
 * it) into row->e; 0 on success, else a short reason for the message. */
typedef const char *(*line_parser)(const char *line, label_row *row);

static const char *parse_id(const char **s, label_row *row)
{
    const char *tok;
    size_t n = next_token(s, &tok);
    long long id;
    if (!parse_int(tok, n, INT32_MIN, INT32_MAX, &id)) return "the label id is not an integer in the int32 range";
    row->e.id = (int32_t)id;
    return NULL;
}

static const char *parse_rgb(const char **s, float rgb[3])
{
    for (int c = 0; c < 3; c++) {
        const char *tok;
        size_t n = next_token(s, &tok);
        long long v;
        if (!parse_int(tok, n, 0, 255, &v)) return "a colour component is not an integer 0..255";
        rgb[c] = (float)v / 255.0f;
    }
    return NULL;
}

static int at_end(const char *s)
{
    const char *tok;
    return next_token(&s, &tok) == 0;
}

/* `id name R G B A` (FreeSurfer: A is transparency, and a 7th column, the
 * tissue type, may follow; Slicer: A is opacity, six columns). */
static const char *parse_rgba_line(const char *line, label_row *row, int freesurfer)
{
    const char *s = line, *tok, *why;
    if ((why = parse_id(&s, row))) return why;
    size_t n = next_token(&s, &tok);
    if (!n) return "the name is missing";
    copy_name(row->e.name, tok, n);
    if ((why = parse_rgb(&s, row->e.color))) return why;
    long long a;
    n = next_token(&s, &tok);
    if (!parse_int(tok, n, 0, 255, &a)) return "the fourth colour value is not an integer 0..255";
    row->e.color[3] = freesurfer ? (float)(255 - a) / 255.0f : (float)a / 255.0f;
    if (freesurfer) {
        long long tissue;
        n = next_token(&s, &tok);
        if (n && !parse_int(tok, n, INT32_MIN, INT32_MAX, &tissue)) return "the tissue type is not an integer";
    }
    if (!at_end(s)) return "too many columns";
    return NULL;
}

static const char *parse_freesurfer(const char *line, label_row *row) { return parse_rgba_line(line, row, 1); }
static const char *parse_slicer(const char *line, label_row *row) { return parse_rgba_line(line, row, 0); }

/* `IDX R G B A VIS MSH "LABEL"`: A opacity 0..1, VIS and MSH 0 or 1; the
 * name is everything between the first and the last quote. */
static const char *parse_itksnap(const char *line, label_row *row)
{
    const char *s = line, *tok, *why;
    if ((why = parse_id(&s, row))) return why;
    if ((why = parse_rgb(&s, row->e.color))) return why;
    double a;
    size_t n = next_token(&s, &tok);
    if (!parse_real(tok, n, 0.0, 1.0, &a)) return "the opacity is not a number 0..1";
    row->e.color[3] = (float)a;
    long long flag[2];
    for (int k = 0; k < 2; k++) {
        n = next_token(&s, &tok);
        if (!parse_int(tok, n, 0, 1, &flag[k])) return "VIS or MSH is not 0 or 1";
    }
    row->e.visible = (uint32_t)flag[0];
    while (*s == ' ' || *s == '\t') s++;
    const char *last = strrchr(s, '"');
    if (*s != '"' || last == s) return "the label is not a quoted name";
    if (!at_end(last + 1)) return "text after the quoted name";
    copy_name(row->e.name, s + 1, (size_t)(last - s - 1));
    return NULL;
}

/* MRIcron's `index name` (.txt beside an atlas): the second token is the
 * name, later tokens (AAL's and AICHA's own codes) are ignored; an index
 * alone names nothing. Colours come from the caller. */
static const char *parse_names(const char *line, label_row *row)
{
    const char *s = line, *tok, *why;
    if ((why = parse_id(&s, row))) return why;
    size_t n = next_token(&s, &tok);
    copy_name(row->e.name, tok, n);
    return NULL;
}

static const line_parser parsers[] = {parse_freesurfer, parse_slicer, parse_itksnap, parse_names};

/* ---------------------------------------------------- format detection */

static int comment_says(const char *line, const char *what)
{
    size_t k = strlen(what);
    for (const char *p = line; *p; p++)
        if (strncasecmp(p, what, k) == 0) return 1;
    return 0;
}

/* Whether a token is shaped like an integer (sign and digits, any length):
 * detection goes by shape, so an id out of range is reported by the line
 * parser with its reason rather than as "not a label table". */
static int looks_integer(const char *tok, size_t len)
{
    size_t i = len && (tok[0] == '-' || tok[0] == '+');
    if (i == len) return 0;
    for (; i < len; i++)
        if (tok[i] < '0' || tok[i] > '9') return 0;
    return 1;
}

/* A header comment that names the format (ITK-SNAP's and Slicer's do);
 * *fmt stays FMT_UNKNOWN for any other comment. */
static int format_from_comment(const char *path, const char *t, label_format *fmt, vxl_err *e)
{
    if (comment_says(t, "ITK-SnAP Label Description")) *fmt = FMT_ITKSNAP;
    else if (comment_says(t, "Color table file")) *fmt = FMT_SLICER;
    else if (comment_says(t, "Color procedural file"))
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s' is a 3D Slicer continuous colour map, not a label table", path);
    return VXL_OK;
}

/* The format from the shape of the first data line, when no comment named
 * it: a quoted name is ITK-SNAP's; `int name int int int int` FreeSurfer's
 * (Slicer's as a .ctbl); a leading integer MRIcron's `index name`. */
static int format_from_line(const char *path, const char *t, uint32_t line_no, label_format *fmt, vxl_err *e)
{
    if (strchr(t, '"')) return *fmt = FMT_ITKSNAP, VXL_OK;
    const char *s = t, *tok;
    size_t n;
    int count = 0;
    while (count < 6 && (n = next_token(&s, &tok)) > 0 && (count == 1 || looks_integer(tok, n))) count++;
    if (count == 6) return *fmt = has_suffix(path, ".ctbl") ? FMT_SLICER : FMT_FREESURFER, VXL_OK;
    if (count >= 1) return *fmt = FMT_NAMES, VXL_OK;
    return vxl_fail(e, VXL_ERR_FORMAT,
                    "'%s' line %u: not a label table (expected `id name R G B A`, ITK-SNAP's "
                    "`IDX R G B A VIS MSH \"LABEL\"` or `index name`)",
                    path, line_no);
}

/* Text only: no NUL and no control bytes but tab, CR, LF, VT, FF. */
static int looks_like_text(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\v' && c != '\f') return 0;
        if (c == 0x7F) return 0;
    }
    return 1;
}

/* ------------------------------------------------------------- reading */

/* The whole file (under the header cap of loader_util.h). */
static int read_whole(const char *path, char **text, size_t *len, vxl_err *e)
{
    uint64_t size = 0;
    int rc = vxl_read_head(path, text, len, &size, e);
    if (rc) return rc;
    if (size > VXL_HEADER_MAX) {
        free(*text);
        *text = NULL;
        return vxl_fail(e, VXL_ERR_LIMIT, "'%s' is %llu bytes: a label table may have at most %u", path,
                        (unsigned long long)size, VXL_HEADER_MAX);
    }
    return VXL_OK;
}

/* The data lines of a text table into rows. fmt FMT_UNKNOWN: the header
 * comments or the first data line decide (*fmt receives it). */
static int parse_text_rows(const char *path, char *text, size_t len, label_format *fmt, label_rows *rows, vxl_err *e)
{
    size_t pos = 0;
    int nl, rc;
    uint32_t line_no = 0;
    char *line;
    while ((line = vxl_next_line(text, len, &pos, &nl)) != NULL) {
        line_no++;
        if (strlen(line) > LABEL_LINE_MAX)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s' line %u is longer than %u bytes", path, line_no, LABEL_LINE_MAX);
        char *t = vxl_trim(line);
        if (!*t) continue;
        if (*t == '#') {
            if (*fmt == FMT_UNKNOWN && (rc = format_from_comment(path, t, fmt, e))) return rc;
            continue;
        }
        if (*fmt == FMT_UNKNOWN && (rc = format_from_line(path, t, line_no, fmt, e))) return rc;
        label_row row = {.e = {.struct_size = sizeof(vxl_label_entry), .visible = 1, .color = {0, 0, 0, 1}},
                         .line = line_no};
        const char *why = parsers[*fmt](t, &row);
        if (why) return vxl_fail(e, VXL_ERR_FORMAT, "'%s' line %u (%s): %s", path, line_no, format_names[*fmt], why);
        if ((rc = add_row(rows, path, &row, e))) return rc;
    }
    if (rows->n == 0) return vxl_fail(e, VXL_ERR_FORMAT, "'%s' holds no labels", path);
    return VXL_OK;
}

/* Steps over a UTF-8 byte order mark (Windows editors write one). */
static void skip_bom(char **text, size_t *len)
{
    if (*len >= 3 && memcmp(*text, "\xEF\xBB\xBF", 3) == 0) *text += 3, *len -= 3;
}

/* A text table; *fmt receives its format. */
static int read_text_table(const char *path, char *text, size_t len, label_format *fmt, label_rows *rows, vxl_err *e)
{
    skip_bom(&text, &len);
    if (!looks_like_text(text, len))
        return vxl_fail(e, VXL_ERR_FORMAT,
                        "'%s' is neither a text label table nor an MRIcron palette (768 bytes: 256 red, green, "
                        "blue)",
                        path);
    return parse_text_rows(path, text, len, fmt, rows, e);
}

/* Reads the 768-byte palette of an MRIcron .lut into rgb[256][3]. */
static int read_palette(const char *path, unsigned char rgb[256][3], vxl_err *e)
{
    char *data = NULL;
    size_t len = 0;
    int rc = read_whole(path, &data, &len, e);
    if (rc) return rc;
    if (len != MRICRON_LUT_BYTES) {
        free(data);
        return vxl_fail(e, VXL_ERR_FORMAT, "'%s' is %zu bytes: an MRIcron palette has %u (256 red, green, blue)", path,
                        len, MRICRON_LUT_BYTES);
    }
    for (int i = 0; i < 256; i++)
        for (int c = 0; c < 3; c++) rgb[i][c] = (unsigned char)data[c * 256 + i];
    free(data);
    return VXL_OK;
}

static void palette_color(const unsigned char rgb[256][3], int32_t id, float out[4])
{
    int k = (int)(((int64_t)id % 256 + 256) % 256);
    for (int c = 0; c < 3; c++) out[c] = rgb[k][c] / 255.0f;
    out[3] = 1.0f;
}

static int by_id(const void *a, const void *b)
{
    const label_row *x = a, *y = b;
    if (x->e.id != y->e.id) return x->e.id < y->e.id ? -1 : 1;
    return x->line < y->line ? -1 : x->line > y->line;
}

/* Sorts by id; a repeated id is an error naming both lines (a file that
 * says two things about one label is ambiguous, and neither FreeSurfer's
 * first-wins nor a last-wins rule would tell the user). */
static int sort_rows(const char *path, label_rows *rows, vxl_err *e)
{
    if (rows->n > 1) qsort(rows->v, rows->n, sizeof *rows->v, by_id);
    for (uint32_t i = 1; i < rows->n; i++)
        if (rows->v[i].e.id == rows->v[i - 1].e.id)
            return vxl_fail(e, VXL_ERR_FORMAT, "'%s': label id %d on line %u repeats line %u", path,
                            (int)rows->v[i].e.id, rows->v[i].line, rows->v[i - 1].line);
    return VXL_OK;
}

/* An MRIcron .lut opened: names from stem.txt when it exists (its ids,
 * coloured by palette entry id mod 256), else the 256 entries unnamed. */
static int read_mricron_lut(const char *path, label_rows *rows, vxl_err *e)
{
    unsigned char rgb[256][3];
    int rc = read_palette(path, rgb, e);
    if (rc) return rc;
    char *names = swap_extension(path, ".txt");
    if (!names) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory", path);
    if (is_regular_file(names)) {
        char *text = NULL;
        size_t len = 0;
        vxl_err inner = {0};
        rc = read_whole(names, &text, &len, &inner);
        char *body = text;
        skip_bom(&body, &len);
        if (!rc && !looks_like_text(body, len)) rc = vxl_fail(&inner, VXL_ERR_FORMAT, "'%s' is not text", names);
        label_format fmt = FMT_NAMES;
        if (!rc) rc = parse_text_rows(names, body, len, &fmt, rows, &inner);
        free(text);
        if (!rc) rc = sort_rows(names, rows, &inner); /* its lines are the .txt's */
        /* the message names both files: the user opened the .lut */
        if (rc) rc = vxl_fail(e, rc, "%s (the label names for '%s')", inner.msg, path);
        for (uint32_t i = 0; !rc && i < rows->n; i++) palette_color(rgb, rows->v[i].e.id, rows->v[i].e.color);
    } else {
        for (int i = 0; !rc && i < 256; i++) {
            label_row row = {.e = {.struct_size = sizeof(vxl_label_entry), .id = i, .visible = 1}, .line = 0};
            palette_color(rgb, i, row.e.color);
            rc = add_row(rows, path, &row, e);
        }
    }
    free(names);
    return rc;
}

/* `index name` lines opened directly: colours from the .lut of the same
 * stem when there is one, else the default palette. */
static int colour_names(const char *path, label_rows *rows, vxl_err *e)
{
    char *lut = swap_extension(path, ".lut");
    if (!lut) return vxl_fail(e, VXL_ERR_NO_MEMORY, "'%s': out of memory", path);
    unsigned char rgb[256][3];
    int rc = VXL_OK, have = 0;
    if (is_regular_file(lut)) {
        rc = read_palette(lut, rgb, e);
        have = rc == VXL_OK;
    }
    free(lut);
    for (uint32_t i = 0; !rc && i < rows->n; i++) {
        if (have) palette_color(rgb, rows->v[i].e.id, rows->v[i].e.color);
        else default_color(rows->v[i].e.id, rows->v[i].e.color);
    }
    return rc;
}

static int read_table(const char *path, label_rows *rows, vxl_err *e)
{
    char *data = NULL;
    size_t len = 0;
    int rc = read_whole(path, &data, &len, e);
    if (rc) return rc;
    /* the binary palette: 768 bytes named .lut, or 768 bytes that are not text */
    if (len == MRICRON_LUT_BYTES && (has_suffix(path, ".lut") || !looks_like_text(data, len))) {
        free(data);
        return read_mricron_lut(path, rows, e);
    }
    label_format fmt = FMT_UNKNOWN;
    rc = read_text_table(path, data, len, &fmt, rows, e);
    free(data);
    if (!rc && fmt == FMT_NAMES) rc = colour_names(path, rows, e);
    return rc ? rc : sort_rows(path, rows, e);
}

VXL_API int vxl_label_table_load(const char *path, vxl_label_entry *out, uint32_t max, uint32_t *count)
{
    if (!count || (max && !out))
        return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "count is NULL, or out is NULL with max > 0");
    *count = 0;
    if (!path || !*path) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "path is empty");
    label_rows rows = {0};
    int rc = read_table(path, &rows, NULL);
    if (!rc) {
        const size_t stride = max && out->struct_size ? out->struct_size : sizeof(vxl_label_entry);
        const size_t have = stride < sizeof(vxl_label_entry) ? stride : sizeof(vxl_label_entry);
        for (uint32_t i = 0; i < rows.n && i < max; i++) {
            vxl_label_entry d = rows.v[i].e;
            d.struct_size = (uint32_t)have;
            memcpy((char *)out + i * stride, &d, have);
        }
        *count = rows.n;
    }
    free(rows.v);
    return rc;
}
