/* overlays.c - the overlay volumes on the GL side (overlays.h). */
#include "overlays.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "holdings.h"
#include "mat4.h"
#include "paging.h"

void vxl_overlays_init(vxl_overlays_state *s, vxl_gpu *g)
{
    s->gpu = g;
    vxl_holding_register(g, VXL_HOLD_OVERLAYS, vxl_holding_counter, &s->bytes);
}

static uint64_t slot_bytes(const vxl_overlay_slot *sl) { return sl->volume_bytes + sl->tf_bytes + sl->distance_bytes; }

static void recount(vxl_overlays_state *s)
{
    s->bytes = 0;
    for (int k = 0; k < VXL_MAX_OVERLAYS; k++) s->bytes += slot_bytes(&s->slots[k]);
}

static void delete_tex(vxl_gpu *g, GLuint *t)
{
    if (*t) g->gl.DeleteTextures(1, t);
    *t = 0;
}

static void release_slot(vxl_gpu *g, vxl_overlay_slot *sl)
{
    delete_tex(g, &sl->tex);
    delete_tex(g, &sl->tf_tex);
    delete_tex(g, &sl->distance_tex);
    vxl_bricks_free(&sl->bricks);
    memset(sl, 0, sizeof *sl);
}

void vxl_overlays_release(vxl_overlays_state *s)
{
    for (int k = 0; k < VXL_MAX_OVERLAYS; k++) release_slot(s->gpu, &s->slots[k]);
    recount(s);
}

/* v's texels as one texture of their own format, filtered linearly (the
 * cubic reads 8 trilinear fetches; nearest reads texels). */
static int upload_volume(vxl_gpu *g, const vxl_volume *v, GLuint *out)
{
    const uint32_t bpv = v->texture_bits / 8;
    vxl_gl *gl = &g->gl;
    gl->GetError();
    GLuint tex = vxl_texture_new(g, GL_TEXTURE_3D, GL_LINEAR);
    /* rows are tightly packed: alignment 1, as the renderer keeps it (renderer.c), set
     * again here because not every upload elsewhere leaves it so */
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl->TexImage3D(GL_TEXTURE_3D, 0, (GLint)vxl_texel_internal_format(bpv), (GLsizei)v->dims[0], (GLsizei)v->dims[1],
                   (GLsizei)v->dims[2], 0, GL_RED, vxl_texel_type(bpv), v->texels);
    int rc = vxl_gl_check(g, "uploading an overlay volume");
    if (rc) {
        gl->DeleteTextures(1, &tex);
        return rc;
    }
    *out = tex;
    return VXL_OK;
}

int vxl_overlays_set(vxl_overlays_state *s, uint32_t slot, const vxl_volume *v)
{
    vxl_gpu *g = s->gpu;
    vxl_overlay_slot *sl = &s->slots[slot];
    if (!v) {
        release_slot(g, sl);
        recount(s);
        return VXL_OK;
    }
    if (v->source || !v->texels)
        return vxl_fail(&g->err, VXL_ERR_INVALID_ARGUMENT,
                        "overlay slot %u: a streamed volume cannot be an overlay (overlays are stored densely, whole): "
                        "load it with streaming off",
                        slot);
    if (v->texture_bits != 8 && v->texture_bits != 16 && v->texture_bits != 32)
        return vxl_fail(&g->err, VXL_ERR_INVALID_ARGUMENT, "overlay slot %u: texels of %u bits are not supported", slot,
                        v->texture_bits);
    double inv[16];
    if (!vxl_mat4_is_finite(v->affine) || !vxl_mat4_invert(inv, v->affine))
        return vxl_fail(&g->err, VXL_ERR_INVALID_ARGUMENT, "overlay slot %u: the volume's affine is not finite or not invertible",
                        slot);
    const uint64_t bytes = (uint64_t)v->dims[0] * v->dims[1] * v->dims[2] * (v->texture_bits / 8);
    /* the volume in this slot is replaced, the other slots stay beside it */
    const uint64_t others = s->bytes - slot_bytes(sl);
    int rc = vxl_holdings_ask(g, VXL_HOLD_OVERLAYS, others + bytes, " (overlays are stored densely)",
                              "overlay slot %u, a %ux%ux%u volume", slot, v->dims[0], v->dims[1], v->dims[2]);
    if (rc) return rc;
    vxl_bricks grid;
    memset(&grid, 0, sizeof grid);
    if ((rc = vxl_bricks_minmax_cpu(&grid, v, vxl_skip_brick_size(), &g->err))) {
        vxl_bricks_free(&grid);
        return rc;
    }
    GLuint tex = 0;
    if ((rc = upload_volume(g, v, &tex))) {
        vxl_bricks_free(&grid);
        return rc;
    }
    release_slot(g, sl);
    sl->tex = tex;
    sl->bricks = grid;
    sl->geom = vxl_volume_geom_of(v);
    sl->volume_bytes = bytes;
    recount(s);
    s->volume_uploads++;
    return VXL_OK;
}

