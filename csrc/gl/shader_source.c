/* shader_source.c - assembles GLSL programs from the shader files. */
#include "shader_source.h"
#include "files.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "voxlight.h"

#define MAX_INCLUDED 32
#define MAX_DEPTH 8

typedef struct strbuf {
    char *s;
    size_t len, cap;
    int oom;
} strbuf;

static void sb_add(strbuf *b, const char *s, size_t n)
{
    if (b->oom) return;
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->len + n + 1) cap *= 2;
        char *p = realloc(b->s, cap);
        if (!p) { b->oom = 1; return; }
        b->s = p;
        b->cap = cap;
    }
    memcpy(b->s + b->len, s, n);
    b->len += n;
    b->s[b->len] = '\0';
}

typedef struct assembler {
    const char *dir;
    char included[MAX_INCLUDED][128]; /* names expanded so far */
    char *owned[MAX_INCLUDED]; /* files read from disk */
    int n_included, n_owned;
    strbuf out;
    vxl_err *e;
} assembler;

static const char *find_text(assembler *a, const char *name)
{
    if (!a->dir) {
        for (const vxl_embedded_file *f = vxl_embedded_shaders; f->name; f++)
            if (!strcmp(f->name, name)) return f->text;
        return NULL;
    }
    if (a->n_owned >= MAX_INCLUDED) return NULL;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", a->dir, name);
    FILE *fp = vxl_fopen(path, "rb");
    if (!fp) return NULL;
    strbuf b = {0};
    char chunk[4096];
    size_t n;
    while ((n = fread(chunk, 1, sizeof chunk, fp)) > 0) sb_add(&b, chunk, n);
    fclose(fp);
    if (b.oom || !b.s) { free(b.s); return NULL; }
    a->owned[a->n_owned++] = b.s;
    return b.s;
}

static int expand(assembler *a, const char *name, int depth)
{
    for (int i = 0; i < a->n_included; i++)
        if (!strcmp(a->included[i], name)) return VXL_OK; /* shared code goes in once */
    if (depth > MAX_DEPTH || a->n_included >= MAX_INCLUDED)
        return vxl_fail(a->e, VXL_ERR_SHADER, "shader %s: includes nested too deeply", name);
    if (strlen(name) >= sizeof a->included[0])
        return vxl_fail(a->e, VXL_ERR_SHADER, "shader name too long: %.64s", name);
    const char *text = find_text(a, name);
    if (!text)
        return vxl_fail(a->e, VXL_ERR_SHADER, "shader file %s not found%s%s", name, a->dir ? " in " : "",
                        a->dir ? a->dir : "");
    snprintf(a->included[a->n_included++], sizeof a->included[0], "%s", name);
    const char *line = text;
    while (*line) {
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line + 1) : strlen(line);
        const char *q1;
        if (!strncmp(line, "#include \"", 10) && (q1 = memchr(line + 10, '"', len - 10))) {
            char inc[128];
            size_t n = (size_t)(q1 - (line + 10));
            if (n >= sizeof inc) return vxl_fail(a->e, VXL_ERR_SHADER, "include name too long in %s", name);
            memcpy(inc, line + 10, n);
            inc[n] = '\0';
            int rc = expand(a, inc, depth + 1);
            if (rc) return rc;
        } else {
            sb_add(&a->out, line, len);
        }
        line += len;
    }
    sb_add(&a->out, "\n", 1);
    return VXL_OK;
}

int vxl_shader_source(const char *dir, const char *name, const char *defines, char **out, vxl_err *e)
{
    assembler a;
    memset(&a, 0, sizeof a);
    a.dir = dir;
    a.e = e;
    *out = NULL;
    static const char header[] = "#version 450 core\n";
    sb_add(&a.out, header, sizeof header - 1);
    if (defines) sb_add(&a.out, defines, strlen(defines));
    int rc = expand(&a, name, 0);
    for (int i = 0; i < a.n_owned; i++) free(a.owned[i]);
    if (!rc && a.out.oom) rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory assembling shader %s", name);
    if (rc) {
        free(a.out.s);
        return rc;
    }
    *out = a.out.s;
    return VXL_OK;
}
