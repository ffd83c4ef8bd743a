/* ome_xml.c - ome_xml.h: attributes of OME-XML's <Pixels> and <Channel>. */
#include "ome_xml.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "channel_meta.h"

/* The first occurrence of needle in [at, end), or NULL. */
static const char *find(const char *at, const char *end, const char *needle)
{
    const size_t n = strlen(needle);
    for (; at && (size_t)(end - at) >= n; at = memchr(at + 1, needle[0], (size_t)(end - at - 1)))
        if (!memcmp(at, needle, n)) return at;
    return NULL;
}

/* The next start tag named `name` (with or without a namespace prefix,
 * "<Pixels" or "<ome:Pixels") in [at, end): where its attributes begin
 * (after the name), its end ('>') in *tag_end; NULL when none. */
static const char *find_tag(const char *at, const char *end, const char *name, const char **tag_end)
{
    const size_t n = strlen(name);
    for (const char *lt = memchr(at, '<', (size_t)(end - at)); lt; lt = memchr(lt + 1, '<', (size_t)(end - lt - 1))) {
        const char *s = lt + 1, *colon = s;
        while (colon < end && colon - s < 32 && *colon != ':' && *colon != ' ' && *colon != '>' && *colon != '/')
            colon++;
        if (colon < end && *colon == ':') s = colon + 1;
        if ((size_t)(end - s) <= n || memcmp(s, name, n)) continue;
        const char after = s[n];
        if (after != ' ' && after != '\t' && after != '\n' && after != '\r' && after != '/' && after != '>') continue;
        const char *gt = memchr(s + n, '>', (size_t)(end - s - n));
        if (!gt) return NULL;
        *tag_end = gt;
        return s + n;
    }
    return NULL;
}

/* Attribute `name`'s value in the tag [at, end), entities decoded, into
 * out (cut to size); 0 when absent. */
static int attribute(const char *at, const char *end, const char *name, char *out, size_t size)
{
    const size_t n = strlen(name);
    for (const char *s = at; s + n + 2 < end; s++) {
        if ((s[-1] != ' ' && s[-1] != '\t' && s[-1] != '\n' && s[-1] != '\r') || memcmp(s, name, n) ||
            s[n] != '=' || (s[n + 1] != '"' && s[n + 1] != '\''))
            continue;
        const char quote = s[n + 1], *v = s + n + 2;
        const char *close = memchr(v, quote, (size_t)(end - v));
        if (!close) return 0;
        size_t o = 0;
        static const struct { const char *ent; char c; } ents[] = {
            {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
        while (v < close && o + 1 < size) {
            char c = *v++;
            if (c == '&')
                for (size_t k = 0; k < sizeof ents / sizeof ents[0]; k++) {
                    const size_t l = strlen(ents[k].ent);
                    if ((size_t)(close - v + 1) >= l && !memcmp(v - 1, ents[k].ent, l)) {
                        c = ents[k].c;
                        v += l - 1;
                        break;
                    }
                }
            out[o++] = c;
        }
        out[o] = '\0';
        return 1;
    }
    return 0;
}

static int positive(const char *at, const char *end, const char *name, uint64_t *out)
{
    char v[32], *stop;
    if (!attribute(at, end, name, v, sizeof v) || v[0] < '0' || v[0] > '9') return 0;
    *out = strtoull(v, &stop, 10);
    return !*stop && *out > 0 && *out <= (1ull << 32);
}

static void note(vxl_ome_pixels *p, const char *what, uint32_t c)
{
    const size_t n = strlen(p->notes);
    const int w = snprintf(p->notes + n, sizeof p->notes - n, "%sOME-XML channel %u's %s", n ? "; " : "", c, what);
    if (w < 0 || (size_t)w >= sizeof p->notes - n) p->notes[n] = '\0';
}

int vxl_ome_xml_parse(const char *text, size_t len, vxl_ome_pixels *p)
{
    memset(p, 0, sizeof *p);
    const char *end = text + len, *tag_end;
    if (!len || !find_tag(text, end, "OME", &tag_end)) return 0;
    const char *px = find_tag(text, end, "Pixels", &tag_end);
    if (!px) return 0;
    char order[16];
    if (!attribute(px, tag_end, "DimensionOrder", order, sizeof order) || strlen(order) != 5 ||
        strncmp(order, "XY", 2) || !strchr(order + 2, 'Z') || !strchr(order + 2, 'C') || !strchr(order + 2, 'T'))
        return 0;
    memcpy(p->order, order, 6);
    if (!positive(px, tag_end, "SizeX", &p->size_x) || !positive(px, tag_end, "SizeY", &p->size_y) ||
        !positive(px, tag_end, "SizeZ", &p->size[0]) || !positive(px, tag_end, "SizeC", &p->size[1]) ||
        !positive(px, tag_end, "SizeT", &p->size[2]))
        return 0;
    /* the image's channels: <Channel> tags before its </Pixels> */
    const char *close = find(tag_end, end, "Pixels>");
    const char *stop = close ? close : end, *at = tag_end, *ch;
    while ((ch = find_tag(at, stop, "Channel", &tag_end)) != NULL) {
        const uint32_t c = p->channels++;
        at = tag_end;
        if (c >= VXL_MAX_CHANNELS) continue;
        char v[256];
        if (attribute(ch, tag_end, "Name", v, sizeof v)) {
            const int r = vxl_channel_meta_name(&p->meta[c], v);
            if (r == VXL_META_CUT) note(p, "Name cut to 63 bytes", c);
            else if (r == VXL_META_REFUSED) note(p, "Name ignored (not a line of text)", c);
        }
        if (attribute(ch, tag_end, "Color", v, sizeof v)) {
            char *e;
            const long long rgba = strtoll(v, &e, 10);
            if (*v && !*e && rgba >= INT32_MIN && rgba <= INT32_MAX) vxl_channel_meta_rgba32(&p->meta[c], rgba);
            else note(p, "Color ignored (not a 32-bit integer)", c);
        }
    }
    return 1;
}

uint64_t vxl_ome_page(const vxl_ome_pixels *p, uint64_t z, uint64_t c, uint64_t t)
{
    const uint64_t coord[3] = {z, c, t};
    uint64_t page = 0, stride = 1;
    for (int k = 2; k < 5; k++) {
        const int d = p->order[k] == 'Z' ? 0 : p->order[k] == 'C' ? 1 : 2;
        page += coord[d] * stride;
        stride *= p->size[d];
    }
    return page;
}
