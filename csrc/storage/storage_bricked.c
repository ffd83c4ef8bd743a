/* storage_bricked.c - the tables of bricked and sparse storage, and what
 * every mode with a pool and a page table (compressed too) does the same
 * way: bind the pool and its page tables for sampling, report the pool. The
 * pool itself is made in paged.c. */
#include "renderer_internal.h"

uint32_t vxl_paged_sample_flags(const vxl_renderer *r)
{
    (void)r;
    return VXL_FLAG_PAGED;
}

/* The pool stands in for the volume on the volume unit; the page tables
 * (data, and the derived pools that exist) translate every tap. */
void vxl_paged_bind(vxl_renderer *r, GLuint prog)
{
    vxl_gl *gl = &r->gl;
    if (r->gradients.page_tex) {
        gl->ActiveTexture(GL_TEXTURE0 + VXL_GPAGE_UNIT);
        gl->BindTexture(GL_TEXTURE_3D, r->gradients.page_tex);
    }
    if (r->bspline.page_tex) {
        gl->ActiveTexture(GL_TEXTURE0 + VXL_CPAGE_UNIT);
        gl->BindTexture(GL_TEXTURE_3D, r->bspline.page_tex);
    }
    gl->ActiveTexture(GL_TEXTURE0 + VXL_PAGE_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, r->storage.page_tex);
    vxl_uniform_i(r, prog, "u_page", VXL_PAGE_UNIT);
    vxl_uniform_f(r, prog, "u_page_brick", (float)r->storage.levels[r->storage.level].brick);
    vxl_uniform_f(r, prog, "u_lod_scale", (float)(1u << r->storage.level));
    const uint32_t *ld = r->storage.level_dims[r->storage.level];
    float pd[3] = {(float)r->storage.pool_dims[0], (float)r->storage.pool_dims[1], (float)r->storage.pool_dims[2]};
    float lv[3] = {(float)ld[0], (float)ld[1], (float)ld[2]};
    GLint ploc = gl->GetUniformLocation(prog, "u_pool_dims"), lloc = gl->GetUniformLocation(prog, "u_page_dims");
    if (ploc >= 0) gl->Uniform3fv(ploc, 1, pd);
    if (lloc >= 0) gl->Uniform3fv(lloc, 1, lv);
    vxl_uniform_i(r, prog, "u_gpage", VXL_GPAGE_UNIT);
    float gd[3] = {(float)r->gradients.pool_dims[0], (float)r->gradients.pool_dims[1], (float)r->gradients.pool_dims[2]};
    GLint gloc = gl->GetUniformLocation(prog, "u_gpool_dims");
    if (gloc >= 0) gl->Uniform3fv(gloc, 1, gd);
    vxl_uniform_i(r, prog, "u_cpage", VXL_CPAGE_UNIT);
    float cd[3] = {(float)r->bspline.pool_dims[0], (float)r->bspline.pool_dims[1], (float)r->bspline.pool_dims[2]};
    GLint cloc = gl->GetUniformLocation(prog, "u_cpool_dims");
    if (cloc >= 0) gl->Uniform3fv(cloc, 1, cd);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, r->storage.pool_tex);
}

GLuint vxl_paged_texels(const vxl_renderer *r, const uint32_t **dims)
{
    *dims = r->storage.pool_dims;
    return r->storage.pool_tex;
}

uint64_t vxl_paged_resident_bytes(const vxl_renderer *r) { return r->storage.pool_bytes; }

void vxl_paged_report(const vxl_renderer *r, vxl_render_stats *s)
{
    s->page_brick = r->storage.levels[r->storage.level].brick;
    s->pages_total = (uint32_t)vxl_page_count(&r->storage.levels[r->storage.level]);
    s->lod_level = r->storage.level;
    s->lod_wanted_bytes = r->storage.lod_wanted_bytes;
    s->decode_ms = r->storage.decode_ms;
    s->pages_resident = r->storage.pages_resident;
    s->pages_constant = r->storage.pages_constant;
}

static int install_bricked(vxl_renderer *r, const vxl_volume *v, vxl_storage_plan *plan)
{
    int rc = vxl_paged_adopt(r, v, plan);
    return rc ? rc : vxl_paged_upload_all(r);
}

static int prepare_bricked(vxl_renderer *r, const vxl_frame *f)
{
    vxl_paged_see(r, f, 1); /* every brick is in the pool: derived pools cover them all */
    return VXL_OK;
}

static int prepare_sparse(vxl_renderer *r, const vxl_frame *f)
{
    vxl_paged_see(r, f, 0);
    return vxl_paged_make_resident(r, f);
}

/* Every non-constant brick in the pool from set_volume on. */
const vxl_storage_ops vxl_storage_bricked =
    VXL_PAGED_OPS(install_bricked, prepare_bricked, vxl_storage_serves_all, vxl_paged_sample_flags, vxl_paged_bind);

/* Only the bricks the classification can see, at the finest level that
 * fits the budget; the pool follows the first frame's classification. */
const vxl_storage_ops vxl_storage_sparse =
    VXL_PAGED_OPS(vxl_paged_adopt, prepare_sparse, vxl_storage_serves_all, vxl_paged_sample_flags, vxl_paged_bind);
