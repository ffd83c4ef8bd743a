/* cutaway.c - the GL side of the cutaways (cutaway.h): the ray caster's
 * cutaway uniforms, and the cutter meshes peeled from the camera into
 * per-pixel crossings each frame. */
#include "cutaway.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "holdings.h"
#include "mat4.h"

#define CORNER_FLOATS 7 /* world xyz, normal xyz, cutter */

void vxl_cut_init(vxl_cut_state *s, vxl_gpu *g)
{
    s->gpu = g;
    vxl_holding_register(g, VXL_HOLD_CUTAWAY, vxl_holding_counter, &s->bytes);
}

uint32_t vxl_cut_flags(const vxl_frame *f)
{
    const vxl_frame_cut *c = &f->cut;
    return (c->plane_count || c->has_crop ? VXL_FLAG_CUT_CONVEX : 0u) | (c->cutter_count ? VXL_FLAG_CUT_CUTTERS : 0u);
}

static uint64_t layer_bytes(uint64_t pixels) { return pixels * (1 + 2 * VXL_CUT_LAYERS) * 4 + pixels; /* + R8 target */ }

void vxl_cut_release(vxl_cut_state *s)
{
    if (!s->gpu) return;
    vxl_gl *gl = &s->gpu->gl;
    if (s->layers) gl->DeleteBuffers(1, &s->layers);
    if (s->vbo) gl->DeleteBuffers(1, &s->vbo);
    if (s->target) gl->DeleteTextures(1, &s->target);
    if (s->fbo) gl->DeleteFramebuffers(1, &s->fbo);
    if (s->vao) gl->DeleteVertexArrays(1, &s->vao);
    s->layers = s->vbo = s->target = s->fbo = s->vao = 0;
    s->width = s->height = 0;
    s->vbo_bytes = s->bytes = 0;
}

/* The triangles of every cutter as corners for cut_peel.vert: each with its
 * face's unit normal in gradient space (model^T times the world normal: the
 * gradient of the face's plane in voxel space, as lib/cut.glsl compares it
 * with the voxel-space ray), pointing out of the mesh. A mesh whose faces
 * wind inward (negative enclosed volume) has its normals turned round, so
 * only a mixed winding can confuse inside and outside. */
static uint64_t fill_corners(const vxl_frame *f, float *out)
{
    uint64_t n = 0;
    for (uint32_t c = 0; c < f->cut.cutter_count; c++) {
        const vxl_frame_cutter *k = &f->cut.cutters[c];
        uint64_t first = n;
        double volume = 0;
        const float *p0 = k->vertices;
        for (uint32_t t = 0; t < k->triangle_count; t++) {
            const float *v[3];
            for (int j = 0; j < 3; j++) v[j] = k->vertices + 3 * (size_t)k->indices[3 * (size_t)t + j];
            double a[3], b[3], q[3];
            for (int j = 0; j < 3; j++) {
                a[j] = (double)v[1][j] - v[0][j];
                b[j] = (double)v[2][j] - v[0][j];
                q[j] = (double)v[0][j] - p0[j];
            }
            double w[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
            volume += q[0] * w[0] + q[1] * w[1] + q[2] * w[2];
            double g[3], len = 0;
            for (int r = 0; r < 3; r++) {
                g[r] = f->model[r * 4] * w[0] + f->model[r * 4 + 1] * w[1] + f->model[r * 4 + 2] * w[2];
                len += g[r] * g[r];
            }
            len = sqrt(len);
            if (!(len > 0) || !isfinite(len)) continue; /* a degenerate triangle covers no pixel */
            for (int j = 0; j < 3; j++) {
                float *o = out + (n + (uint64_t)j) * CORNER_FLOATS;
                memcpy(o, v[j], 3 * sizeof *o);
                for (int r = 0; r < 3; r++) o[3 + r] = (float)(g[r] / len);
                o[6] = (float)c;
            }
            n += 3;
        }
        if (volume < 0) /* inward winding: this cutter's normals turn round */
            for (uint64_t i = first; i < n; i++)
                for (int r = 3; r < 6; r++) out[i * CORNER_FLOATS + r] = -out[i * CORNER_FLOATS + r];
    }
    return n;
}

/* The layers buffer and the peel's framebuffer for a width x height frame. */
static int ensure_layers(vxl_cut_state *s, uint32_t w, uint32_t h)
{
    vxl_gl *gl = &s->gpu->gl;
    if (s->layers && s->width == w && s->height == h) return VXL_OK;
    if (!s->layers) gl->GenBuffers(1, &s->layers);
    gl->BindBuffer(GL_SHADER_STORAGE_BUFFER, s->layers);
    gl->BufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(layer_bytes((uint64_t)w * h) - (uint64_t)w * h), NULL,
                   GL_DYNAMIC_COPY);
    if (s->target) gl->DeleteTextures(1, &s->target);
    s->target = vxl_texture_new(s->gpu, GL_TEXTURE_2D, GL_NEAREST);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_R8, (GLsizei)w, (GLsizei)h, 0, GL_RED, GL_UNSIGNED_BYTE, NULL);
    if (!s->fbo) gl->GenFramebuffers(1, &s->fbo);
    gl->BindFramebuffer(GL_FRAMEBUFFER, s->fbo);
    gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, s->target, 0);
    int rc = vxl_gl_check(s->gpu, "allocating the cutter layers");
    if (!rc && gl->CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        rc = vxl_fail(&s->gpu->err, VXL_ERR_GL, "the %ux%u cutter peel framebuffer is incomplete", w, h);
    if (rc) {
        vxl_cut_release(s);
        return rc;
    }
    s->width = w;
    s->height = h;
    return VXL_OK;
}

