/* shadow_maps.c - the lights' shadow maps of the scene's occluders
 * (shadow_maps.h): frusta around the volume's world box, one depth layer
 * per view in a 2D array texture, the occluders uploaded once per key. */
#include "shadow_maps.h"

#include <math.h>
#include <string.h>

#include "hash.h"
#include "holdings.h"
#include "mat4.h"

/* Beyond this angle from its axis a single perspective view stretches its
 * texels too much (tan 60 = 1.7 times the axis' size at the edge): a cube. */
#define MAX_HALF_ANGLE_TAN 1.7320508
#define MARGIN 0.02 /* of the box's radius, around every frustum: the filter reads past the box's edge cells */

void vxl_shadow_maps_init(vxl_shadow_maps_state *s, vxl_gpu *g) { s->gpu = g; }

uint64_t vxl_shadow_maps_bytes(const vxl_shadow_maps_state *s) { return s->map_bytes + s->mesh_bytes; }

void vxl_shadow_maps_release(vxl_shadow_maps_state *s)
{
    vxl_gl *gl = &s->gpu->gl;
    if (s->tex) gl->DeleteTextures(1, &s->tex);
    if (s->fbo) gl->DeleteFramebuffers(1, &s->fbo);
    if (s->vao) gl->DeleteVertexArrays(1, &s->vao);
    GLuint buffers[2] = {s->vbo, s->ebo};
    if (s->vbo || s->ebo) gl->DeleteBuffers(2, buffers);
    vxl_shadow_maps_state kept = {.gpu = s->gpu, .builds = s->builds};
    *s = kept;
}

/* The volume box's corners in world space, their centre and radius. */
static void world_box(const vxl_frame *f, const uint32_t dims[3], double corner[8][3], double centre[3], double *radius)
{
    for (int a = 0; a < 3; a++) centre[a] = 0;
    for (int c = 0; c < 8; c++) {
        double v[4] = {(c & 1) ? dims[0] - 0.5 : -0.5, (c & 2) ? dims[1] - 0.5 : -0.5, (c & 4) ? dims[2] - 0.5 : -0.5, 1}, w[4];
        vxl_mat4_transform(f->model, v, w);
        for (int a = 0; a < 3; a++) {
            corner[c][a] = w[a];
            centre[a] += w[a] / 8;
        }
    }
    double r2 = 0;
    for (int c = 0; c < 8; c++) {
        double d2 = 0;
        for (int a = 0; a < 3; a++) d2 += (corner[c][a] - centre[a]) * (corner[c][a] - centre[a]);
        r2 = d2 > r2 ? d2 : r2;
    }
    *radius = sqrt(r2) > 0 ? sqrt(r2) : 1;
}

/* Any up vector not parallel to the view direction d. */
static void up_for(const double d[3], double up[3])
{
    up[0] = 0;
    up[1] = 0;
    up[2] = 1;
    if (fabs(d[2]) > 0.9 * sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])) {
        up[1] = 1;
        up[2] = 0;
    }
}

static void ortho(double m[16], double l, double r, double b, double t, double n, double f)
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = 2 / (r - l);
    m[5] = 2 / (t - b);
    m[10] = -2 / (f - n);
    m[12] = -(r + l) / (r - l);
    m[13] = -(t + b) / (t - b);
    m[14] = -(f + n) / (f - n);
    m[15] = 1;
}

static void store_view(vxl_shadow_light *L, int v, const double proj[16], const double view[16])
{
    double m[16];
    vxl_mat4_mul(m, proj, view);
    vxl_mat4_to_float(L->matrix[v], m);
}

/* A directional light (unit dir towards it): an orthographic view along its
 * travel, tight around the corners. */
