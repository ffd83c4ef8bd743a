/* json.c - see json.h. A recursive-descent parser whose depth is capped at
 * VXL_JSON_MAX_DEPTH, so the C stack it uses is bounded whatever the input;
 * nodes live in one growing array (at most one node per input byte). */
#include "json.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct parser {
    const char *s;
    size_t len, pos;
    vxl_json_doc *doc;
    uint32_t cap;
    char *out;      /* write cursor into doc->text for decoded strings */
    char *err;
    size_t err_size;
} parser;

static int fail(parser *p, const char *fmt, ...)
{
    if (p->err && p->err_size && !p->err[0]) {
        int n = snprintf(p->err, p->err_size, "at byte %zu: ", p->pos);
        if (n > 0 && (size_t)n < p->err_size) {
            va_list ap;
            va_start(ap, fmt);
            vsnprintf(p->err + n, p->err_size - (size_t)n, fmt, ap);
            va_end(ap);
        }
    }
    return -1;
}

static void skip_ws(parser *p)
{
    while (p->pos < p->len && (p->s[p->pos] == ' ' || p->s[p->pos] == '\t' || p->s[p->pos] == '\n' ||
                               p->s[p->pos] == '\r'))
        p->pos++;
}

static int32_t new_node(parser *p, int type)
{
    vxl_json_doc *d = p->doc;
    if (d->n == p->cap) {
        /* never more nodes than input bytes + 1: the growth is bounded */
        uint32_t cap = p->cap ? p->cap * 2 : 64;
        if (cap > p->len + 1) cap = (uint32_t)p->len + 1;
        if (cap <= d->n) return fail(p, "too many values"), -1;
        vxl_json *n = realloc(d->nodes, (size_t)cap * sizeof *n);
        if (!n) return fail(p, "out of memory"), -1;
        d->nodes = n;
        p->cap = cap;
    }
    vxl_json *v = &d->nodes[d->n];
    memset(v, 0, sizeof *v);
    v->type = type;
    v->first = v->next = -1;
    return (int32_t)d->n++;
}

static int hex4(parser *p, unsigned *out)
{
    if (p->len - p->pos < 4) return fail(p, "short \\u escape");
    unsigned v = 0;
    for (int i = 0; i < 4; i++) {
        char c = p->s[p->pos++];
        v <<= 4;
        if (c >= '0' && c <= '9') v |= (unsigned)(c - '0');
        else if (c >= 'a' && c <= 'f') v |= (unsigned)(c - 'a' + 10);
        else if (c >= 'A' && c <= 'F') v |= (unsigned)(c - 'A' + 10);
        else return fail(p, "bad \\u escape");
    }
    *out = v;
    return 0;
}

/* Decodes a string starting after its opening quote into p->out; returns
 * where it starts. Decoded text is never longer than its source, so the
 * copy of the input has room. */
