/* channels.c - a multi-channel volume's channels on the GL side (channels.h). */
#include "channels.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "channel_volume.h"
#include "hash.h"
#include "holdings.h"
#include "paging.h"

void vxl_channels_init(vxl_channels_state *s, vxl_gpu *g, vxl_storage_state *storage)
{
    s->gpu = g;
    s->storage = storage;
    vxl_holding_register(g, VXL_HOLD_CHANNELS, vxl_holding_counter, &s->bytes);
}

static void recount(vxl_channels_state *s) { s->bytes = s->volume_bytes + s->tf_bytes + s->distance_bytes; }

static void delete_tex(vxl_gpu *g, GLuint *t)
{
    if (*t) g->gl.DeleteTextures(1, t);
    *t = 0;
}

void vxl_channels_release(vxl_channels_state *s)
{
    for (uint32_t g = 0; g < VXL_CHANNEL_GROUPS_MAX; g++) delete_tex(s->gpu, &s->tex[g]);
    for (uint32_t c = 0; c < VXL_MAX_CHANNELS; c++) {
        delete_tex(s->gpu, &s->tf_tex[c]);
        vxl_bricks_free(&s->bricks[c]);
    }
    delete_tex(s->gpu, &s->distance_tex);
    delete_tex(s->gpu, &s->page_tex);
    vxl_channel_pages_free(&s->pages);
    free(s->kept.channels);
    vxl_gpu *g = s->gpu;
    vxl_storage_state *storage = s->storage;
    const uint64_t uploads = s->uploads;
    memset(s, 0, sizeof *s);
    s->gpu = g;
    s->storage = storage;
    s->uploads = uploads;
}

void vxl_channel_plan_free(vxl_channel_plan *p)
{
    for (uint32_t c = 0; c < VXL_MAX_CHANNELS; c++) vxl_bricks_free(&p->bricks[c]);
    vxl_channel_pages_free(&p->pages);
    p->bytes = 0;
}

/* Channel c of v alone, for its brick min-max grid. */
static int channel_minmax(vxl_gpu *g, const vxl_volume *v, uint32_t c, vxl_bricks *out)
{
    vxl_volume one;
    memset(out, 0, sizeof *out);
    int rc = vxl_channel_alone(v, c, &one, &g->err);
    if (!rc) rc = vxl_bricks_minmax_cpu(out, &one, vxl_skip_brick_size(), &g->err);
    free(one.texels);
    return rc;
}

int vxl_channels_plan(vxl_channels_state *s, const vxl_volume *v, const vxl_storage_plan *sp, vxl_channel_plan *out)
{
    memset(out, 0, sizeof *out);
    if (!v->channels) return VXL_OK;
    vxl_gpu *g = s->gpu;
    const int dense = sp->mode == VXL_STORAGE_DENSE;
    for (int a = 0; dense && a < 3; a++)
        if (v->dims[a] > (uint32_t)g->info.max_3d_texture_size)
            return vxl_fail(&g->err, VXL_ERR_LIMIT,
                            "the channels of a %ux%ux%u volume are 3D textures in dense storage and exceed this "
                            "backend's limit of %d per axis (use bricked storage, or crop it)",
                            v->dims[0], v->dims[1], v->dims[2], g->info.max_3d_texture_size);
    int rc = VXL_OK;
    for (uint32_t c = 0; c < v->channel_count && !rc; c++) rc = channel_minmax(g, v, c, &out->bricks[c]);
    /* paged: the scalar's page bricks (every level has the same brick size) */
    if (!rc && !dense)
        rc = vxl_channel_pages_plan(&out->pages, v, sp->levels[0].brick, sp->mode == VXL_STORAGE_SPARSE, s->storage);
    if (rc) {
        vxl_channel_plan_free(out);
        return rc;
    }
    out->bytes = dense ? vxl_volume_channel_bytes(v) : out->pages.bytes;
    /* a new volume releases everything derived from the old one and the
     * old volume itself: only what it keeps (labels, overlays, the MatCap,
     * cutters, shadow maps) stays, beside the new scalar's sp->bytes */
    uint64_t held[VXL_HOLD_COUNT];
    vxl_holdings(g, held);
    held[VXL_HOLD_STORAGE] = 0;
    held[VXL_HOLD_GRADIENTS] = held[VXL_HOLD_BSPLINE] = held[VXL_HOLD_CLASSIFIED] = 0;
    held[VXL_HOLD_ILLUMINATION] = held[VXL_HOLD_MODE_BRICKS] = held[VXL_HOLD_COLOUR] = 0;
    rc = vxl_budget_ask(g->budget, held, VXL_HOLD_CHANNELS, out->bytes + sp->bytes, &g->err,
                        dense ? " (a multi-channel volume's channels are stored densely, 2 bytes a channel a voxel, "
                                "beside its scalar)"
                              : " (a multi-channel volume's channels are paged beside its scalar: every brick where "
                                "a channel varies, 2 bytes a channel a voxel with the ghost borders)",
                        "the %ux%ux%u volume's %u channels (%s storage)", v->dims[0], v->dims[1], v->dims[2],
                        v->channel_count, vxl_storage_name(sp->mode));
    if (rc) vxl_channel_plan_free(out);
    return rc;
}

