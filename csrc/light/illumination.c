/* illumination.c - the illumination volumes (illumination.h): a grid of
 * cells over the volume box, the extinction pass, one transmittance volume
 * per light (swept slice by slice away from the light) and the occlusion,
 * all by shaders/compute/illumination.comp, each keyed by what it depends
 * on. The size is asked of the memory budget (budget.h): over it, the grid
 * halves until it fits. */
#include "illumination.h"

#include <math.h>
#include <string.h>

#include "environment_map.h"
#include "hash.h"
#include "holdings.h"
#include "mat4.h"
#include "storage.h"

/* Cells along the longest side when the frame leaves it to us. On a
 * 181x217x181 head (ch2better) at 512^2 on llvmpipe, under load: a light
 * move adds little to a frame; a transfer-function change (the extinction
 * pass) about a frame at 64 and twice that at 96. */
#define AUTO_SIZE 64u
#define MIN_SIZE 8u

enum { PASS_EXTINCTION, PASS_SWEEP, PASS_OCCLUSION, PASS_SCENE_SHADOWS, PASS_ENVIRONMENT = VXL_FLAG_ENVIRONMENT };
/* The environment's irradiance is a mean over the whole sphere, smoother
 * than any lamp's shadow: it is kept on a grid half as fine as the lamps'
 * per axis, an eighth of the cells and of the pass's cost. Its RGBA16F
 * texture then weighs at most as much as one R16F block. */
#define ENV_BLOCKS 1u

static void env_grid(const uint32_t cells[3], uint32_t out[3])
{
    for (int a = 0; a < 3; a++) out[a] = (cells[a] + 1) / 2;
}

void vxl_illumination_release(vxl_illumination_state *s)
{
    if (s->extinction_tex) s->gpu->gl.DeleteTextures(1, &s->extinction_tex);
    if (s->tex) s->gpu->gl.DeleteTextures(1, &s->tex);
    if (s->env_tex) s->gpu->gl.DeleteTextures(1, &s->env_tex);
    if (s->scene_depth_tex) s->gpu->gl.DeleteTextures(1, &s->scene_depth_tex);
    if (s->transmittance_tex) s->gpu->gl.DeleteTextures(1, &s->transmittance_tex);
    vxl_shadow_maps_release(&s->shadows);
    vxl_illumination_state kept = {.gpu = s->gpu, .storage = s->storage, .builds = s->builds, .shadows = s->shadows,
                                   .bind_labels = s->bind_labels, .labels_ctx = s->labels_ctx};
    *s = kept;
}

/* GL memory: the shadow maps, the occluders, the transmittance images. */
static uint64_t scene_shadow_bytes(const void *state)
{
    const vxl_illumination_state *s = state;
    return vxl_shadow_maps_bytes(&s->shadows) + s->image_bytes;
}

void vxl_illumination_init(vxl_illumination_state *s, vxl_gpu *g, vxl_storage_state *st)
{
    s->gpu = g;
    s->storage = st;
    vxl_holding_register(g, VXL_HOLD_ILLUMINATION, vxl_holding_counter, &s->bytes);
    vxl_shadow_maps_init(&s->shadows, g);
    vxl_holding_register(g, VXL_HOLD_SCENE_SHADOWS, scene_shadow_bytes, s);
}

/* Light i in voxel space: w = 0 the unit direction towards it, w = 1 its
 * position; *radius its radius in voxels (point lights). */
static void light_voxel(const vxl_frame *f, int i, float out[4], float *radius)
{
    double inv[16], w[4] = {f->light_world[i][0], f->light_world[i][1], f->light_world[i][2], f->light_world[i][3]}, v[4];
    if (!vxl_mat4_invert(inv, f->model)) vxl_mat4_identity(inv); /* frame.c refuses a singular model */
    vxl_mat4_transform(inv, w, v);
    double n = w[3] == 0 ? sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) : 1;
    if (!(n > 0)) n = 1;
    for (int k = 0; k < 3; k++) out[k] = (float)(v[k] / n);
    out[3] = (float)w[3];
    /* world units per voxel: the geometric mean of the model's axes */
    double vox = 1;
    for (int a = 0; a < 3; a++)
        vox *= sqrt(f->model[4 * a] * f->model[4 * a] + f->model[4 * a + 1] * f->model[4 * a + 1] +
                    f->model[4 * a + 2] * f->model[4 * a + 2]);
    vox = cbrt(vox);
    *radius = w[3] != 0 && vox > 0 ? (float)(f->light_size[i] / vox) : 0.0f;
}