static const char *parse_string(parser *p)
{
    char *start = p->out;
    for (;;) {
        if (p->pos >= p->len) return fail(p, "unterminated string"), NULL;
        unsigned char c = (unsigned char)p->s[p->pos++];
        if (c == '"') break;
        if (c < 0x20) return fail(p, "control character in a string"), NULL;
        if (c != '\\') {
            *p->out++ = (char)c;
            continue;
        }
        if (p->pos >= p->len) return fail(p, "unterminated escape"), NULL;
        char esc = p->s[p->pos++];
        const char *simple = strchr("\"\\/bfnrt", esc);
        if (esc && simple) {
            static const char map[] = "\"\\/\b\f\n\r\t";
            *p->out++ = map[simple - "\"\\/bfnrt"];
            continue;
        }
        if (esc != 'u') return fail(p, "bad escape \\%c", esc), NULL;
        unsigned cp;
        if (hex4(p, &cp)) return NULL;
        if (cp >= 0xD800 && cp <= 0xDBFF) {
            unsigned lo;
            if (p->len - p->pos < 2 || p->s[p->pos] != '\\' || p->s[p->pos + 1] != 'u')
                return fail(p, "unpaired surrogate"), NULL;
            p->pos += 2;
            if (hex4(p, &lo)) return NULL;
            if (lo < 0xDC00 || lo > 0xDFFF) return fail(p, "unpaired surrogate"), NULL;
            cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
        } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
            return fail(p, "unpaired surrogate"), NULL;
        }
        if (cp == 0) return fail(p, "NUL in a string"), NULL;
        /* 6 source bytes (12 for a pair) become at most 4 */
        if (cp < 0x80) *p->out++ = (char)cp;
        else if (cp < 0x800) {
            *p->out++ = (char)(0xC0 | (cp >> 6));
            *p->out++ = (char)(0x80 | (cp & 0x3F));
        } else if (cp < 0x10000) {
            *p->out++ = (char)(0xE0 | (cp >> 12));
            *p->out++ = (char)(0x80 | ((cp >> 6) & 0x3F));
            *p->out++ = (char)(0x80 | (cp & 0x3F));
        } else {
            *p->out++ = (char)(0xF0 | (cp >> 18));
            *p->out++ = (char)(0x80 | ((cp >> 12) & 0x3F));
            *p->out++ = (char)(0x80 | ((cp >> 6) & 0x3F));
            *p->out++ = (char)(0x80 | (cp & 0x3F));
        }
    }
    *p->out++ = '\0';
    return start;
}

static int is_digit(char c) { return c >= '0' && c <= '9'; }

static int parse_number(parser *p, vxl_json *v)
{
    size_t b = p->pos;
    int integer = 1;
    if (p->pos < p->len && p->s[p->pos] == '-') p->pos++;
    if (p->pos >= p->len || !is_digit(p->s[p->pos])) return fail(p, "bad number");
    if (p->s[p->pos] == '0') p->pos++;
    else
        while (p->pos < p->len && is_digit(p->s[p->pos])) p->pos++;
    if (p->pos < p->len && p->s[p->pos] == '.') {
        integer = 0;
        p->pos++;
        if (p->pos >= p->len || !is_digit(p->s[p->pos])) return fail(p, "bad number");
        while (p->pos < p->len && is_digit(p->s[p->pos])) p->pos++;
    }
    if (p->pos < p->len && (p->s[p->pos] == 'e' || p->s[p->pos] == 'E')) {
        integer = 0;
        p->pos++;
        if (p->pos < p->len && (p->s[p->pos] == '+' || p->s[p->pos] == '-')) p->pos++;
        if (p->pos >= p->len || !is_digit(p->s[p->pos])) return fail(p, "bad number");
        while (p->pos < p->len && is_digit(p->s[p->pos])) p->pos++;
    }
    char buf[64];
    size_t n = p->pos - b;
    if (n >= sizeof buf) return fail(p, "number too long");
    memcpy(buf, p->s + b, n);
    buf[n] = '\0';
    v->num = strtod(buf, NULL);
    if (!isfinite(v->num)) return fail(p, "number out of range");
    v->is_integer = integer;
    return 0;
}

static int32_t parse_value(parser *p, int depth);

/* Array or object after its opening bracket; children are linked in order. */
static int parse_container(parser *p, int32_t self, int is_object, int depth)
{
    const char close = is_object ? '}' : ']';
    int32_t last = -1;
    skip_ws(p);
    if (p->pos < p->len && p->s[p->pos] == close) {
        p->pos++;
        return 0;
    }
    for (;;) {
        const char *key = NULL;
        if (is_object) {
            skip_ws(p);
            if (p->pos >= p->len || p->s[p->pos] != '"') return fail(p, "expected a member name");
            p->pos++;
            if (!(key = parse_string(p))) return -1;
            skip_ws(p);
            if (p->pos >= p->len || p->s[p->pos] != ':') return fail(p, "expected ':'");
            p->pos++;
        }
        int32_t child = parse_value(p, depth + 1);
        if (child < 0) return -1;
        vxl_json *nodes = p->doc->nodes;
        nodes[child].key = key;
        if (last < 0) nodes[self].first = child;
        else nodes[last].next = child;
        last = child;
        nodes[self].count++;
        skip_ws(p);
        if (p->pos >= p->len) return fail(p, "unterminated %s", is_object ? "object" : "array");
        char c = p->s[p->pos++];
        if (c == close) return 0;
        if (c != ',') return fail(p, "expected ',' or '%c'", close);
    }
}