/* Uploads n corners (a fresh buffer each frame: the meshes move). */
static void upload_corners(vxl_cut_state *s, const float *corners, uint64_t n)
{
    vxl_gl *gl = &s->gpu->gl;
    if (!s->vao) {
        gl->GenVertexArrays(1, &s->vao);
        gl->GenBuffers(1, &s->vbo);
    }
    gl->BindVertexArray(s->vao);
    gl->BindBuffer(GL_ARRAY_BUFFER, s->vbo);
    s->vbo_bytes = n * CORNER_FLOATS * sizeof(float);
    gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)s->vbo_bytes, corners, GL_STREAM_DRAW);
    gl->VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, CORNER_FLOATS * sizeof(float), (const void *)0);
    gl->VertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, CORNER_FLOATS * sizeof(float), (const void *)(3 * sizeof(float)));
    gl->EnableVertexAttribArray(0);
    gl->EnableVertexAttribArray(1);
}

static void set_matrix(vxl_gl *gl, GLuint prog, const char *name, const double m[16])
{
    float v[16];
    for (int i = 0; i < 16; i++) v[i] = (float)m[i];
    gl->UniformMatrix4fv(gl->GetUniformLocation(prog, name), 1, GL_FALSE, v);
}

int vxl_cut_prepare(vxl_cut_state *s, const vxl_frame *f)
{
    if (!f->cut.cutter_count) {
        vxl_cut_release(s); /* no layers held between frames that have no cutters */
        return VXL_OK;
    }
    vxl_gl *gl = &s->gpu->gl;
    uint64_t tris = 0;
    for (uint32_t c = 0; c < f->cut.cutter_count; c++) tris += f->cut.cutters[c].triangle_count;
    uint64_t pixels = (uint64_t)f->width * f->height;
    uint64_t vbo = tris * 3 * CORNER_FLOATS * sizeof(float);
    uint64_t need = layer_bytes(pixels) + vbo;
    /* the shaders index the layers with 32-bit ints */
    if (pixels * (1 + 2 * VXL_CUT_LAYERS) >= (1ull << 31))
        return vxl_fail(&s->gpu->err, VXL_ERR_LIMIT, "cutters: a %ux%u image has too many pixels for the cutter layers",
                        f->width, f->height);
    int rc = vxl_holdings_ask(s->gpu, VXL_HOLD_CUTAWAY, need, " (a smaller image, or fewer cutter triangles)",
                              "cutter layers for %ux%u pixels and %llu triangles", f->width, f->height,
                              (unsigned long long)tris);
    if (rc) return rc;
    float *corners = tris ? malloc((size_t)vbo) : NULL;
    if (tris && !corners)
        return vxl_fail(&s->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for %llu cutter triangles",
                        (unsigned long long)tris);
    uint64_t n = tris ? fill_corners(f, corners) : 0;
    GLuint prog;
    rc = vxl_program_get(s->gpu, VXL_PROG_CUT_PEEL, 0, 0, &prog);
    if (!rc) rc = ensure_layers(s, f->width, f->height);
    if (rc) {
        free(corners);
        return rc;
    }
    upload_corners(s, corners, n);
    free(corners);
    s->bytes = layer_bytes(pixels) + s->vbo_bytes;
    /* every pixel's count to 0; the crossings past a count are never read */
    gl->BindBuffer(GL_SHADER_STORAGE_BUFFER, s->layers);
    gl->ClearBufferSubData(GL_SHADER_STORAGE_BUFFER, GL_R32UI, 0, (GLsizeiptr)(pixels * 4), GL_RED_INTEGER,
                           GL_UNSIGNED_INT, NULL);
    gl->BindBufferBase(GL_SHADER_STORAGE_BUFFER, VXL_SSBO_CUT_LAYERS, s->layers);
    gl->BindFramebuffer(GL_FRAMEBUFFER, s->fbo);
    const GLenum none = GL_NONE;
    gl->DrawBuffers(1, &none);
    gl->Viewport(0, 0, (GLsizei)f->width, (GLsizei)f->height);
    gl->Disable(GL_DEPTH_TEST);
    gl->Disable(GL_BLEND);
    gl->Disable(GL_SCISSOR_TEST);
    gl->Disable(GL_CULL_FACE);
    gl->UseProgram(prog);
    double vp[16];
    vxl_mat4_mul(vp, f->proj, f->view);
    set_matrix(gl, prog, "u_view_proj", vp);
    set_matrix(gl, prog, "u_view", f->view);
    vxl_uniform_i(s->gpu, prog, "u_cut_width", (int)f->width);
    vxl_uniform_i(s->gpu, prog, "u_cut_pixels", (int)pixels);
    if (n) gl->DrawArrays(GL_TRIANGLES, 0, (GLsizei)n);
    gl->MemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    gl->BindVertexArray(0);
    gl->UseProgram(0);
    return vxl_gl_check(s->gpu, "peeling the cutter meshes");
}