static void grid_for(const vxl_illumination_state *s, uint32_t size, uint32_t cells[3])
{
    uint32_t longest = s->storage->geom.dims[0];
    for (int a = 1; a < 3; a++) longest = s->storage->geom.dims[a] > longest ? s->storage->geom.dims[a] : longest;
    for (int a = 0; a < 3; a++) {
        uint32_t n = (uint32_t)ceil((double)s->storage->geom.dims[a] * size / longest);
        cells[a] = n < 1 ? 1 : n > s->storage->geom.dims[a] ? s->storage->geom.dims[a] : n; /* never finer than the voxels */
    }
}

static uint64_t extinction_bytes(const uint32_t c[3]) { return (uint64_t)c[0] * c[1] * c[2] * 4; } /* R32F */
static uint64_t light_bytes(const uint32_t c[3], uint32_t blocks) { return (uint64_t)c[0] * c[1] * c[2] * 2 * blocks; }
static uint64_t bytes_for(const uint32_t cells[3], uint32_t blocks)
{
    return extinction_bytes(cells) + light_bytes(cells, blocks);
}

/* The grid the budget allows: the asked size, halved until it fits. */
static int choose_grid(vxl_illumination_state *s, const vxl_frame *f, uint32_t blocks, uint32_t *size, uint32_t cells[3])
{
    uint32_t n = f->illumination_size ? f->illumination_size : AUTO_SIZE;
    uint64_t held[VXL_HOLD_COUNT];
    vxl_holdings(s->gpu, held);
    for (;;) {
        grid_for(s, n, cells);
        uint64_t bytes = bytes_for(cells, blocks);
        if (vxl_budget_fits(s->gpu->budget, held, VXL_HOLD_ILLUMINATION, bytes)) break;
        if (n / 2 < MIN_SIZE)
            return vxl_holdings_ask(s->gpu, VXL_HOLD_ILLUMINATION, bytes, NULL, "illumination volumes of %ux%ux%u cells",
                                    cells[0], cells[1], cells[2]);
        n /= 2;
    }
    *size = n;
    return VXL_OK;
}

/* Whether the extinction grid held, built for classification `key`, can
 * serve lights on `cells`: as fine or finer (the passes read it through its
 * sampler, in voxel coordinates, whatever its grid), and within the budget
 * beside them. Then a change of the lights' grid alone, such as the add-on's
 * coarser grid while a light is dragged and back, costs no extinction pass. */
static int keeps_extinction(vxl_illumination_state *s, uint64_t key, const uint32_t cells[3], uint32_t blocks)
{
    if (!s->extinction_tex || s->extinction_key != key) return 0;
    for (int a = 0; a < 3; a++)
        if (s->extinction_cells[a] < cells[a]) return 0;
    uint64_t held[VXL_HOLD_COUNT];
    vxl_holdings(s->gpu, held);
    return vxl_budget_fits(s->gpu->budget, held, VXL_HOLD_ILLUMINATION,
                           extinction_bytes(s->extinction_cells) + light_bytes(cells, blocks));
}

/* The extinction texture on ext_cells, the lights' on cells x blocks and
 * (env) the environment's on cells; a texture already of its size is kept
 * with what it holds. */
static int allocate(vxl_illumination_state *s, const uint32_t ext_cells[3], const uint32_t cells[3], uint32_t blocks,
                    int env)
{
    vxl_gl *gl = &s->gpu->gl;
    if (!s->extinction_tex || memcmp(s->extinction_cells, ext_cells, sizeof s->extinction_cells)) {
        if (s->extinction_tex) gl->DeleteTextures(1, &s->extinction_tex);
        s->extinction_tex = vxl_texture_new(s->gpu, GL_TEXTURE_3D, GL_LINEAR);
        gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)ext_cells[0], (GLsizei)ext_cells[1], (GLsizei)ext_cells[2], 0,
                       GL_RED, GL_FLOAT, NULL);
        memcpy(s->extinction_cells, ext_cells, sizeof s->extinction_cells);
        s->extinction_key = 0;
    }
    if (!s->tex || memcmp(s->cells, cells, sizeof s->cells) || s->blocks != blocks) {
        if (s->tex) gl->DeleteTextures(1, &s->tex);
        s->tex = vxl_texture_new(s->gpu, GL_TEXTURE_3D, GL_LINEAR);
        gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R16F, (GLsizei)cells[0], (GLsizei)cells[1], (GLsizei)(cells[2] * blocks), 0,
                       GL_RED, GL_FLOAT, NULL);
        memcpy(s->cells, cells, sizeof s->cells);
        s->blocks = blocks;
        memset(s->light_key, 0, sizeof s->light_key);
        s->occlusion_key = 0;
    }
    uint32_t ec[3];
    env_grid(cells, ec);
    if (s->env_tex && (!env || memcmp(s->env_cells, ec, sizeof s->env_cells))) {
        gl->DeleteTextures(1, &s->env_tex);
        s->env_tex = 0;
    }
    if (env && !s->env_tex) {
        s->env_tex = vxl_texture_new(s->gpu, GL_TEXTURE_3D, GL_LINEAR);
        gl->TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA16F, (GLsizei)ec[0], (GLsizei)ec[1], (GLsizei)ec[2], 0, GL_RGBA, GL_FLOAT,
                       NULL);
        memcpy(s->env_cells, ec, sizeof s->env_cells);
        s->env_key = 0;
    }
    s->bytes = extinction_bytes(s->extinction_cells) + light_bytes(s->cells, s->blocks) +
               (s->env_tex ? (uint64_t)s->env_cells[0] * s->env_cells[1] * s->env_cells[2] * 8 : 0);
    int rc = vxl_gl_check(s->gpu, "allocating the illumination volumes");
    if (rc) {
        uint32_t builds = s->builds;
        vxl_illumination_release(s);
        s->builds = builds;
    }
    return rc;
}