static int literal(parser *p, const char *word)
{
    size_t n = strlen(word);
    if (p->len - p->pos < n || memcmp(p->s + p->pos, word, n)) return fail(p, "unexpected character");
    p->pos += n;
    return 0;
}

static int32_t parse_value(parser *p, int depth)
{
    if (depth > VXL_JSON_MAX_DEPTH) return fail(p, "nested deeper than %d", VXL_JSON_MAX_DEPTH), -1;
    skip_ws(p);
    if (p->pos >= p->len) return fail(p, "unexpected end"), -1;
    char c = p->s[p->pos];
    int32_t self;
    switch (c) {
    case '{':
    case '[':
        if ((self = new_node(p, c == '{' ? VXL_JSON_OBJECT : VXL_JSON_ARRAY)) < 0) return -1;
        p->pos++;
        return parse_container(p, self, c == '{', depth) ? -1 : self;
    case '"': {
        if ((self = new_node(p, VXL_JSON_STRING)) < 0) return -1;
        p->pos++;
        const char *s = parse_string(p);
        if (!s) return -1;
        p->doc->nodes[self].str = s;
        return self;
    }
    case 't':
        if ((self = new_node(p, VXL_JSON_TRUE)) < 0) return -1;
        return literal(p, "true") ? -1 : self;
    case 'f':
        if ((self = new_node(p, VXL_JSON_FALSE)) < 0) return -1;
        return literal(p, "false") ? -1 : self;
    case 'n':
        if ((self = new_node(p, VXL_JSON_NULL)) < 0) return -1;
        return literal(p, "null") ? -1 : self;
    default:
        if ((self = new_node(p, VXL_JSON_NUMBER)) < 0) return -1;
        return parse_number(p, &p->doc->nodes[self]) ? -1 : self;
    }
}

int vxl_json_parse(const char *text, size_t len, vxl_json_doc *doc, char *err, size_t err_size)
{
    memset(doc, 0, sizeof *doc);
    if (err && err_size) err[0] = '\0';
    parser p = {.s = text, .len = len, .doc = doc, .err = err, .err_size = err_size};
    if (len > VXL_JSON_MAX_BYTES) return fail(&p, "larger than %u bytes", VXL_JSON_MAX_BYTES);
    if (!(doc->text = malloc(len + 1))) return fail(&p, "out of memory");
    p.out = doc->text;
    int32_t root = parse_value(&p, 0);
    if (root >= 0) {
        skip_ws(&p);
        if (p.pos != len) root = fail(&p, "text after the value");
    }
    if (root < 0) {
        vxl_json_free(doc);
        return -1;
    }
    return 0;
}

void vxl_json_free(vxl_json_doc *doc)
{
    free(doc->nodes);
    free(doc->text);
    memset(doc, 0, sizeof *doc);
}

const vxl_json *vxl_json_get(const vxl_json_doc *d, const vxl_json *obj, const char *key)
{
    if (!obj || obj->type != VXL_JSON_OBJECT) return NULL;
    const vxl_json *found = NULL; /* the last of duplicate names wins, as in Python's json */
    for (int32_t i = obj->first; i >= 0; i = d->nodes[i].next)
        if (!strcmp(d->nodes[i].key, key)) found = &d->nodes[i];
    return found;
}

const vxl_json *vxl_json_at(const vxl_json_doc *d, const vxl_json *arr, uint32_t i)
{
    if (!arr || arr->type != VXL_JSON_ARRAY || i >= arr->count) return NULL;
    int32_t k = arr->first;
    while (i-- && k >= 0) k = d->nodes[k].next;
    return k >= 0 ? &d->nodes[k] : NULL;
}

const char *vxl_json_string(const vxl_json *v) { return v && v->type == VXL_JSON_STRING ? v->str : NULL; }