static void directional_frustum(vxl_shadow_light *L, const float dir[3], double corner[8][3], const double centre[3],
                                double radius, uint32_t size)
{
    double d[3] = {dir[0], dir[1], dir[2]}, eye[3], up[3], view[16], proj[16];
    for (int a = 0; a < 3; a++) eye[a] = centre[a] + d[a] * radius;
    up_for(d, up);
    vxl_mat4_look_at(view, eye, centre, up);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int c = 0; c < 8; c++) {
        double w[4] = {corner[c][0], corner[c][1], corner[c][2], 1}, v[4];
        vxl_mat4_transform(view, w, v);
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], v[a]);
            hi[a] = fmax(hi[a], v[a]);
        }
    }
    const double m = MARGIN * radius;
    ortho(proj, lo[0] - m, hi[0] + m, lo[1] - m, hi[1] + m, -hi[2] - m, -lo[2] + m);
    store_view(L, 0, proj, view);
    L->views = 1;
    L->texel_world = (float)(fmax(hi[0] - lo[0], hi[1] - lo[1]) + 2 * m) / (float)size;
}

/* A point light at pos: one perspective view at the box when its corners
 * lie in front within MAX_HALF_ANGLE of the axis, else a cube. */
static void point_frustum(vxl_shadow_light *L, const float pos[3], double corner[8][3], const double centre[3],
                          double radius, uint32_t size)
{
    double eye[3] = {pos[0], pos[1], pos[2]}, axis[3], up[3], view[16], proj[16];
    double dist = 0;
    for (int a = 0; a < 3; a++) {
        axis[a] = centre[a] - eye[a];
        dist += axis[a] * axis[a];
    }
    dist = sqrt(dist);
    double z_near = INFINITY, z_far = 0, tan_max = 0;
    int single = dist > 1e-6 * radius;
    if (single) {
        up_for(axis, up);
        vxl_mat4_look_at(view, eye, centre, up);
        for (int c = 0; c < 8 && single; c++) {
            double w[4] = {corner[c][0], corner[c][1], corner[c][2], 1}, v[4];
            vxl_mat4_transform(view, w, v);
            double ahead = -v[2];
            if (!(ahead > 1e-3 * radius)) {
                single = 0;
                break;
            }
            tan_max = fmax(tan_max, fmax(fabs(v[0]), fabs(v[1])) / ahead);
            z_near = fmin(z_near, ahead);
            z_far = fmax(z_far, ahead);
        }
        single = single && tan_max * (1 + MARGIN) < MAX_HALF_ANGLE_TAN;
    }
    if (single) {
        double t = fmax(tan_max * (1 + MARGIN), 1e-3);
        vxl_mat4_perspective(proj, 2 * atan(t), 1, 0.5 * z_near, z_far * (1 + MARGIN));
        store_view(L, 0, proj, view);
        L->views = 1;
        L->texel_world = (float)(2 * t * dist / size);
        return;
    }
    /* the cube: the six axis directions, 90 degrees each; its far plane
     * reaches the farthest corner, its near plane is small, and occluders
     * nearer than it clamp to depth 0 (they block) */
    z_far = 0;
    for (int c = 0; c < 8; c++) {
        double d2 = 0;
        for (int a = 0; a < 3; a++) d2 += (corner[c][a] - eye[a]) * (corner[c][a] - eye[a]);
        z_far = fmax(z_far, sqrt(d2));
    }
    vxl_mat4_perspective(proj, M_PI / 2, 1, 0.01 * radius, z_far * (1 + MARGIN) + 0.01 * radius);
    for (int v = 0; v < 6; v++) {
        double dir[3] = {0, 0, 0}, at[3];
        dir[v / 2] = v % 2 ? -1 : 1;
        for (int a = 0; a < 3; a++) at[a] = eye[a] + dir[a];
        up_for(dir, up);
        vxl_mat4_look_at(view, eye, at, up);
        store_view(L, v, proj, view);
    }
    L->views = 6;
    L->texel_world = (float)(2 * fmax(dist, 0.1 * radius) / size);
}