/* A pass's program with the grid's uniforms set (and in use). */
static int pass_program(vxl_illumination_state *s, uint32_t pass, uint32_t extinction_flags, const uint32_t cells[3],
                        GLuint *prog)
{
    vxl_gl *gl = &s->gpu->gl;
    uint32_t flags = pass | (pass == PASS_EXTINCTION ? extinction_flags | s->storage->ops->sample_flags(s->storage) : 0);
    int rc = vxl_program_get(s->gpu, VXL_PROG_ILLUMINATION, 0, flags, prog);
    if (rc) return rc;
    if (pass == PASS_EXTINCTION) {
        rc = vxl_storage_bind_sampling(s->storage, *prog); /* the ray caster's sampling */
        if (rc) return rc;
    } else {
        gl->UseProgram(*prog);
        float dims[3] = {(float)s->storage->geom.dims[0], (float)s->storage->geom.dims[1], (float)s->storage->geom.dims[2]};
        gl->Uniform3fv(gl->GetUniformLocation(*prog, "u_dims"), 1, dims);
        gl->ActiveTexture(GL_TEXTURE0 + VXL_EXTINCTION_UNIT);
        gl->BindTexture(GL_TEXTURE_3D, s->extinction_tex);
        vxl_uniform_i(s->gpu, *prog, "u_extinction", VXL_EXTINCTION_UNIT);
        /* sampled at its own cell size: point samples a coarser grid's cell
         * apart would alias a kept finer extinction (keeps_extinction) */
        float step = 0;
        for (int a = 0; a < 3; a++) {
            float h = (float)s->storage->geom.dims[a] / (float)s->extinction_cells[a];
            step = a == 0 || h < step ? h : step;
        }
        vxl_uniform_f(s->gpu, *prog, "u_ext_step", step);
    }
    float cell[3];
    for (int a = 0; a < 3; a++) cell[a] = (float)s->storage->geom.dims[a] / (float)cells[a];
    gl->Uniform3i(gl->GetUniformLocation(*prog, "u_cells"), (GLint)cells[0], (GLint)cells[1], (GLint)cells[2]);
    gl->Uniform3fv(gl->GetUniformLocation(*prog, "u_cell"), 1, cell);
    return VXL_OK;
}

/* Every pass writes with image stores and is read through samplers: the
 * next pass (the sweep and the occlusion read the extinction), the sweep's
 * next slice (the texture it writes, read back as u_previous) and the ray
 * caster. By the GL spec (7.13.2, MemoryBarrier) texture fetches after image
 * stores need GL_TEXTURE_FETCH_BARRIER_BIT, which also invalidates texture
 * caches; GL_SHADER_IMAGE_ACCESS_BARRIER_BIT orders image loads and stores,
 * which no pass makes of another's output, and GL_TEXTURE_UPDATE_BARRIER_BIT
 * readbacks, which nothing does. Within one dispatch no texel is both
 * written and fetched: a sweep dispatch writes one slice and fetches others. */
#define AFTER_IMAGE_STORES GL_TEXTURE_FETCH_BARRIER_BIT

static void dispatch_cells(vxl_illumination_state *s, const uint32_t c[3])
{
    s->gpu->gl.DispatchCompute((c[0] + 3) / 4, (c[1] + 3) / 4, (c[2] + 3) / 4);
    s->gpu->gl.MemoryBarrier(AFTER_IMAGE_STORES);
}