void vxl_overlays_geoms(const vxl_overlays_state *s, const vxl_volume_geom *geoms[VXL_MAX_OVERLAYS])
{
    for (int k = 0; k < VXL_MAX_OVERLAYS; k++) geoms[k] = s->slots[k].tex ? &s->slots[k].geom : NULL;
}

uint32_t vxl_overlays_flags(const vxl_frame *f) { return f->overlays.count << VXL_FLAG_OVERLAYS_SHIFT; }

/* After a texture upload: on a GL error the texture is deleted and its bytes
 * and key cleared (the next frame uploads again), else they become the
 * new ones; the budget's count follows either way. */
static int settle_upload(vxl_overlays_state *s, GLuint *tex, uint64_t *bytes, uint64_t *key, uint64_t new_bytes,
                         uint64_t new_key, const char *what)
{
    const int rc = vxl_gl_check(s->gpu, what);
    if (rc) delete_tex(s->gpu, tex);
    *bytes = rc ? 0 : new_bytes;
    *key = rc ? 0 : new_key;
    recount(s);
    return rc;
}

/* The overlay's transfer function on its slot, when its key changed. */
static int ensure_tf(vxl_overlays_state *s, vxl_overlay_slot *sl, const vxl_frame_overlay *ov)
{
    if (sl->tf_tex && sl->tf_key == ov->table.key) return VXL_OK;
    vxl_gpu *g = s->gpu;
    const uint64_t bytes = (uint64_t)ov->table.tf_size * 4 * sizeof(float);
    int rc = vxl_holdings_ask(g, VXL_HOLD_OVERLAYS, s->bytes - sl->tf_bytes + bytes, NULL, "an overlay's transfer function");
    if (rc) return rc;
    vxl_gl *gl = &g->gl;
    gl->GetError();
    if (!sl->tf_tex) sl->tf_tex = vxl_texture_new(g, GL_TEXTURE_1D, GL_LINEAR);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    gl->BindTexture(GL_TEXTURE_1D, sl->tf_tex);
    gl->TexImage1D(GL_TEXTURE_1D, 0, GL_RGBA32F, (GLsizei)ov->table.tf_size, 0, GL_RGBA, GL_FLOAT, ov->table.tf);
    if ((rc = settle_upload(s, &sl->tf_tex, &sl->tf_bytes, &sl->tf_key, bytes, ov->table.key,
                            "uploading an overlay's transfer function")))
        return rc;
    s->table_uploads++;
    return VXL_OK;
}

/* The overlay's brick occupancy under its classification, as a distance
 * map, when the key or the interpolation changed. The cubic reads texels up
 * to 2 voxels beyond a brick, one more than the grid's apron: its map is the
 * occupancy dilated by one brick, which in Chebyshev distance is d - 1. */
static int ensure_distance(vxl_overlays_state *s, vxl_overlay_slot *sl, const vxl_frame_overlay *ov)
{
    vxl_gpu *g = s->gpu;
    const vxl_occupancy_rule rule = {.table_key = ov->table.key,
                                     .tf = ov->table.tf,
                                     .tf_size = ov->table.tf_size,
                                     .window_offset = ov->table.window_offset,
                                     .window_scale = ov->table.window_scale,
                                     .opacity_scale = ov->table.opacity_scale,
                                     .filter = VXL_FILTER_CENTRAL,
                                     .sample_distance = 1.0f};
    int changed = vxl_bricks_classify(&sl->bricks, &rule);
    if (changed < 0) return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for an overlay's brick occupancy");
    const int cubic = ov->interpolation == VXL_INTERP_CUBIC;
    const uint64_t key = sl->bricks.tf_key * 2 + (uint64_t)cubic;
    if (sl->distance_tex && !changed && sl->distance_key == key) return VXL_OK;
    const vxl_bricks *b = &sl->bricks;
    const size_t n = (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    int rc = VXL_OK;
    if (!sl->distance_tex &&
        (rc = vxl_holdings_ask(g, VXL_HOLD_OVERLAYS, s->bytes + n, NULL, "an overlay's brick distance map")))
        return rc;
    uint8_t *d = malloc(n ? n : 1);
    if (!d) return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for an overlay's brick distance map");
    for (size_t i = 0; i < n; i++) d[i] = cubic && b->distance[i] > 0 ? (uint8_t)(b->distance[i] - 1) : b->distance[i];
    vxl_gl *gl = &g->gl;
    gl->GetError();
    if (!sl->distance_tex) sl->distance_tex = vxl_texture_new(g, GL_TEXTURE_3D, GL_NEAREST);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, sl->distance_tex);
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1); /* rows of any length: see upload_volume */
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R8UI, (GLsizei)b->dims[0], (GLsizei)b->dims[1], (GLsizei)b->dims[2], 0,
                   GL_RED_INTEGER, GL_UNSIGNED_BYTE, d);
    free(d);
    return settle_upload(s, &sl->distance_tex, &sl->distance_bytes, &sl->distance_key, n, key,
                         "uploading an overlay's brick distance map");
}