/* The occluders in the vertex and index buffers, once per key. */
static int upload_mesh(vxl_shadow_maps_state *s, const vxl_frame *f)
{
    vxl_gl *gl = &s->gpu->gl;
    if (s->mesh_key == f->occluder_key && s->triangle_count == f->occluder_triangle_count) return VXL_OK;
    const uint64_t bytes = (uint64_t)f->occluder_vertex_count * 3 * sizeof(float) +
                           (uint64_t)f->occluder_triangle_count * 3 * sizeof(uint32_t);
    s->mesh_key = 0;
    s->mesh_bytes = 0; /* the old buffers are replaced */
    int rc = vxl_holdings_ask(s->gpu, VXL_HOLD_SCENE_SHADOWS, bytes + s->map_bytes, NULL,
                              "the scene's %u occluder triangles", f->occluder_triangle_count);
    if (rc) return rc;
    if (!s->vao) {
        gl->GenVertexArrays(1, &s->vao);
        gl->GenBuffers(1, &s->vbo);
        gl->GenBuffers(1, &s->ebo);
    }
    gl->BindVertexArray(s->vao);
    gl->BindBuffer(GL_ARRAY_BUFFER, s->vbo);
    gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)f->occluder_vertex_count * 3 * sizeof(float), f->occluder_vertices,
                   GL_STATIC_DRAW);
    gl->VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), NULL);
    gl->EnableVertexAttribArray(0);
    gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, s->ebo); /* recorded in the vertex array */
    gl->BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)f->occluder_triangle_count * 3 * sizeof(uint32_t),
                   f->occluder_indices, GL_STATIC_DRAW);
    gl->BindVertexArray(0);
    gl->BindBuffer(GL_ARRAY_BUFFER, 0);
    if ((rc = vxl_gl_check(s->gpu, "uploading the scene's occluders"))) return rc;
    s->mesh_key = f->occluder_key;
    s->triangle_count = f->occluder_triangle_count;
    s->mesh_bytes = bytes;
    return VXL_OK;
}

/* The map array with at least `layers` layers of size^2 (kept when it has them). */
static int allocate_maps(vxl_shadow_maps_state *s, uint32_t size, uint32_t layers)
{
    vxl_gl *gl = &s->gpu->gl;
    if (s->tex && s->size == size && s->layers >= layers) return VXL_OK;
    const uint64_t bytes = (uint64_t)size * size * layers * 4;
    if (s->tex) gl->DeleteTextures(1, &s->tex);
    s->tex = 0;
    s->map_bytes = 0;
    for (int i = 0; i < VXL_MAX_LIGHTS; i++) s->light[i].key = 0;
    int rc = vxl_holdings_ask(s->gpu, VXL_HOLD_SCENE_SHADOWS, bytes + s->mesh_bytes,
                              "; use a smaller scene_shadows.shadow_map_size", "%u shadow maps of %u^2", layers, size);
    if (rc) return rc;
    s->tex = vxl_texture_new(s->gpu, GL_TEXTURE_2D_ARRAY, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    gl->TexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT32F, (GLsizei)size, (GLsizei)size, (GLsizei)layers, 0,
                   GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    if (!s->fbo) gl->GenFramebuffers(1, &s->fbo);
    if ((rc = vxl_gl_check(s->gpu, "allocating the shadow maps"))) {
        gl->DeleteTextures(1, &s->tex);
        s->tex = 0;
        return rc;
    }
    s->size = size;
    s->layers = layers;
    s->map_bytes = bytes;
    return VXL_OK;
}

static int rasterise(vxl_shadow_maps_state *s, const vxl_shadow_light *L)
{
    vxl_gl *gl = &s->gpu->gl;
    GLuint prog;
    int rc = vxl_program_get(s->gpu, VXL_PROG_SHADOW_MAP, 0, 0, &prog);
    if (rc) return rc;
    gl->UseProgram(prog);
    GLint loc = gl->GetUniformLocation(prog, "u_light_matrix");
    gl->BindFramebuffer(GL_FRAMEBUFFER, s->fbo);
    const GLenum none = GL_NONE;
    gl->DrawBuffers(1, &none);
    gl->ReadBuffer(GL_NONE);
    gl->Viewport(0, 0, (GLsizei)s->size, (GLsizei)s->size);
    gl->Disable(GL_SCISSOR_TEST);
    gl->Disable(GL_BLEND);
    gl->Enable(GL_DEPTH_TEST);
    gl->Enable(GL_DEPTH_CLAMP); /* occluders before the near plane block at depth 0 */
    gl->DepthFunc(GL_LESS);
    gl->DepthMask(GL_TRUE);
    gl->BindVertexArray(s->vao);
    const float z_far = 1;
    for (uint32_t v = 0; v < L->views; v++) {
        gl->FramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, s->tex, 0, (GLint)(L->first_layer + v));
        if (v == 0 && gl->CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            rc = vxl_fail(&s->gpu->err, VXL_ERR_GL, "the %u^2 shadow map framebuffer is incomplete", s->size);
            break;
        }
        gl->ClearBufferfv(GL_DEPTH, 0, &z_far);
        gl->UniformMatrix4fv(loc, 1, GL_FALSE, L->matrix[v]);
        gl->DrawElements(GL_TRIANGLES, (GLsizei)(s->triangle_count * 3), GL_UNSIGNED_INT, NULL);
    }
    gl->FramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, 0, 0, 0);
    gl->BindVertexArray(0);
    gl->Disable(GL_DEPTH_CLAMP);
    gl->Disable(GL_DEPTH_TEST);
    gl->UseProgram(0);
    return rc ? rc : vxl_gl_check(s->gpu, "rasterising the shadow maps");
}