/* Whether the frame's clip planes or crop box cut the volume: what they
 * remove casts no shadow, on the volume itself nor on the scene. The
 * cutter meshes are peeled from the camera per pixel and have no voxel-space
 * form here, so they do not cut the shadows (docs/scene_shadows.md). */
static int cuts_convex(const vxl_frame *f) { return f->cut.any && (f->cut.plane_count || f->cut.has_crop); }

/* Whether hidden labels leave the extinction (a label map that is shown). */
static int masks_labels(const vxl_illumination_state *s, const vxl_frame *f) { return f->labels.on && s->bind_labels; }

/* The clip planes' and crop box's uniforms, as cut/cutaway.c hands the ray
 * caster the same numbers (voxel space; shaders/compute/illumination.comp's
 * cut_keeps reads them). */
static void bind_cut(vxl_illumination_state *s, GLuint prog, const vxl_frame *f)
{
    vxl_gl *gl = &s->gpu->gl;
    const vxl_frame_cut *c = &f->cut;
    float planes[VXL_MAX_CLIP_PLANES][4], thick[VXL_MAX_CLIP_PLANES], crop[16];
    vxl_frame_cut_plane_floats(c, planes, thick);
    vxl_uniform_i(s->gpu, prog, "u_cut_plane_count", (int)c->plane_count);
    gl->Uniform4fv(gl->GetUniformLocation(prog, "u_cut_planes"), VXL_MAX_CLIP_PLANES, &planes[0][0]);
    gl->Uniform1fv(gl->GetUniformLocation(prog, "u_cut_thickness"), VXL_MAX_CLIP_PLANES, thick);
    vxl_uniform_i(s->gpu, prog, "u_cut_has_crop", c->has_crop);
    vxl_mat4_to_float(crop, c->crop);
    gl->UniformMatrix4fv(gl->GetUniformLocation(prog, "u_cut_crop"), 1, GL_FALSE, crop);
}

