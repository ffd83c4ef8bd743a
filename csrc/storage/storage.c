/* storage.c - which storage table serves a volume. A new mode is a new
 * table (storage.h) and one line here. */
#include "budget.h"
#include "holdings.h"
#include "storage.h"

static const vxl_storage_ops *const tables[VXL_STORAGE_COUNT] = {
    [VXL_STORAGE_AUTO] = &vxl_storage_bricked, /* reached only when dense does not fit; the plan picks bricked or sparse */
    [VXL_STORAGE_DENSE] = &vxl_storage_dense,
    [VXL_STORAGE_BRICKED] = &vxl_storage_bricked,
    [VXL_STORAGE_SPARSE] = &vxl_storage_sparse,
    [VXL_STORAGE_COMPRESSED] = &vxl_storage_compressed,
};

const vxl_storage_ops *vxl_storage_ops_for(uint32_t mode) { return mode < VXL_STORAGE_COUNT ? tables[mode] : NULL; }

const vxl_storage_ops *vxl_storage_ops_for_volume(const vxl_volume *v, uint32_t mode)
{
    return v->source ? &vxl_storage_streamed : vxl_storage_ops_for(mode); /* no texels to upload */
}

uint32_t vxl_storage_choose(const vxl_storage_state *st, const vxl_volume *v)
{
    if (st->request != VXL_STORAGE_AUTO || v->source) return st->request; /* streamed: the streamed plan decides */
    for (int a = 0; a < 3; a++)
        if (v->dims[a] > (uint32_t)st->gpu->info.max_3d_texture_size) return VXL_STORAGE_AUTO;
    return vxl_budget_fits(st->gpu->budget, NULL, VXL_HOLD_STORAGE, v->storage_bytes) ? VXL_STORAGE_DENSE : VXL_STORAGE_AUTO;
}

void vxl_storage_plan_free(vxl_storage_plan *plan)
{
    for (int k = 0; k < VXL_LOD_LEVELS; k++) vxl_pages_free(&plan->levels[k]);
    vxl_bricks_free(&plan->bricks);
}

static uint64_t held_bytes(const void *state)
{
    const vxl_storage_state *st = state;
    return st->ops ? st->ops->resident_bytes(st) : 0;
}

void vxl_storage_init(vxl_storage_state *st, vxl_gpu *g)
{
    st->gpu = g;
    vxl_holding_register(g, VXL_HOLD_STORAGE, held_bytes, st);
}

int vxl_storage_bind_sampling(vxl_storage_state *st, GLuint prog)
{
    vxl_gl *gl = &st->gpu->gl;
    gl->UseProgram(prog);
    st->ops->bind(st, prog); /* the values on the volume unit, and what translates a sample */
    vxl_uniform_i(st->gpu, prog, "u_volume", VXL_VOLUME_UNIT);
    GLint loc = gl->GetUniformLocation(prog, "u_dims");
    float dims[3] = {(float)st->geom.dims[0], (float)st->geom.dims[1], (float)st->geom.dims[2]};
    if (loc >= 0) gl->Uniform3fv(loc, 1, dims);
    return VXL_OK;
}
