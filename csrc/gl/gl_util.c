/* gl_util.c - shader program cache and small GL helpers (GL thread only). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu.h"
#include "shader_source.h"

static const char *const filter_defines[VXL_FILTER_COUNT] = {
    "#define FILTER_CENTRAL 1\n", "#define FILTER_FORWARD3 1\n", "#define FILTER_SOBEL8 1\n",
    "#define FILTER_SOBEL14 1\n", "#define FILTER_SOBEL26 1\n", "#define FILTER_PRECOMPUTED 1\n",
    "#define FILTER_CUBIC 1\n", "#define FILTER_CUBIC_SMOOTH 1\n"};

/* flags bits for RAYCAST: 1 shading, 2 reuse gradients, bits 2-3 the
 * classify mode, bits 4-5 the gradient-opacity mode, bit 6 (also PROBE)
 * bricked storage, bit 7 compressed storage filtered in the compressed
 * domain, bits 8-9 the shading model, bits 10-12 the render
 * mode, bit 13 a MatCap, bit 14 convex cutaways (clip planes, crop box),
 * bit 15 cutter meshes (VXL_FLAG_* in gpu.h); for GRAD_STORE: the store format; for DECODE_BRICKS: the cache's
 * bytes per voxel - 1 */
static const char *const store_formats[] = {"rgba8_snorm", "rgba16f", "rgba32f"};
static const char *const cache_formats[] = {"r8", "r16", "r32f", "r32f"};

static int compile(vxl_gpu *g, GLenum type, const char *file, const char *defines, GLuint *out)
{
    vxl_gl *gl = &g->gl;
    /* the binding numbers first, so layout(binding = VXL_...) reads gl_bindings.h */
    char all[2048];
    snprintf(all, sizeof all, "%s%s", vxl_glsl_binding_defines(), defines ? defines : "");
    char *src = NULL;
    int rc = vxl_shader_source(g->shader_dir, file, all, &src, &g->err);
    if (rc) return rc;
    GLuint s = gl->CreateShader(type);
    const GLchar *srcs[1] = {src};
    gl->ShaderSource(s, 1, srcs, NULL);
    gl->CompileShader(s);
    free(src);
    GLint ok = 0;
    gl->GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[400];
        log[0] = '\0';
        gl->GetShaderInfoLog(s, sizeof log, NULL, log);
        gl->DeleteShader(s);
        return vxl_fail(&g->err, VXL_ERR_SHADER, "shader %s failed to compile: %s", file, log);
    }
    *out = s;
    return VXL_OK;
}

static int link(vxl_gpu *g, GLuint a, GLuint b, GLuint *out)
{
    vxl_gl *gl = &g->gl;
    GLuint p = gl->CreateProgram();
    gl->AttachShader(p, a);
    if (b) gl->AttachShader(p, b);
    gl->LinkProgram(p);
    gl->DeleteShader(a);
    if (b) gl->DeleteShader(b);
    GLint ok = 0;
    gl->GetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[400];
        log[0] = '\0';
        gl->GetProgramInfoLog(p, sizeof log, NULL, log);
        gl->DeleteProgram(p);
        return vxl_fail(&g->err, VXL_ERR_SHADER, "shader program failed to link: %s", log);
    }
    *out = p;
    return VXL_OK;
}