static int build_extinction(vxl_illumination_state *s, const vxl_frame *f)
{
    vxl_gl *gl = &s->gpu->gl;
    GLuint prog;
    uint32_t flags = f->gopacity << 2 | (cuts_convex(f) ? VXL_FLAG_CUT_CONVEX : 0) |
                     (masks_labels(s, f) ? (f->labels.mode + 1u) << VXL_FLAG_LABELS_SHIFT |
                                                (f->labels.voxels ? VXL_FLAG_LABEL_VOXELS : 0u)
                                          : 0);
    int rc = pass_program(s, PASS_EXTINCTION, flags, s->extinction_cells, &prog);
    if (rc) return rc;
    if (cuts_convex(f)) bind_cut(s, prog, f);
    if (masks_labels(s, f) && (rc = s->bind_labels(s->labels_ctx, f, prog))) return rc;
    /* the classification uniforms of lib/classify.glsl; the table is on its unit */
    vxl_uniform_i(s->gpu, prog, "u_tf", VXL_TF_UNIT);
    vxl_uniform_f(s->gpu, prog, "u_tf_size", (float)f->tf_size);
    gl->Uniform2f(gl->GetUniformLocation(prog, "u_window"), f->window_offset, f->window_scale);
    vxl_uniform_f(s->gpu, prog, "u_opacity_scale", f->opacity_scale);
    vxl_uniform_f(s->gpu, prog, "u_sample_distance", f->sample_distance);
    if (f->gopacity == VXL_GOPACITY_BOUNDARY)
        gl->Uniform2f(gl->GetUniformLocation(prog, "u_gopacity_param"), f->gradient_ref, f->gradient_exp);
    else if (f->gopacity == VXL_GOPACITY_ISO)
        gl->Uniform2f(gl->GetUniformLocation(prog, "u_gopacity_param"), f->iso_pos, f->iso_thickness);
    /* two trilinear samples per cell and axis when a cell spans more than a
     * voxel: each reads a 2^3 neighbourhood, so a cell of up to ~3 voxels is
     * read whole, and the pass stays a small part of a frame (more samples
     * made a transfer-function change cost several frames on llvmpipe) */
    GLint sub[3];
    for (int a = 0; a < 3; a++) sub[a] = s->storage->geom.dims[a] > s->extinction_cells[a] ? 2 : 1;
    gl->Uniform3i(gl->GetUniformLocation(prog, "u_sub"), sub[0], sub[1], sub[2]);
    gl->BindImageTexture(VXL_IMAGE_OUT, s->extinction_tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    dispatch_cells(s, s->extinction_cells);
    return vxl_gl_check(s->gpu, "building the extinction volume");
}

/* Slices first .. last (either order) of one sweep, starting at voxel
 * coordinate `from` along the axis. */
static void sweep(vxl_illumination_state *s, GLuint prog, int axis, int first, int last, float from)
{
    vxl_gl *gl = &s->gpu->gl;
    const uint32_t *c = s->cells;
    const uint32_t w = c[(axis + 1) % 3], h = c[(axis + 2) % 3];
    GLint slice_loc = gl->GetUniformLocation(prog, "u_slice"), first_loc = gl->GetUniformLocation(prog, "u_first");
    vxl_uniform_f(s->gpu, prog, "u_from", from);
    const int dir = last >= first ? 1 : -1;
    for (int k = first;; k += dir) {
        gl->Uniform1i(slice_loc, k);
        gl->Uniform1i(first_loc, k == first);
        gl->DispatchCompute((w + 7) / 8, (h + 7) / 8, 1);
        gl->MemoryBarrier(AFTER_IMAGE_STORES); /* the next slice fetches this one */
        if (k == last) break;
    }
}

static int dominant_axis(const double v[3])
{
    int axis = 2;
    for (int a = 0; a < 2; a++)
        if (fabs(v[a]) > fabs(v[axis])) axis = a;
    return axis;
}

/* Light i's transmittance volume: a directional light sweeps from the box
 * face it enters by, along the dominant axis of its travel; a point light
 * sweeps away from its plane across the axis towards the box's centre, both
 * ways when the plane cuts the box. */
static int build_light(vxl_illumination_state *s, int i, const float lv[4], float radius, float size)
{
    vxl_gl *gl = &s->gpu->gl;
    GLuint prog;
    int point = lv[3] != 0;
    int rc = pass_program(s, PASS_SWEEP, 0, s->cells, &prog);
    if (rc) return rc;
    vxl_uniform_i(s->gpu, prog, "u_block", i);
    gl->BindImageTexture(VXL_IMAGE_OUT, s->tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R16F);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_ILLUMINATION_UNIT); /* read back, slice by slice */
    gl->BindTexture(GL_TEXTURE_3D, s->tex);
    vxl_uniform_i(s->gpu, prog, "u_previous", VXL_ILLUMINATION_UNIT);
    float light[4] = {point ? lv[0] : -lv[0], point ? lv[1] : -lv[1], point ? lv[2] : -lv[2], lv[3]};
    gl->Uniform4fv(gl->GetUniformLocation(prog, "u_light"), 1, light);
    vxl_uniform_f(s->gpu, prog, "u_spread", point ? radius : tanf(0.5f * size));
    double axis_of[3];
    for (int a = 0; a < 3; a++) axis_of[a] = point ? 0.5 * (s->storage->geom.dims[a] - 1.0) - lv[a] : light[a];
    const int axis = dominant_axis(axis_of);
    vxl_uniform_i(s->gpu, prog, "u_axis", axis);
    const int n = (int)s->cells[axis];
    const float lo = -0.5f, hi = (float)s->storage->geom.dims[axis] - 0.5f, cell = (float)s->storage->geom.dims[axis] / (float)n;
    if (!point) {
        if (light[axis] > 0) sweep(s, prog, axis, 0, n - 1, lo);
        else sweep(s, prog, axis, n - 1, 0, hi);
        return vxl_gl_check(s->gpu, "sweeping a directional light's illumination volume");
    }
    /* slices whose centre (k + 0.5) * cell - 0.5 lies beyond the light's
     * plane go up from it, the others down */
    double up0 = ceil((lv[axis] + 0.5) / cell - 0.5 + 1e-9);
    int k_up = up0 < 0 ? 0 : up0 > n ? n : (int)up0;
    if (k_up < n) sweep(s, prog, axis, k_up, n - 1, lv[axis] > lo ? lv[axis] : lo);
    if (k_up > 0) sweep(s, prog, axis, k_up - 1, 0, lv[axis] < hi ? lv[axis] : hi);
    return vxl_gl_check(s->gpu, "sweeping a point light's illumination volume");
}

static int build_occlusion(vxl_illumination_state *s, const vxl_frame *f, int block)
{
    GLuint prog;
    int rc = pass_program(s, PASS_OCCLUSION, 0, s->cells, &prog);
    if (rc) return rc;
    vxl_uniform_i(s->gpu, prog, "u_block", block);
    vxl_uniform_f(s->gpu, prog, "u_radius", f->ao_radius);
    s->gpu->gl.BindImageTexture(VXL_IMAGE_OUT, s->tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R16F);
    dispatch_cells(s, s->cells);
    return vxl_gl_check(s->gpu, "building the ambient occlusion volume");
}

