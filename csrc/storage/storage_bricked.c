/* storage_bricked.c - the tables of bricked and sparse storage, and what
 * every mode with a pool and a page table (compressed too) does the same
 * way: bind the pool and its page tables for sampling, report the pool. The
 * pool itself is made in paged.c. */

#include "storage.h"

uint32_t vxl_paged_sample_flags(const vxl_storage_state *st)
{
    (void)st;
    return VXL_FLAG_PAGED;
}

/* The pool stands in for the volume on the volume unit; the page tables
 * (data, and the derived pools that exist) translate every tap. */
void vxl_paged_bind(vxl_storage_state *st, GLuint prog)
{
    vxl_gl *gl = &st->gpu->gl;
    for (int k = 0; k < VXL_DERIVED_COUNT; k++) {
        const vxl_derived *d = &st->derived[k];
        if (d->page_tex && *d->page_tex) {
            gl->ActiveTexture(GL_TEXTURE0 + (GLenum)d->page_unit);
            gl->BindTexture(GL_TEXTURE_3D, *d->page_tex);
        }
    }
    gl->ActiveTexture(GL_TEXTURE0 + VXL_PAGE_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, st->page_tex);
    vxl_uniform_i(st->gpu, prog, "u_page", VXL_PAGE_UNIT);
    vxl_uniform_f(st->gpu, prog, "u_page_brick", (float)st->levels[st->level].brick);
    vxl_uniform_f(st->gpu, prog, "u_lod_scale", (float)(1u << st->level));
    const uint32_t *ld = st->level_dims[st->level];
    float pd[3] = {(float)st->pool_dims[0], (float)st->pool_dims[1], (float)st->pool_dims[2]};
    float lv[3] = {(float)ld[0], (float)ld[1], (float)ld[2]};
    GLint ploc = gl->GetUniformLocation(prog, "u_pool_dims"), lloc = gl->GetUniformLocation(prog, "u_page_dims");
    if (ploc >= 0) gl->Uniform3fv(ploc, 1, pd);
    if (lloc >= 0) gl->Uniform3fv(lloc, 1, lv);
    for (int k = 0; k < VXL_DERIVED_COUNT; k++) {
        const vxl_derived *d = &st->derived[k];
        if (!d->pool_dims) continue;
        vxl_uniform_i(st->gpu, prog, d->page_name, d->page_unit);
        float dd[3] = {(float)d->pool_dims[0], (float)d->pool_dims[1], (float)d->pool_dims[2]};
        GLint loc = gl->GetUniformLocation(prog, d->dims_name);
        if (loc >= 0) gl->Uniform3fv(loc, 1, dd);
    }
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, st->pool_tex);
}

GLuint vxl_paged_texels(const vxl_storage_state *st, const uint32_t **dims)
{
    *dims = st->pool_dims;
    return st->pool_tex;
}

uint64_t vxl_paged_resident_bytes(const vxl_storage_state *st) { return st->pool_bytes; }

void vxl_paged_report(const vxl_storage_state *st, vxl_render_stats *s)
{
    s->page_brick = st->levels[st->level].brick;
    s->pages_total = (uint32_t)vxl_page_count(&st->levels[st->level]);
    s->lod_level = st->level;
    s->lod_wanted_bytes = st->lod_wanted_bytes;
    s->decode_ms = st->decode_ms;
    s->pages_resident = st->pages_resident;
    s->pages_constant = st->pages_constant;
}

static int install_bricked(vxl_storage_state *st, const vxl_volume *v, vxl_storage_plan *plan)
{
    int rc = vxl_paged_adopt(st, v, plan);
    return rc ? rc : vxl_paged_upload_all(st);
}

static int prepare_bricked(vxl_storage_state *st, const vxl_frame *f)
{
    vxl_paged_see(st, f, 1); /* every brick is in the pool: derived pools cover them all */
    return VXL_OK;
}

static int prepare_sparse(vxl_storage_state *st, const vxl_frame *f)
{
    vxl_paged_see(st, f, 0);
    return vxl_paged_make_resident(st, f);
}

/* Every non-constant brick in the pool from set_volume on. */
const vxl_storage_ops vxl_storage_bricked =
    VXL_PAGED_OPS(install_bricked, prepare_bricked, vxl_storage_serves_all, vxl_paged_sample_flags, vxl_paged_bind);

/* Only the bricks the classification can see, at the finest level that
 * fits the budget; the pool follows the first frame's classification. */
const vxl_storage_ops vxl_storage_sparse =
    VXL_PAGED_OPS(vxl_paged_adopt, prepare_sparse, vxl_storage_serves_all, vxl_paged_sample_flags, vxl_paged_bind);