/* The pools and page table of cp, replacing what is on the GL side. */
static int upload_pools(vxl_channels_state *s, const vxl_channel_pages *cp, const vxl_volume *v)
{
    for (uint32_t g = 0; g < VXL_CHANNEL_GROUPS_MAX; g++) delete_tex(s->gpu, &s->tex[g]);
    delete_tex(s->gpu, &s->page_tex);
    const uint32_t e = vxl_page_edge(&cp->layout);
    for (int a = 0; a < 3; a++) s->pool_dims[a] = cp->slots[a] * e;
    return vxl_channel_pages_upload(cp, v, s->storage, s->tex, &s->page_tex);
}

/* Sparse: takes the plan's pages and copies the channels, so frames can
 * re-page them after the caller lets go of v. */
static int keep_for_paging(vxl_channels_state *s, vxl_channel_plan *plan, const vxl_volume *v)
{
    const uint64_t bytes = vxl_volume_channel_bytes(v);
    if (!(s->kept.channels = malloc(bytes ? bytes : 1)))
        return vxl_fail(&s->gpu->err, VXL_ERR_NO_MEMORY, "out of memory keeping the channels for sparse storage");
    memcpy(s->kept.channels, v->channels, bytes);
    memcpy(s->kept.dims, v->dims, sizeof s->kept.dims);
    s->kept.channel_count = v->channel_count;
    s->pages = plan->pages; /* taken */
    memset(&plan->pages, 0, sizeof plan->pages);
    return VXL_OK;
}

int vxl_channels_set(vxl_channels_state *s, const vxl_volume *v, vxl_channel_plan *plan)
{
    vxl_channels_release(s);
    if (!v || !v->channels) return VXL_OK;
    vxl_gpu *g = s->gpu;
    vxl_gl *gl = &g->gl;
    s->count = v->channel_count;
    for (uint32_t c = 0; c < v->channel_count; c++) {
        s->geom[c] = vxl_volume_geom_of(v);
        s->geom[c].tex_lo = v->ch_tex_lo[c];
        s->geom[c].tex_hi = v->ch_tex_hi[c];
        s->geom[c].value_min = v->ch_min[c];
        s->geom[c].value_max = v->ch_max[c];
        s->bricks[c] = plan->bricks[c]; /* taken */
        memset(&plan->bricks[c], 0, sizeof plan->bricks[c]);
    }
    s->groups = vxl_channel_groups(v);
    int rc = VXL_OK;
    if (plan->pages.layout.brick) { /* paged: pools behind one page table */
        rc = upload_pools(s, &plan->pages, v);
        if (!rc && s->storage->mode == VXL_STORAGE_SPARSE) rc = keep_for_paging(s, plan, v);
    } else {
        gl->GetError();
        for (uint32_t grp = 0; grp < s->groups && !rc; grp++) {
            const uint32_t w = vxl_channel_group_width(v, grp);
            /* filtered as the scalar is: trilinear between voxel centres */
            s->tex[grp] = vxl_texture_new(g, GL_TEXTURE_3D, GL_LINEAR);
            gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
            gl->TexImage3D(GL_TEXTURE_3D, 0, (GLint)vxl_channel_group_format(w), (GLsizei)v->dims[0],
                           (GLsizei)v->dims[1], (GLsizei)v->dims[2], 0, vxl_channel_group_layout(w), GL_UNSIGNED_SHORT,
                           vxl_channel_group(v, grp));
            rc = vxl_gl_check(g, "uploading a multi-channel volume's channels");
        }
    }
    if (rc) {
        vxl_channels_release(s);
        return rc;
    }
    s->volume_bytes = plan->bytes;
    recount(s);
    s->uploads++;
    return VXL_OK;
}