/* World units per cell: the longest of a cell's edges in world space. */
static float cell_world(const vxl_illumination_state *s, const vxl_frame *f)
{
    double longest = 0;
    for (int a = 0; a < 3; a++) {
        const double *col = f->model + 4 * a;
        double edge = sqrt(col[0] * col[0] + col[1] * col[1] + col[2] * col[2]) * s->storage->geom.dims[a] / s->cells[a];
        longest = edge > longest ? edge : longest;
    }
    return (float)longest;
}

/* Light i's block times the visibility through the scene's occluders
 *, cell by cell. The compared point moves half a cell towards
 * the light, plus the map's texels' depth error, so a cell an occluder
 * surface cuts is not shadowed by that surface; the filter spans a cell, so
 * the trilinear read between cells sees a soft, not a stepped, edge. */
static int apply_scene_shadows(vxl_illumination_state *s, const vxl_frame *f, int i)
{
    GLuint prog;
    int rc = pass_program(s, PASS_SCENE_SHADOWS, 0, s->cells, &prog);
    if (rc) return rc;
    vxl_gl *gl = &s->gpu->gl;
    const float cell = cell_world(s, f);
    vxl_shadow_maps_bind(&s->shadows, prog, f, i, 0.5f * cell + 1.5f * s->shadows.light[i].texel_world, 0.5f * cell);
    float model[16];
    vxl_mat4_to_float(model, f->model);
    gl->UniformMatrix4fv(gl->GetUniformLocation(prog, "u_model"), 1, GL_FALSE, model);
    vxl_uniform_i(s->gpu, prog, "u_block", i);
    gl->BindImageTexture(VXL_IMAGE_OUT, s->tex, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R16F);
    gl->MemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT); /* image loads of what the sweep stored */
    dispatch_cells(s, s->cells);
    return vxl_gl_check(s->gpu, "cutting a light's illumination volume by the scene's shadows");
}

/* The environment's irradiance E(x) per cell: each direction cell's
 * radiance times its transmittance to the box, weighed by its solid angle
 * (1 / cells of the sphere: a uniform map that nothing occludes gives E =
 * its radiance). The directions go into voxel space as the lights' do. */
static void environment_voxel_dirs(const vxl_frame *f, float dirs[VXL_ENV_CELLS][3])
{
    double inv[16];
    if (!vxl_mat4_invert(inv, f->model)) vxl_mat4_identity(inv); /* frame.c refuses a singular model */
    for (int k = 0; k < VXL_ENV_CELLS; k++) {
        double w[4] = {0, 0, 0, 0}, v[4];
        vxl_environment_cell_direction(k, w);
        vxl_mat4_transform(inv, w, v);
        double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!(n > 0)) n = 1;
        for (int a = 0; a < 3; a++) dirs[k][a] = (float)(v[a] / n);
    }
}