static GLint loc_k(vxl_gl *gl, GLuint prog, const char *name, uint32_t k)
{
    char buf[64];
    snprintf(buf, sizeof buf, "%s[%u]", name, k);
    return gl->GetUniformLocation(prog, buf);
}

/* Overlay j of the program is frame overlay ov (the program takes them
 * OVER first, then MAX, then ADD: the order the blends combine in). */
static void bind_one(vxl_overlays_state *s, const vxl_frame *f, const vxl_frame_overlay *ov, uint32_t j, GLuint prog)
{
    vxl_gl *gl = &s->gpu->gl;
    const vxl_overlay_slot *sl = &s->slots[ov->slot];
    gl->ActiveTexture(GL_TEXTURE0 + VXL_OVERLAY_VOLUME_UNIT + j);
    gl->BindTexture(GL_TEXTURE_3D, sl->tex);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_OVERLAY_TF_UNIT + j);
    gl->BindTexture(GL_TEXTURE_1D, sl->tf_tex);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_OVERLAY_DISTANCE_UNIT + j);
    gl->BindTexture(GL_TEXTURE_3D, sl->distance_tex); /* 0 when skipping is off: never read then */
    /* every sampler gets its own unit even when unread: samplers of different
     * types on one unit fail the draw */
    gl->Uniform1i(loc_k(gl, prog, "u_ov_volume", j), (GLint)(VXL_OVERLAY_VOLUME_UNIT + j));
    gl->Uniform1i(loc_k(gl, prog, "u_ov_tf", j), (GLint)(VXL_OVERLAY_TF_UNIT + j));
    gl->Uniform1i(loc_k(gl, prog, "u_ov_distance", j), (GLint)(VXL_OVERLAY_DISTANCE_UNIT + j));
    /* base voxel -> world -> overlay voxel; a gradient in overlay voxels goes
     * back to base voxels by the transpose of the linear part */
    double inv[16], m[16];
    vxl_mat4_invert(inv, ov->model); /* checked invertible by the frame or set */
    vxl_mat4_mul(m, inv, f->model);
    float mf[16], gt[9];
    vxl_mat4_to_float(mf, m);
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++) gt[c * 3 + r] = (float)m[r * 4 + c];
    gl->UniformMatrix4fv(loc_k(gl, prog, "u_ov_from_vox", j), 1, GL_FALSE, mf);
    gl->UniformMatrix3fv(loc_k(gl, prog, "u_ov_grad_to_vox", j), 1, GL_FALSE, gt);
    const float dims[3] = {(float)sl->geom.dims[0], (float)sl->geom.dims[1], (float)sl->geom.dims[2]};
    gl->Uniform3fv(loc_k(gl, prog, "u_ov_dims", j), 1, dims);
    const float cls[4] = {ov->table.window_offset, ov->table.window_scale, (float)ov->table.tf_size, ov->table.opacity_scale};
    gl->Uniform4fv(loc_k(gl, prog, "u_ov_class", j), 1, cls);
    gl->Uniform1i(loc_k(gl, prog, "u_ov_blend", j), (GLint)ov->blend);
    gl->Uniform1i(loc_k(gl, prog, "u_ov_interp", j), (GLint)ov->interpolation);
    gl->Uniform1i(loc_k(gl, prog, "u_ov_shading", j), (GLint)ov->shading);
    gl->Uniform1i(loc_k(gl, prog, "u_ov_brick_size", j), (GLint)sl->bricks.size);
}

int vxl_overlays_prepare(vxl_overlays_state *s, const vxl_frame *f, GLuint prog)
{
    if (!f->overlays.count) return VXL_OK;
    static const uint32_t blend_order[VXL_BLEND_COUNT] = {VXL_BLEND_OVER, VXL_BLEND_MAX, VXL_BLEND_ADD};
    uint32_t j = 0;
    for (int b = 0; b < VXL_BLEND_COUNT; b++)
        for (uint32_t k = 0; k < f->overlays.count; k++) {
            const vxl_frame_overlay *ov = &f->overlays.ov[k];
            if (ov->blend != blend_order[b]) continue;
            vxl_overlay_slot *sl = &s->slots[ov->slot];
            if (!sl->tex)
                return vxl_fail(&s->gpu->err, VXL_ERR_STATE, "overlay slot %u is empty: call vxl_renderer_set_overlay first",
                                ov->slot);
            int rc = ensure_tf(s, sl, ov);
            if (!rc && f->skip) rc = ensure_distance(s, sl, ov);
            if (rc) return rc;
            bind_one(s, f, ov, j++, prog);
        }
    return VXL_OK;
}
