/* labels.c - the label volume and the per-label table on the GL side (labels.h). */
#include "labels.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "holdings.h"
#include "label_margin.h"
#include "mat4.h"
#include "volume.h"

void vxl_labels_init(vxl_labels_state *s, vxl_gpu *g)
{
    s->gpu = g;
    vxl_holding_register(g, VXL_HOLD_LABELS, vxl_holding_counter, &s->bytes);
}

static void delete_tex(vxl_labels_state *s, GLuint *t)
{
    if (*t) s->gpu->gl.DeleteTextures(1, t);
    *t = 0;
}

static void release_volume(vxl_labels_state *s)
{
    delete_tex(s, &s->volume_tex);
    delete_tex(s, &s->bricks_tex);
    delete_tex(s, &s->margin_tex);
    vxl_label_bricks_free(&s->bricks);
    s->volume_bytes = 0;
    s->bytes = s->table_bytes;
}

void vxl_labels_release(vxl_labels_state *s)
{
    release_volume(s);
    delete_tex(s, &s->table_tex);
    s->table_bytes = s->bytes = 0;
    s->table_key = 0;
}

/* v's ids as 16-bit integers, checked: the stored value maps back to the
 * data value exactly (tex_lo + t * span), which must be a whole id. */
static int convert_ids(const vxl_volume *v, uint16_t *ids, uint64_t n, vxl_err *e)
{
    const double span = v->tex_hi - v->tex_lo;
    for (uint64_t i = 0; i < n; i++) {
        double val = v->tex_lo + vxl_volume_texel(v, (size_t)i) * span;
        double id = floor(val + 0.5);
        if (!(id >= 0 && id <= VXL_MAX_LABEL_ID) || fabs(val - id) > 0.01) {
            uint64_t x = i % v->dims[0], y = (i / v->dims[0]) % v->dims[1], z = i / ((uint64_t)v->dims[0] * v->dims[1]);
            return vxl_fail(e, VXL_ERR_INVALID_ARGUMENT,
                            "label volume value %g at voxel (%llu, %llu, %llu) is not a label id in [0, %d]", val,
                            (unsigned long long)x, (unsigned long long)y, (unsigned long long)z, VXL_MAX_LABEL_ID);
        }
        ids[i] = (uint16_t)id;
    }
    return VXL_OK;
}

int vxl_labels_set(vxl_labels_state *s, const vxl_volume *v)
{
    vxl_gpu *g = s->gpu;
    if (!v) {
        release_volume(s);
        return VXL_OK;
    }
    const uint32_t t = v->src_dtype;
    if (t != VXL_DTYPE_U8 && t != VXL_DTYPE_U16 && t != VXL_DTYPE_I16 && t != VXL_DTYPE_I32)
        return vxl_fail(&g->err, VXL_ERR_INVALID_ARGUMENT,
                        "a label volume must hold integers (u8, u16, i16 or i32), not dtype %u", t);
    if (!vxl_mat4_is_finite(v->affine))
        return vxl_fail(&g->err, VXL_ERR_INVALID_ARGUMENT, "the label volume's affine is not finite");
    double inv[16];
    if (!vxl_mat4_invert(inv, v->affine))
        return vxl_fail(&g->err, VXL_ERR_INVALID_ARGUMENT, "the label volume's affine is not invertible");
    const uint64_t n = (uint64_t)v->dims[0] * v->dims[1] * v->dims[2];
    uint64_t bricks = 1; /* the brick texture: one word per brick */
    for (int a = 0; a < 3; a++) bricks *= (v->dims[a] + VXL_LABEL_BRICK - 1) / VXL_LABEL_BRICK;
    /* the ids, the margins (one byte a voxel: smooth boundaries) and the brick words */
    const uint64_t bytes = n * sizeof(uint16_t) + n + bricks * sizeof(uint32_t);
    /* the volume it replaces is not charged against it, the table is */
    uint64_t kept = s->volume_bytes;
    s->bytes -= kept;
    int rc = vxl_holdings_ask(g, VXL_HOLD_LABELS, bytes + s->table_bytes, " (labels are stored densely, 3 bytes a voxel)",
                              "the %ux%ux%u label volume", v->dims[0], v->dims[1], v->dims[2]);
    s->bytes += kept;
    if (rc) return rc;
    uint16_t *ids = malloc(n ? n * sizeof(uint16_t) : 1);
    uint8_t *margin = malloc(n ? n : 1);
    if (!ids || !margin) {
        free(ids);
        free(margin);
        return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the label volume");
    }
    rc = convert_ids(v, ids, n, &g->err);
    vxl_label_bricks grid;
    memset(&grid, 0, sizeof grid);
    if (!rc && vxl_label_bricks_build(&grid, ids, v->dims))
        rc = vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the label volume's brick grid");
    if (!rc && vxl_label_margin_build(margin, ids, v->dims))
        rc = vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the label volume's margins");
    if (rc) {
        vxl_label_bricks_free(&grid);
        free(ids);
        free(margin);
        return rc;
    }
    vxl_gl *gl = &g->gl;
    gl->GetError();
    GLuint tex = vxl_texture_new(g, GL_TEXTURE_3D, GL_NEAREST); /* ids are never filtered */
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R16UI, (GLsizei)v->dims[0], (GLsizei)v->dims[1], (GLsizei)v->dims[2], 0,
                   GL_RED_INTEGER, GL_UNSIGNED_SHORT, ids);
    free(ids);
    /* the margins are read with texelFetch too: each corner's sign depends on the label asked about */
    GLuint mtex = vxl_texture_new(g, GL_TEXTURE_3D, GL_NEAREST);
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R8, (GLsizei)v->dims[0], (GLsizei)v->dims[1], (GLsizei)v->dims[2], 0, GL_RED,
                   GL_UNSIGNED_BYTE, margin);
    free(margin);
    rc = vxl_gl_check(g, "uploading the label volume");
    if (rc) {
        gl->DeleteTextures(1, &tex);
        gl->DeleteTextures(1, &mtex);
        vxl_label_bricks_free(&grid);
        return rc;
    }
    release_volume(s);
    s->volume_tex = tex;
    s->margin_tex = mtex;
    s->bricks = grid;
    s->bricks_stale = 1;
    memcpy(s->dims, v->dims, sizeof s->dims);
    memcpy(s->affine, v->affine, sizeof s->affine);
    s->volume_bytes = bytes;
    s->bytes = s->volume_bytes + s->table_bytes;
    s->volume_uploads++;
    return VXL_OK;
}