int vxl_channels_flags(const vxl_channels_state *s, const vxl_frame *f, uint32_t *flags)
{
    *flags = 0;
    if (!f->channels.on) return VXL_OK;
    if (!s->count)
        return vxl_fail(&s->gpu->err, VXL_ERR_STATE,
                        "params.channels lists %u channels, but the volume has none (it is not multi-channel)",
                        f->channels.listed);
    for (uint32_t k = 0; k < f->channels.count; k++)
        if (f->channels.ch[k].channel >= s->count)
            return vxl_fail(&s->gpu->err, VXL_ERR_STATE, "params.channels names channel %u: the volume has channels 0..%u",
                            f->channels.ch[k].channel, s->count - 1);
    *flags = s->groups << VXL_FLAG_CHANNELS_SHIFT;
    return VXL_OK;
}

/* Channel c's table on its texture, when its key changed. */
static int ensure_tf(vxl_channels_state *s, const vxl_frame_channel *ch)
{
    const uint32_t c = ch->channel;
    if (s->tf_tex[c] && s->tf_key[c] == ch->table.key) return VXL_OK;
    vxl_gpu *g = s->gpu;
    const uint64_t bytes = (uint64_t)ch->table.tf_size * 4 * sizeof(float);
    int rc = vxl_holdings_ask(g, VXL_HOLD_CHANNELS, s->bytes - s->tf_entry_bytes[c] + bytes, NULL,
                              "channel %u's transfer function", c);
    if (rc) return rc;
    vxl_gl *gl = &g->gl;
    gl->GetError();
    if (!s->tf_tex[c]) s->tf_tex[c] = vxl_texture_new(g, GL_TEXTURE_1D, GL_LINEAR);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    gl->BindTexture(GL_TEXTURE_1D, s->tf_tex[c]);
    gl->TexImage1D(GL_TEXTURE_1D, 0, GL_RGBA32F, (GLsizei)ch->table.tf_size, 0, GL_RGBA, GL_FLOAT, ch->table.tf);
    rc = vxl_gl_check(g, "uploading a channel's transfer function");
    if (rc) delete_tex(g, &s->tf_tex[c]);
    /* on an error the next frame uploads again */
    s->tf_key[c] = rc ? 0 : ch->table.key;
    s->tf_entry_bytes[c] = rc ? 0 : bytes;
    s->tf_bytes = 0;
    for (uint32_t k = 0; k < VXL_MAX_CHANNELS; k++) s->tf_bytes += s->tf_entry_bytes[k];
    recount(s);
    return rc;
}

/* Classifies each drawn channel's skipping bricks under its table (cached
 * by its key) and gives the key of the drawn set and their classifications. */
static int classify_drawn(vxl_channels_state *s, const vxl_frame *f, uint64_t *drawn_key)
{
    vxl_gpu *g = s->gpu;
    uint64_t key = 0xcbf29ce484222325ull;
    for (uint32_t k = 0; k < f->channels.count; k++) {
        const vxl_frame_channel *ch = &f->channels.ch[k];
        const vxl_occupancy_rule rule = {.table_key = ch->table.key,
                                         .tf = ch->table.tf,
                                         .tf_size = ch->table.tf_size,
                                         .window_offset = ch->table.window_offset,
                                         .window_scale = ch->table.window_scale,
                                         .opacity_scale = ch->table.opacity_scale,
                                         .filter = VXL_FILTER_CENTRAL,
                                         .sample_distance = 1.0f};
        if (vxl_bricks_classify(&s->bricks[ch->channel], &rule) < 0)
            return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for channel %u's brick occupancy", ch->channel);
        const uint64_t part[2] = {ch->channel, s->bricks[ch->channel].tf_key};
        key = vxl_fnv(key, part, sizeof part);
    }
    *drawn_key = key;
    return VXL_OK;
}

/* The drawn channels' union occupancy (after classify_drawn) into d, one
 * byte a skipping brick: 0 occupied by some drawn channel, 255 empty. */