int vxl_shadow_maps_prepare(vxl_shadow_maps_state *s, const vxl_frame *f, const uint32_t dims[3])
{
    s->rebuilt = 0;
    s->active = 0;
    if (!f->occluder_triangle_count) return VXL_OK; /* kept: a frame without occluders between two with costs nothing */
    double corner[8][3], centre[3], radius;
    world_box(f, dims, corner, centre, &radius);
    vxl_shadow_light next[VXL_MAX_LIGHTS];
    uint32_t layers = 0;
    for (int i = 0; i < f->light_count; i++) {
        memset(&next[i], 0, sizeof next[i]);
        if (f->light_world[i][3] == 0) directional_frustum(&next[i], f->light_world[i], corner, centre, radius, f->shadow_map_size);
        else point_frustum(&next[i], f->light_world[i], corner, centre, radius, f->shadow_map_size);
        next[i].first_layer = layers;
        layers += next[i].views;
    }
    int rc = upload_mesh(s, f);
    if (!rc) rc = allocate_maps(s, f->shadow_map_size, layers);
    if (rc) return rc;
    for (int i = 0; i < f->light_count; i++) {
        uint64_t k = vxl_fnv(f->occluder_key, f->light_world[i], sizeof f->light_world[i]);
        k = vxl_fnv(k, &f->shadow_map_size, sizeof f->shadow_map_size);
        k = vxl_fnv(k, f->model, sizeof f->model);
        k = vxl_fnv(k, dims, 3 * sizeof *dims);
        k = vxl_fnv(k, &next[i].first_layer, sizeof next[i].first_layer);
        k = k ? k : 1;
        if (s->light[i].key == k) continue;
        s->light[i] = next[i];
        s->light[i].key = 0;
        if ((rc = rasterise(s, &s->light[i]))) return rc;
        s->light[i].key = k;
        s->rebuilt++;
        s->builds++;
    }
    s->active = 1;
    return VXL_OK;
}

void vxl_shadow_maps_bind(vxl_shadow_maps_state *s, GLuint prog, const vxl_frame *f, int i, float bias, float pcf)
{
    vxl_gl *gl = &s->gpu->gl;
    const vxl_shadow_light *L = &s->light[i];
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SHADOW_MAP_UNIT);
    gl->BindTexture(GL_TEXTURE_2D_ARRAY, s->tex);
#define LOC(name) gl->GetUniformLocation(prog, name)
    gl->Uniform1i(LOC("u_shadow_maps"), VXL_SHADOW_MAP_UNIT);
    gl->UniformMatrix4fv(LOC("u_shadow_matrix"), (GLsizei)L->views, GL_FALSE, &L->matrix[0][0]);
    gl->Uniform1i(LOC("u_shadow_views"), (GLint)L->views);
    gl->Uniform1f(LOC("u_shadow_first_layer"), (float)L->first_layer);
    gl->Uniform4fv(LOC("u_shadow_light"), 1, f->light_world[i]);
    gl->Uniform1f(LOC("u_shadow_bias"), bias);
    /* the filter's half width in texels: a cell's footprint, at least the bilinear one */
    gl->Uniform1f(LOC("u_shadow_pcf"), fmaxf(0.5f, fminf(16.0f, pcf / L->texel_world)));
#undef LOC
}