uint32_t vxl_labels_flags(const vxl_frame *f)
{
    if (!f->labels.on) return 0u;
    return (f->labels.mode + 1u) << VXL_FLAG_LABELS_SHIFT | (f->labels.voxels ? VXL_FLAG_LABEL_VOXELS : 0u);
}

/* Entry i of f's labels (the caller's stride). */
static const vxl_label_entry *frame_entry(const vxl_frame *f, uint32_t i)
{
    return (const vxl_label_entry *)((const char *)f->labels.entries + (size_t)i * f->labels.stride);
}

/* *tex (made on first use) bound to target on the scratch unit, to be filled. */
static void bind_for_upload(vxl_labels_state *s, GLuint *tex, GLenum target)
{
    vxl_gl *gl = &s->gpu->gl;
    gl->GetError();
    if (!*tex) {
        *tex = vxl_texture_new(s->gpu, target, GL_NEAREST);
        return;
    }
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    gl->BindTexture(target, *tex);
}

static int upload_table(vxl_labels_state *s, const vxl_frame *f)
{
    vxl_gpu *g = s->gpu;
    /* rows 0 .. SIDE-1: colours; rows SIDE .. 2 SIDE-1: materials (x -1: the frame's) */
    const uint64_t texels = (uint64_t)VXL_LABEL_TABLE_SIDE * VXL_LABEL_TABLE_SIDE;
    const uint64_t bytes = 2 * texels * 4 * sizeof(float);
    if (!s->table_tex) {
        int rc = vxl_holdings_ask(g, VXL_HOLD_LABELS, bytes + s->volume_bytes, NULL, "the label table");
        if (rc) return rc;
    }
    float *table = malloc(bytes);
    if (!table) return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the label table");
    for (uint64_t i = 0; i < texels; i++) {
        table[4 * i] = table[4 * i + 1] = table[4 * i + 2] = 0.0f;
        table[4 * i + 3] = -1.0f; /* unlisted: hidden */
        float *m = table + 4 * (texels + i);
        m[0] = -1.0f; /* the frame's material */
        m[1] = m[2] = m[3] = 0.0f;
    }
    for (uint32_t i = 0; i < f->labels.count; i++) {
        const vxl_label_entry *en = frame_entry(f, i);
        float *t = table + 4 * (size_t)en->id;
        memcpy(t, en->color, 4 * sizeof(float));
        if (!en->visible) t[3] = -1.0f;
        const float *m = vxl_label_material(en, f->labels.stride);
        if (m) memcpy(table + 4 * (texels + (size_t)en->id), m, 4 * sizeof(float));
    }
    bind_for_upload(s, &s->table_tex, GL_TEXTURE_2D);
    g->gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, VXL_LABEL_TABLE_SIDE, 2 * VXL_LABEL_TABLE_SIDE, 0, GL_RGBA, GL_FLOAT,
                     table);
    free(table);
    int rc = vxl_gl_check(g, "uploading the label table");
    if (rc) {
        delete_tex(s, &s->table_tex);
        s->table_bytes = 0;
        s->bytes = s->volume_bytes;
        return rc;
    }
    s->table_bytes = bytes;
    s->bytes = s->volume_bytes + s->table_bytes;
    s->table_key = f->labels.key;
    s->table_uploads++;
    return VXL_OK;
}