static int build(vxl_gpu *g, uint32_t kind, uint32_t filter, uint32_t flags, GLuint *out)
{
    char defines[512] = "";
    const char *fdef = filter < VXL_FILTER_COUNT ? filter_defines[filter] : filter_defines[0];
    const uint32_t storage = flags & (VXL_FLAG_PAGED | VXL_FLAG_COMPRESSED_DOMAIN | VXL_FLAG_PAGED_MIXED);
    const char *paged = storage == (VXL_FLAG_PAGED | VXL_FLAG_COMPRESSED_DOMAIN) ? "#define PAGED 1\n#define COMPRESSED_DOMAIN 1\n"
                        : storage == VXL_FLAG_PAGED                              ? "#define PAGED 1\n"
                        : storage == (VXL_FLAG_PAGED | VXL_FLAG_PAGED_MIXED)     ? "#define PAGED 1\n#define PAGED_MIXED 1\n"
                                                                                 : "";
    GLuint a = 0, b = 0;
    int rc;
    switch (kind) {
    case VXL_PROG_RAYCAST:
    case VXL_PROG_SLICES:
        snprintf(defines, sizeof defines, "%s%s#define GOPACITY %u\n%s%s%s", paged, fdef, (flags >> 4) & 3,
                 (flags & 1) ? "#define SHADING 1\n" : "",
                 (flags & 2) ? "#define REUSE_GRADIENTS 1\n" : "",
                 ((flags >> 2) & 3) == VXL_CLASSIFY_PRE      ? "#define CLASSIFY_PRE 1\n"
                 : ((flags >> 2) & 3) == VXL_CLASSIFY_PREINT ? "#define CLASSIFY_PREINT 1\n"
                                                             : "");
        if (flags & VXL_FLAG_DATA_COLOUR) /* a colour volume's own colour (colour/colour.c) */
            snprintf(defines + strlen(defines), sizeof defines - strlen(defines), "#define DATA_COLOUR 1\n");
        if ((flags >> 8) & 3) /* shadowed / scatter; PHONG compiles as before */
            snprintf(defines + strlen(defines), sizeof defines - strlen(defines), "#define SHADING_MODEL %u\n",
                     (flags >> 8) & 3);
        if (flags & VXL_FLAG_ENVIRONMENT) /* the World's light replaces the ambient term */
            snprintf(defines + strlen(defines), sizeof defines - strlen(defines), "#define ENVIRONMENT 1\n");
        if (kind == VXL_PROG_RAYCAST) /* the mode, the MatCap and the cutaways */
            snprintf(defines + strlen(defines), sizeof defines - strlen(defines), "#define MODE %u\n%s%s%s",
                     (flags >> VXL_FLAG_MODE_SHIFT) & 7, (flags & VXL_FLAG_MATCAP) ? "#define MATCAP 1\n" : "",
                     (flags & VXL_FLAG_CUT_CONVEX) ? "#define CUT_CONVEX 1\n" : "",
                     (flags & VXL_FLAG_CUT_CUTTERS) ? "#define CUT_CUTTERS 1\n" : "");
        if (kind == VXL_PROG_RAYCAST && (flags >> VXL_FLAG_LABELS_SHIFT) & 3) /* label mode + 1 */
            snprintf(defines + strlen(defines), sizeof defines - strlen(defines), "#define LABELS %u\n%s",
                     (flags >> VXL_FLAG_LABELS_SHIFT) & 3, (flags & VXL_FLAG_LABEL_VOXELS) ? "#define LABEL_VOXELS 1\n" : "");
        if (kind == VXL_PROG_RAYCAST && (flags >> VXL_FLAG_CHANNELS_SHIFT) & 3) /* a multi-channel volume's texture groups */
            snprintf(defines + strlen(defines), sizeof defines - strlen(defines), "#define CHANNEL_GROUPS %u\n",
                     (flags >> VXL_FLAG_CHANNELS_SHIFT) & 3);
        if (kind == VXL_PROG_RAYCAST && (flags >> VXL_FLAG_OVERLAYS_SHIFT) & 3) /* the number of overlays */
            snprintf(defines + strlen(defines), sizeof defines - strlen(defines), "#define OVERLAYS %u\n",
                     (flags >> VXL_FLAG_OVERLAYS_SHIFT) & 3);
        rc = compile(g, GL_VERTEX_SHADER, kind == VXL_PROG_SLICES ? "render/slices.vert" : "render/raycast.vert", NULL, &a);
        if (rc) return rc;
        rc = compile(g, GL_FRAGMENT_SHADER, kind == VXL_PROG_SLICES ? "render/slices.frag" : "render/raycast.frag", defines, &b);
        if (rc) {
            g->gl.DeleteShader(a);
            return rc;
        }
        return link(g, a, b, out);
    case VXL_PROG_PATH: /* the PATH model: scatter's lighting (SHADING_MODEL 2) at every collision */
        snprintf(defines, sizeof defines, "%s%s#define SHADING 1\n#define SHADING_MODEL 2\n%s%s%s", paged, fdef,
                 (flags & VXL_FLAG_DATA_COLOUR) ? "#define DATA_COLOUR 1\n" : "",
                 (flags & VXL_FLAG_ENVIRONMENT) ? "#define ENVIRONMENT 1\n" : "",
                 (flags & VXL_FLAG_CUT_CONVEX) ? "#define CUT_CONVEX 1\n" : "");
        rc = compile(g, GL_VERTEX_SHADER, "render/raycast.vert", NULL, &a);
        if (rc) return rc;
        rc = compile(g, GL_FRAGMENT_SHADER, "render/path.frag", defines, &b);
        if (rc) {
            g->gl.DeleteShader(a);
            return rc;
        }
        return link(g, a, b, out);
    case VXL_PROG_PROBE:
        snprintf(defines, sizeof defines, "%s%s", paged, fdef);
        rc = compile(g, GL_COMPUTE_SHADER, "compute/probe.comp", defines, &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_GRAD_BLUR:
    case VXL_PROG_PAGED_BLUR:
        rc = compile(g, GL_COMPUTE_SHADER, "compute/gradients.comp",
                     kind == VXL_PROG_PAGED_BLUR ? "#define PAGED 1\n#define BLUR_PASS 1\n" : "#define BLUR_PASS 1\n", &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_GRAD_MAX: /* the dense texture's largest gradient (bricked: found on the CPU) */
        rc = compile(g, GL_COMPUTE_SHADER, "compute/gradients.comp", "#define MAX_PASS 1\n", &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_GRAD_STORE:
    case VXL_PROG_PAGED_GRAD_STORE:
        snprintf(defines, sizeof defines, "%s#define GRADIENT_FORMAT %s\n", kind == VXL_PROG_PAGED_GRAD_STORE ? "#define PAGED 1\n" : "",
                 store_formats[flags % 3]);
        rc = compile(g, GL_COMPUTE_SHADER, "compute/gradients.comp", defines, &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_BSPLINE_COPY:
        rc = compile(g, GL_COMPUTE_SHADER, "compute/bspline_prefilter.comp", "#define COPY_PASS 1\n", &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_BSPLINE_AXIS:
        rc = compile(g, GL_COMPUTE_SHADER, "compute/bspline_prefilter.comp", NULL, &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_CLASSIFY_VOLUME:
        rc = compile(g, GL_COMPUTE_SHADER, "compute/classify_volume.comp", NULL, &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_DECODE_BRICKS:
        snprintf(defines, sizeof defines, "#define CACHE_FORMAT %s\n", cache_formats[flags & 3]);
        rc = compile(g, GL_COMPUTE_SHADER, "compute/decode_bricks.comp", defines, &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_ILLUMINATION: /* illumination.c: flags & 3 the pass (ENVIRONMENT: pass 4), bits 2-3 the gradient-opacity mode, plus the storage's sample flags; the extinction's cut (CUT_CONVEX) and label mode (LABELS bits) */
        snprintf(defines, sizeof defines, "%s#define PASS %u\n#define GOPACITY %u\n#define ENV_CELLS %u\n%s", paged,
                 (flags & VXL_FLAG_ENVIRONMENT) ? 4u : flags & 3, (flags >> 2) & 3, VXL_ENV_CELLS,
                 (flags & VXL_FLAG_CUT_CONVEX) ? "#define CUT_KEEPS 1\n" : "");
        if ((flags >> VXL_FLAG_LABELS_SHIFT) & 3) /* the extinction leaves hidden labels out: label mode + 1 */
            snprintf(defines + strlen(defines), sizeof defines - strlen(defines), "#define LABEL_SHADOWS %u\n%s",
                     (flags >> VXL_FLAG_LABELS_SHIFT) & 3, (flags & VXL_FLAG_LABEL_VOXELS) ? "#define LABEL_VOXELS 1\n" : "");
        rc = compile(g, GL_COMPUTE_SHADER, "compute/illumination.comp", defines, &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_SLICE_PLANE: /* slice_plane.c: flags & 3 the interpolation (VXL_INTERP_*), plus the sample flags and DATA_COLOUR */
        snprintf(defines, sizeof defines, "%s%s#define INTERP %u\n%s", paged, fdef, flags & 3,
                 (flags & VXL_FLAG_DATA_COLOUR) ? "#define DATA_COLOUR 1\n" : "");
        rc = compile(g, GL_COMPUTE_SHADER, "compute/slice_plane.comp", defines, &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_SHADOW_MAP: /* depth only */
        rc = compile(g, GL_VERTEX_SHADER, "render/shadow_map.vert", NULL, &a);
        if (rc) return rc;
        rc = compile(g, GL_FRAGMENT_SHADER, "render/shadow_map.frag", NULL, &b);
        if (rc) {
            g->gl.DeleteShader(a);
            return rc;
        }
        return link(g, a, b, out);
    case VXL_PROG_SCENE_TRANSMITTANCE:
        rc = compile(g, GL_COMPUTE_SHADER, "compute/scene_transmittance.comp", NULL, &a);
        return rc ? rc : link(g, a, 0, out);
    case VXL_PROG_CUT_PEEL: /* cut/cutaway.c */
        rc = compile(g, GL_VERTEX_SHADER, "render/cut_peel.vert", NULL, &a);
        if (!rc && (rc = compile(g, GL_FRAGMENT_SHADER, "render/cut_peel.frag", "#define CUT_PEEL 1\n", &b)))
            g->gl.DeleteShader(a);
        return rc ? rc : link(g, a, b, out);
    case VXL_PROG_BRICK_MINMAX:
        rc = compile(g, GL_COMPUTE_SHADER, "compute/brick_minmax.comp", flags & 1 ? "#define GRADIENT_BOUND 1\n" : NULL, &a);
        return rc ? rc : link(g, a, 0, out);
    default:
        return vxl_fail(&g->err, VXL_ERR_INVALID_ARGUMENT, "unknown program kind %u", kind);
    }
}

int vxl_program_get(vxl_gpu *g, uint32_t kind, uint32_t filter, uint32_t flags, GLuint *out)
{
    const uint64_t key = kind | (filter << 5) | ((uint64_t)flags << 12); /* kind < 32, filter < 8 */
    for (int i = 0; i < g->n_programs; i++)
        if (g->programs[i].key == key) {
            *out = g->programs[i].program;
            return VXL_OK;
        }
    GLuint p = 0;
    int rc = build(g, kind, filter, flags, &p);
    if (rc) return rc;
    if (g->n_programs == VXL_MAX_PROGRAMS) { /* the key space is smaller than the cache */
        g->gl.DeleteProgram(p);
        return vxl_fail(&g->err, VXL_ERR_STATE, "program cache full");
    }
    g->programs[g->n_programs].key = key;
    g->programs[g->n_programs++].program = p;
    *out = p;
    return VXL_OK;
}

void vxl_programs_delete(vxl_gpu *g)
{
    for (int i = 0; i < g->n_programs; i++) g->gl.DeleteProgram(g->programs[i].program);
    g->n_programs = 0;
}

void vxl_uniform_i(vxl_gpu *g, GLuint prog, const char *name, int v)
{
    GLint loc = g->gl.GetUniformLocation(prog, name);
    if (loc >= 0) g->gl.Uniform1i(loc, v);
}

void vxl_uniform_f(vxl_gpu *g, GLuint prog, const char *name, float v)
{
    GLint loc = g->gl.GetUniformLocation(prog, name);
    if (loc >= 0) g->gl.Uniform1f(loc, v);
}

/* Created on the scratch unit, so making a texture never disturbs what a
 * program has bound on its sampler units. Leaves VXL_SCRATCH_UNIT active. */
GLuint vxl_texture_new(vxl_gpu *g, GLenum target, GLint filter)
{
    GLuint t = 0;
    g->gl.ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    g->gl.GenTextures(1, &t);
    g->gl.BindTexture(target, t);
    g->gl.TexParameteri(target, GL_TEXTURE_MIN_FILTER, filter);
    g->gl.TexParameteri(target, GL_TEXTURE_MAG_FILTER, filter);
    g->gl.TexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    g->gl.TexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    g->gl.TexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    g->gl.TexParameteri(target, GL_TEXTURE_BASE_LEVEL, 0);
    g->gl.TexParameteri(target, GL_TEXTURE_MAX_LEVEL, 0);
    return t;
}

int vxl_gl_check(vxl_gpu *g, const char *what)
{
    GLenum e = g->gl.GetError(), first = e;
    while (e != GL_NO_ERROR) e = g->gl.GetError(); /* drain */
    if (first == GL_NO_ERROR) return VXL_OK;
    if (first == GL_OUT_OF_MEMORY)
        return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "%s: the OpenGL implementation ran out of memory", what);
    return vxl_fail(&g->err, VXL_ERR_GL, "%s: OpenGL error 0x%04x", what, first);
}