static void drawn_occupancy(const vxl_channels_state *s, const vxl_frame *f, uint8_t *d)
{
    const vxl_bricks *b0 = &s->bricks[0];
    const size_t n = (size_t)b0->dims[0] * b0->dims[1] * b0->dims[2];
    memset(d, 255, n);
    for (uint32_t k = 0; k < f->channels.count; k++) {
        const uint8_t *dc = s->bricks[f->channels.ch[k].channel].distance;
        for (size_t i = 0; i < n; i++)
            if (dc[i] == 0) d[i] = 0;
    }
}

/* The drawn channels' union occupancy as one distance map, when a drawn
 * channel's classification or the drawn set changed. */
static int ensure_distance(vxl_channels_state *s, const vxl_frame *f)
{
    vxl_gpu *g = s->gpu;
    uint64_t key;
    int rc = classify_drawn(s, f, &key);
    if (rc || (s->distance_tex && s->distance_key == key)) return rc;
    const vxl_bricks *b0 = &s->bricks[0];
    const size_t n = (size_t)b0->dims[0] * b0->dims[1] * b0->dims[2];
    if (!s->distance_tex &&
        (rc = vxl_holdings_ask(g, VXL_HOLD_CHANNELS, s->bytes + n, NULL, "the channels' brick distance map")))
        return rc;
    uint8_t *d = malloc(n ? n : 1);
    if (!d) return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the channels' brick distance map");
    drawn_occupancy(s, f, d);
    uint32_t occupied = 0;
    for (size_t i = 0; i < n; i++) occupied += d[i] == 0;
    if (vxl_bricks_chebyshev(d, b0->dims) < 0) {
        free(d);
        return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the channels' brick distance map");
    }
    vxl_gl *gl = &g->gl;
    gl->GetError();
    if (!s->distance_tex) s->distance_tex = vxl_texture_new(g, GL_TEXTURE_3D, GL_NEAREST);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, s->distance_tex);
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R8UI, (GLsizei)b0->dims[0], (GLsizei)b0->dims[1], (GLsizei)b0->dims[2], 0,
                   GL_RED_INTEGER, GL_UNSIGNED_BYTE, d);
    free(d);
    rc = vxl_gl_check(g, "uploading the channels' brick distance map");
    if (rc) {
        delete_tex(g, &s->distance_tex);
        s->distance_key = 0;
        s->distance_bytes = 0;
        recount(s);
        return rc;
    }
    s->distance_key = key;
    s->distance_bytes = n;
    s->occupied = occupied;
    s->bricks_total = (uint32_t)n;
    recount(s);
    return VXL_OK;
}

/* Sparse storage: every varying brick the drawn channels' tables can see,
 * within the gradient taps' reach, gets a slot of its own (the pools are
 * laid out and uploaded anew when one lacks it), as the scalar's sparse
 * pool follows its classification; the budget is asked first. */
static int page_visible(vxl_channels_state *s, const vxl_frame *f)
{
    if (!s->kept.channels) return VXL_OK; /* not sparse */
    vxl_gpu *g = s->gpu;
    uint64_t key;
    int rc = classify_drawn(s, f, &key);
    if (rc) return rc;
    const vxl_bricks *b0 = &s->bricks[0];
    const size_t nb = (size_t)b0->dims[0] * b0->dims[1] * b0->dims[2];
    const uint64_t np = vxl_page_count(&s->pages.layout);
    uint8_t *occ = malloc(nb + np), *need = occ + nb;
    if (!occ) return vxl_fail(&g->err, VXL_ERR_NO_MEMORY, "out of memory for the channels' visible bricks");
    drawn_occupancy(s, f, occ);
    vxl_bricks union_grid = *b0; /* a view: the drawn channels' occupancy on the skipping grid */
    union_grid.distance = occ;
    const uint32_t reach = (uint32_t)ceilf(f->sample_distance) + 1; /* gradient taps and their trilinear footprint */
    vxl_pages_needed(&s->pages.layout, &union_grid, reach, 1, 0, s->pages.varies, need);
    int changed;
    rc = vxl_channel_pages_resident(&s->pages, s->count, need, s->storage, s->stale, &changed);
    free(occ);
    if (rc || !changed) return rc;
    rc = vxl_holdings_ask(g, VXL_HOLD_CHANNELS, s->bytes - s->volume_bytes + s->pages.bytes, NULL,
                          "the %u channels' visible bricks", s->count);
    if (!rc) rc = upload_pools(s, &s->pages, &s->kept);
    s->stale = rc != VXL_OK; /* the pools no longer match the pages: the next frame lays them out again */
    if (rc) {
        for (uint32_t grp = 0; grp < VXL_CHANNEL_GROUPS_MAX; grp++) delete_tex(g, &s->tex[grp]);
        delete_tex(g, &s->page_tex);
    }
    s->volume_bytes = rc ? 0 : s->pages.bytes;
    recount(s);
    return rc;
}