void vxl_cut_bind(vxl_cut_state *s, GLuint prog, const vxl_frame *f)
{
    const vxl_frame_cut *c = &f->cut;
    if (!c->any) return;
    vxl_gl *gl = &s->gpu->gl;
    vxl_uniform_i(s->gpu, prog, "u_cut_caps", c->caps);
    if (c->plane_count || c->has_crop) {
        float planes[VXL_MAX_CLIP_PLANES][4], thick[VXL_MAX_CLIP_PLANES];
        vxl_frame_cut_plane_floats(c, planes, thick);
        vxl_uniform_i(s->gpu, prog, "u_cut_plane_count", (int)c->plane_count);
        gl->Uniform4fv(gl->GetUniformLocation(prog, "u_cut_planes"), VXL_MAX_CLIP_PLANES, &planes[0][0]);
        gl->Uniform1fv(gl->GetUniformLocation(prog, "u_cut_thickness"), VXL_MAX_CLIP_PLANES, thick);
        vxl_uniform_i(s->gpu, prog, "u_cut_has_crop", c->has_crop);
        if (c->has_crop) set_matrix(gl, prog, "u_cut_crop", c->crop);
    }
    if (c->cutter_count) {
        GLuint outside = 0;
        for (uint32_t i = 0; i < c->cutter_count; i++) outside |= c->cutters[i].remove_outside ? 1u << i : 0u;
        gl->Uniform1ui(gl->GetUniformLocation(prog, "u_cut_outside"), outside);
        vxl_uniform_i(s->gpu, prog, "u_cut_width", (int)f->width);
        vxl_uniform_i(s->gpu, prog, "u_cut_pixels", (int)(f->width * f->height));
        gl->BindBufferBase(GL_SHADER_STORAGE_BUFFER, VXL_SSBO_CUT_LAYERS, s->layers);
    }
}
