/* storage_compressed.c - the table of compressed storage: the bricked
 * modes' pool and page table (paged.c, storage_bricked.c) over the codes and
 * palettes of compressed_pool.c. */

#include "storage.h"

/* The derived filters read every brick's values, which only the GL side
 * keeps (as codes); the compressed domain (a comparison mode) has no cache to
 * derive from. */
static int check_filter(vxl_storage_state *st, uint32_t filter, uint32_t classify)
{
    const int derived = filter == VXL_FILTER_PRECOMPUTED || filter == VXL_FILTER_CUBIC;
    const char *what = st->compressed_domain && (derived || classify == VXL_CLASSIFY_PRE)
                           ? "filtering in the compressed domain (a comparison mode) with the precomputed or cubic filter or pre-classification"
                       : derived
                           ? "the precomputed and cubic filters with compressed storage (their data is derived from every brick's values, which only the GL side keeps, as codes)"
                           : NULL;
    if (!what) return VXL_OK;
    return vxl_fail(&st->gpu->err, VXL_ERR_STATE,
                    "%s is not supported (volume %ux%ux%u); use bricked or sparse storage, or central, forward3, "
                    "sobel8, sobel14 or sobel26",
                    what, st->geom.dims[0], st->geom.dims[1], st->geom.dims[2]);
}

/* In the compressed domain the pool is the code pool: every tap decodes. */
static uint32_t sample_flags(const vxl_storage_state *st)
{
    return st->compressed_domain ? VXL_FLAG_PAGED | VXL_FLAG_COMPRESSED_DOMAIN : VXL_FLAG_PAGED;
}

static void bind(vxl_storage_state *st, GLuint prog)
{
    vxl_gl *gl = &st->gpu->gl;
    if (st->compressed_domain) {
        gl->ActiveTexture(GL_TEXTURE0 + VXL_PALETTE_UNIT);
        gl->BindTexture(GL_TEXTURE_2D, st->palette_tex);
        vxl_uniform_i(st->gpu, prog, "u_palette", VXL_PALETTE_UNIT);
        gl->Uniform3i(gl->GetUniformLocation(prog, "u_code_slots"), (GLint)st->code_slots[0], (GLint)st->code_slots[1],
                      (GLint)st->code_slots[2]);
    }
    vxl_paged_bind(st, prog);
}

static int install(vxl_storage_state *st, const vxl_volume *v, vxl_storage_plan *plan)
{
    int rc = vxl_paged_adopt(st, v, plan);
    if (!rc) rc = vxl_compressed_upload(st);
    /* deferred filtering: the cache follows the first frame's classification */
    return rc || !st->compressed_domain ? rc : vxl_paged_upload_all(st);
}

static int prepare(vxl_storage_state *st, const vxl_frame *f)
{
    vxl_paged_see(st, f, 0);
    return st->compressed_domain ? VXL_OK : vxl_paged_make_resident(st, f);
}

/* Codes of every data brick on the GL side; the bricks the classification
 * can see decoded into the pool (deferred filtering), or, in the compressed
 * domain, the code pool itself sampled. */
const vxl_storage_ops vxl_storage_compressed = VXL_PAGED_OPS(install, prepare, check_filter, sample_flags, bind);