/* The label bricks under f's table (label_bricks.h), uploaded to bricks_tex. */
static int derive_bricks(vxl_labels_state *s, const vxl_frame *f)
{
    vxl_gpu *g = s->gpu;
    uint8_t *visible = calloc((VXL_MAX_LABEL_ID + 1) / 8, 1);
    if (!visible) return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the label bricks");
    for (uint32_t i = 0; i < f->labels.count; i++) {
        const vxl_label_entry *en = frame_entry(f, i);
        if (en->visible) visible[en->id >> 3] |= (uint8_t)(1u << (en->id & 7));
    }
    int failed = vxl_label_bricks_classify(&s->bricks, visible);
    free(visible);
    if (failed) return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the label bricks");
    bind_for_upload(s, &s->bricks_tex, GL_TEXTURE_3D);
    const uint32_t *d = s->bricks.dims;
    g->gl.TexImage3D(GL_TEXTURE_3D, 0, GL_R32UI, (GLsizei)d[0], (GLsizei)d[1], (GLsizei)d[2], 0, GL_RED_INTEGER,
                   GL_UNSIGNED_INT, s->bricks.words);
    int rc = vxl_gl_check(g, "uploading the label bricks");
    if (rc) {
        delete_tex(s, &s->bricks_tex);
        return rc;
    }
    s->bricks_key = f->labels.key;
    s->bricks_stale = 0;
    return VXL_OK;
}

int vxl_labels_prepare(vxl_labels_state *s, const vxl_frame *f, GLuint prog, const double vox_to_world[16])
{
    if (!f->labels.on) return VXL_OK;
    vxl_gpu *g = s->gpu;
    if (!s->volume_tex)
        return vxl_fail(&g->err, VXL_ERR_STATE, "params.labels is set but no label volume: call vxl_renderer_set_labels first");
    if (!s->table_tex || s->table_key != f->labels.key) {
        int rc = upload_table(s, f);
        if (rc) return rc;
    }
    if (!s->bricks_tex || s->bricks_stale || s->bricks_key != f->labels.key) {
        int rc = derive_bricks(s, f);
        if (rc) return rc;
    }
    /* intensity voxel -> world -> label voxel; a gradient in label voxels
     * goes back to intensity voxels by the transpose of the linear part */
    double inv[16], m[16];
    vxl_mat4_invert(inv, s->affine); /* checked invertible in vxl_labels_set */
    vxl_mat4_mul(m, inv, vox_to_world);
    float mf[16], gt[9];
    vxl_mat4_to_float(mf, m);
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++) gt[c * 3 + r] = (float)m[r * 4 + c];
    vxl_gl *gl = &g->gl;
    gl->ActiveTexture(GL_TEXTURE0 + VXL_LABELS_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, s->volume_tex);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_LABEL_TABLE_UNIT);
    gl->BindTexture(GL_TEXTURE_2D, s->table_tex);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_LABEL_BRICKS_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, s->bricks_tex);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_LABEL_MARGIN_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, s->margin_tex);
    vxl_uniform_i(g, prog, "u_label_margin", VXL_LABEL_MARGIN_UNIT);
    vxl_uniform_i(g, prog, "u_labels", VXL_LABELS_UNIT);
    vxl_uniform_i(g, prog, "u_label_bricks", VXL_LABEL_BRICKS_UNIT);
    vxl_uniform_i(g, prog, "u_label_table", VXL_LABEL_TABLE_UNIT);
    gl->UniformMatrix4fv(gl->GetUniformLocation(prog, "u_label_from_vox"), 1, GL_FALSE, mf);
    gl->UniformMatrix3fv(gl->GetUniformLocation(prog, "u_label_grad_to_vox"), 1, GL_FALSE, gt);
    return VXL_OK;
}