static GLint loc_k(vxl_gl *gl, GLuint prog, const char *name, uint32_t k)
{
    char buf[64];
    snprintf(buf, sizeof buf, "%s[%u]", name, k);
    return gl->GetUniformLocation(prog, buf);
}

int vxl_channels_prepare(vxl_channels_state *s, const vxl_frame *f, GLuint prog)
{
    if (!f->channels.on) return VXL_OK;
    int rc;
    for (uint32_t k = 0; k < f->channels.count; k++)
        if ((rc = ensure_tf(s, &f->channels.ch[k]))) return rc;
    if ((rc = page_visible(s, f))) return rc;
    if (f->skip && (rc = ensure_distance(s, f))) return rc;
    vxl_gl *gl = &s->gpu->gl;
    for (uint32_t grp = 0; grp < s->groups; grp++) {
        gl->ActiveTexture(GL_TEXTURE0 + VXL_CHANNEL_DATA_UNIT + grp);
        gl->BindTexture(GL_TEXTURE_3D, s->tex[grp]);
    }
    vxl_uniform_i(s->gpu, prog, "u_ch_data0", VXL_CHANNEL_DATA_UNIT);
    vxl_uniform_i(s->gpu, prog, "u_ch_data1", VXL_CHANNEL_DATA_UNIT + 1);
    if (s->page_tex) { /* paged: the pools' page table, read as the scalar's is */
        gl->ActiveTexture(GL_TEXTURE0 + VXL_CHANNEL_PAGE_UNIT);
        gl->BindTexture(GL_TEXTURE_3D, s->page_tex);
        vxl_uniform_i(s->gpu, prog, "u_ch_page", VXL_CHANNEL_PAGE_UNIT);
        const float pd[3] = {(float)s->pool_dims[0], (float)s->pool_dims[1], (float)s->pool_dims[2]};
        const GLint loc = gl->GetUniformLocation(prog, "u_ch_pool_dims");
        if (loc >= 0) gl->Uniform3fv(loc, 1, pd);
    }
    gl->ActiveTexture(GL_TEXTURE0 + VXL_CHANNEL_DISTANCE_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, s->distance_tex); /* 0 when skipping is off: never read then */
    vxl_uniform_i(s->gpu, prog, "u_ch_distance", VXL_CHANNEL_DISTANCE_UNIT);
    vxl_uniform_i(s->gpu, prog, "u_ch_brick_size", (int)(s->bricks[0].size ? s->bricks[0].size : VXL_DEFAULT_BRICK));
    vxl_uniform_i(s->gpu, prog, "u_ch_blend", (int)f->channels.blend);
    int drawn = 0;
    const uint32_t slots = s->groups * VXL_CHANNELS_PER_GROUP;
    /* every sampler gets its own unit even when unread: samplers of
     * different types on one unit fail the draw */
    for (uint32_t c = 0; c < slots; c++) gl->Uniform1i(loc_k(gl, prog, "u_ch_tf", c), (GLint)(VXL_CHANNEL_TF_UNIT + c));
    for (uint32_t k = 0; k < f->channels.count; k++) {
        const vxl_frame_channel *ch = &f->channels.ch[k];
        const uint32_t c = ch->channel;
        drawn |= 1 << c;
        gl->ActiveTexture(GL_TEXTURE0 + VXL_CHANNEL_TF_UNIT + c);
        gl->BindTexture(GL_TEXTURE_1D, s->tf_tex[c]);
        const float cls[4] = {ch->table.window_offset, ch->table.window_scale, (float)ch->table.tf_size, ch->table.opacity_scale};
        gl->Uniform4fv(loc_k(gl, prog, "u_ch_class", c), 1, cls);
        gl->Uniform3fv(loc_k(gl, prog, "u_ch_color", c), 1, ch->color);
    }
    vxl_uniform_i(s->gpu, prog, "u_ch_drawn", drawn);
    return VXL_OK;
}