static int build_environment(vxl_illumination_state *s, const float dirs[VXL_ENV_CELLS][3])
{
    vxl_gl *gl = &s->gpu->gl;
    GLuint prog;
    int rc = pass_program(s, PASS_ENVIRONMENT, 0, s->env_cells, &prog);
    if (rc) return rc;
    float radiance[VXL_ENV_CELLS][3], start = 0;
    for (int k = 0; k < VXL_ENV_CELLS; k++)
        for (int c = 0; c < 3; c++) radiance[k][c] = s->env_radiance[k][c] / VXL_ENV_CELLS;
    /* half a cell out, as the lights' reads move half a cell towards the
     * light: a surface half fills its own cell and would occlude itself */
    for (int a = 0; a < 3; a++) {
        float cell = (float)s->storage->geom.dims[a] / (float)s->env_cells[a];
        start = cell > start ? cell : start;
    }
    gl->Uniform3fv(gl->GetUniformLocation(prog, "u_env_dir"), VXL_ENV_CELLS, &dirs[0][0]);
    gl->Uniform3fv(gl->GetUniformLocation(prog, "u_env_radiance"), VXL_ENV_CELLS, &radiance[0][0]);
    vxl_uniform_f(s->gpu, prog, "u_env_start", 0.5f * start);
    gl->BindImageTexture(VXL_IMAGE_OUT, s->env_tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    dispatch_cells(s, s->env_cells);
    return vxl_gl_check(s->gpu, "building the environment's irradiance volume");
}

/* The map's reduction, when its key changed: cheap next to a frame for the
 * add-on's 128 x 64 maps, a few hundred milliseconds for a large HDRI. */
static void reduce_environment(vxl_illumination_state *s, const vxl_frame *f)
{
    if (s->env_map_key == f->env.key) return;
    vxl_environment_reduce(f->env.rgb, f->env.width, f->env.height, f->env.strength, f->env.rotation_deg,
                           s->env_radiance);
    double mean[3] = {0, 0, 0};
    for (int k = 0; k < VXL_ENV_CELLS; k++)
        for (int c = 0; c < 3; c++) mean[c] += s->env_radiance[k][c];
    for (int c = 0; c < 3; c++) s->env_mean[c] = (float)(mean[c] / VXL_ENV_CELLS);
    s->env_map_key = f->env.key;
    s->env_key = 0; /* the irradiance follows the cells' radiance */
}

static int uses_illumination(const vxl_frame *f) { return f->shading && f->shading_model != VXL_SHADING_PHONG; }

int vxl_illumination_prepare(vxl_illumination_state *s, const vxl_frame *f)
{
    s->rebuilt = 0;
    s->in_use = 0;
    if (f->shading && f->env.on) reduce_environment(s, f); /* Phong reads its mean too */
    if (!uses_illumination(f)) return VXL_OK; /* kept: a Phong frame between two shadowed ones costs nothing */
    const uint32_t blocks = (uint32_t)f->light_count + 1, budget_blocks = blocks + (f->env.on ? ENV_BLOCKS : 0);
    uint32_t size = 0, cells[3] = {0, 0, 0};
    int rc = choose_grid(s, f, budget_blocks, &size, cells);
    if (rc) return rc;
    uint64_t key = vxl_classification_key(f);
    key = vxl_fnv(key, &s->storage->pool_generation, sizeof s->storage->pool_generation);
    if (f->gopacity) { /* the opacity follows the gradient too */
        const float g[4] = {(float)f->gopacity, f->gopacity == VXL_GOPACITY_ISO ? f->iso_pos : f->gradient_ref,
                            f->gopacity == VXL_GOPACITY_ISO ? f->iso_thickness : f->gradient_exp, f->sample_distance};
        key = vxl_fnv(key, g, sizeof g);
    }
    if (cuts_convex(f)) { /* what is cut away casts no shadow */
        key = vxl_fnv(key, f->cut.plane, sizeof f->cut.plane);
        key = vxl_fnv(key, f->cut.thickness, sizeof f->cut.thickness);
        key = vxl_fnv(key, &f->cut.plane_count, sizeof f->cut.plane_count);
        if (f->cut.has_crop) key = vxl_fnv(key, f->cut.crop, sizeof f->cut.crop);
    }
    if (masks_labels(s, f)) { /* nor do hidden labels */
        key = vxl_fnv(key, &f->labels.key, sizeof f->labels.key);
        key = vxl_fnv(key, &f->labels.mode, sizeof f->labels.mode);
    }
    const int keep = keeps_extinction(s, key, cells, budget_blocks);
    if ((rc = allocate(s, keep ? s->extinction_cells : cells, cells, blocks, f->env.on))) return rc;
    s->size = size;
    if (s->extinction_key != key) {
        s->extinction_key = 0;
        if ((rc = build_extinction(s, f))) return rc;
        s->extinction_key = key;
    }
    /* the lights and the occlusion follow the extinction and their own grid */
    key = vxl_fnv(key, s->extinction_cells, sizeof s->extinction_cells);
    key = vxl_fnv(key, s->cells, sizeof s->cells);
    /* the occluders' maps first; a light's volume follows its map */
    if ((rc = vxl_shadow_maps_prepare(&s->shadows, f, s->storage->geom.dims))) return rc;
    for (int i = 0; i < f->light_count; i++) {
        float lv[4], radius;
        light_voxel(f, i, lv, &radius);
        uint64_t k = vxl_fnv(key, lv, sizeof lv);
        k = vxl_fnv(k, &f->light_size[i], sizeof f->light_size[i]);
        k = vxl_fnv(k, &i, sizeof i);
        if (s->shadows.active) k = vxl_fnv(k, &s->shadows.light[i].key, sizeof s->shadows.light[i].key);
        if (s->light_key[i] == k) continue;
        s->light_key[i] = 0;
        if ((rc = build_light(s, i, lv, radius, f->light_size[i]))) return rc;
        if (s->shadows.active && (rc = apply_scene_shadows(s, f, i))) return rc;
        s->light_key[i] = k;
        s->rebuilt++;
        s->builds++;
    }
    if (f->ao_radius > 0) {
        uint64_t k = vxl_fnv(key, &f->ao_radius, sizeof f->ao_radius);
        if (s->occlusion_key != k) {
            s->occlusion_key = 0;
            if ((rc = build_occlusion(s, f, f->light_count))) return rc;
            s->occlusion_key = k;
            s->rebuilt++;
            s->builds++;
        }
    }
    if (f->env.on) {
        float dirs[VXL_ENV_CELLS][3];
        environment_voxel_dirs(f, dirs);
        uint64_t k = vxl_fnv(key, &f->env.key, sizeof f->env.key);
        k = vxl_fnv(k, dirs, sizeof dirs);
        if (s->env_key != k) {
            s->env_key = 0;
            if ((rc = build_environment(s, dirs))) return rc;
            s->env_key = k;
            s->rebuilt++;
            s->builds++;
        }
        s->gpu->gl.ActiveTexture(GL_TEXTURE0 + VXL_ENVIRONMENT_UNIT);
        s->gpu->gl.BindTexture(GL_TEXTURE_3D, s->env_tex);
    }
    s->gpu->gl.ActiveTexture(GL_TEXTURE0 + VXL_ILLUMINATION_UNIT);
    s->gpu->gl.BindTexture(GL_TEXTURE_3D, s->tex);
    s->gpu->gl.UseProgram(0);
    s->in_use = 1;
    return vxl_gl_check(s->gpu, "preparing the illumination volumes");
}

void vxl_illumination_bind(vxl_illumination_state *s, GLuint prog, const vxl_frame *f)
{
    vxl_gl *gl = &s->gpu->gl;
#define LOC(name) gl->GetUniformLocation(prog, name)
    if (f->shading && f->env.on) { /* Phong's term; the others' volume */
        gl->Uniform3fv(LOC("u_env_mean"), 1, s->env_mean);
        gl->Uniform1i(LOC("u_environment"), VXL_ENVIRONMENT_UNIT);
    }
    if (!s->in_use) return;
    float lv[VXL_MAX_LIGHTS][4] = {{0}}, cells[3], bias = 0;
    for (int i = 0; i < f->light_count; i++) {
        float radius;
        light_voxel(f, i, lv[i], &radius);
    }
    for (int a = 0; a < 3; a++) {
        cells[a] = (float)s->cells[a];
        float cell = (float)s->storage->geom.dims[a] / cells[a];
        bias = cell > bias ? cell : bias;
    }
    /* Half a cell towards the light: a surface half fills its cell, so the
     * trilinear read at the sample would darken the lit side of every opaque
     * surface; half a cell was closest to the reference on soft and opaque
     * blobs alike (none: soft best, opaque 15% dark; a whole cell: 10% bright). */
    bias *= 0.5f;
    gl->Uniform1i(LOC("u_illumination"), VXL_ILLUMINATION_UNIT);
    gl->Uniform3fv(LOC("u_illum_cells"), 1, cells);
    gl->Uniform1f(LOC("u_illum_blocks"), (float)s->blocks);
    gl->Uniform1i(LOC("u_illum_ao_block"), f->ao_radius > 0 ? f->light_count : -1);
    gl->Uniform4fv(LOC("u_light_voxel"), VXL_MAX_LIGHTS, &lv[0][0]);
    gl->Uniform1f(LOC("u_illum_bias"), bias);
    if (f->env.on && s->env_tex) { /* half the environment's own (coarser) cell */
        float env_bias = 0;
        for (int a = 0; a < 3; a++) {
            float cell = (float)s->storage->geom.dims[a] / (float)s->env_cells[a];
            env_bias = cell > env_bias ? cell : env_bias;
        }
        gl->Uniform1f(LOC("u_env_bias"), 0.5f * env_bias);
    }
    gl->Uniform3fv(LOC("u_spot_dir"), VXL_MAX_LIGHTS, &f->light_spot_dir[0][0]);
    float shape[VXL_MAX_LIGHTS][4] = {{0}};
    for (int i = 0; i < VXL_MAX_LIGHTS; i++) {
        shape[i][0] = i < f->light_count ? f->light_spot_cos[i] : -2.0f;
        shape[i][1] = f->light_spot_blend[i];
    }
    gl->Uniform4fv(LOC("u_spot_shape"), VXL_MAX_LIGHTS, &shape[0][0]);
    gl->Uniform1f(LOC("u_ao_strength"), f->ao_strength);
    gl->Uniform1f(LOC("u_anisotropy"), f->anisotropy);
    gl->Uniform1f(LOC("u_scatter_ref"), f->gradient_ref);
#undef LOC
}

void vxl_illumination_report(const vxl_illumination_state *s, vxl_render_stats *st)
{
    st->illumination_size = s->in_use ? s->size : 0;
    st->illumination_rebuilt = s->rebuilt;
}
