/* bspline.c - coefficients of the interpolating cubic B-spline for the
 * `cubic` gradient filter, computed on the GL side once per volume
 * (shaders/compute/bspline_prefilter.comp) and kept until the volume changes. */
#include <stdlib.h>

#include "gradients.h"
#include "holdings.h"

void vxl_bspline_release(vxl_bspline_state *bs)
{
    const GLuint tex[2] = {bs->tex, bs->page_tex}; /* the volume or pool, and a pool's page table */
    bs->gpu->gl.DeleteTextures(2, tex); /* 0 is ignored */
    bs->tex = bs->page_tex = 0;
    bs->bytes = 0;
    free(bs->covered); /* bricked: the coefficient bricks made */
    bs->covered = NULL;
}

static GLuint groups8(uint32_t n) { return (n + 7) / 8; }

int vxl_bspline_ensure(vxl_bspline_state *bs)
{
    if (bs->tex) return VXL_OK;
    vxl_gl *gl = &bs->gpu->gl;
    uint64_t n = (uint64_t)bs->storage->geom.dims[0] * bs->storage->geom.dims[1] * bs->storage->geom.dims[2];
    int rc = vxl_holdings_ask(bs->gpu, VXL_HOLD_BSPLINE, n * 4, NULL, "cubic B-spline coefficients");
    if (rc) return rc;
    GLuint copy_prog, axis_prog;
    rc = vxl_program_get(bs->gpu, VXL_PROG_BSPLINE_COPY, 0, 0, &copy_prog);
    if (!rc) rc = vxl_program_get(bs->gpu, VXL_PROG_BSPLINE_AXIS, 0, 0, &axis_prog);
    if (rc) return rc;
    gl->GetError();
    bs->tex = vxl_texture_new(bs->gpu, GL_TEXTURE_3D, GL_LINEAR);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)bs->storage->geom.dims[0], (GLsizei)bs->storage->geom.dims[1], (GLsizei)bs->storage->geom.dims[2], 0,
                   GL_RED, GL_FLOAT, NULL);
    gl->BindImageTexture(VXL_IMAGE_OUT, bs->tex, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32F);
    gl->UseProgram(copy_prog);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, bs->storage->volume_tex);
    vxl_uniform_i(bs->gpu, copy_prog, "u_volume", VXL_VOLUME_UNIT);
    gl->DispatchCompute(groups8(bs->storage->geom.dims[1]), groups8(bs->storage->geom.dims[2]), 1);
    gl->MemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    gl->UseProgram(axis_prog);
    for (int axis = 0; axis < 3; axis++) {
        uint32_t u = axis == 0 ? bs->storage->geom.dims[1] : bs->storage->geom.dims[0], v = axis == 2 ? bs->storage->geom.dims[1] : bs->storage->geom.dims[2];
        vxl_uniform_i(bs->gpu, axis_prog, "u_axis", axis);
        gl->DispatchCompute(groups8(u), groups8(v), 1);
        gl->MemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    }
    gl->UseProgram(0);
    rc = vxl_gl_check(bs->gpu, "prefiltering cubic B-spline coefficients");
    if (rc) {
        vxl_bspline_release(bs);
        return rc;
    }
    bs->bytes = n * 4;
    return VXL_OK;
}

/* As the storage (storage.h, vxl_derived) and the budget (holdings.h) call it. */
static int whole(void *state, int unused)
{
    (void)unused;
    return vxl_bspline_ensure(state);
}
static int per_brick(void *state, int unused, void (*make_room)(void *room), void *room)
{
    (void)unused;
    return vxl_paged_bspline_ensure(state, make_room, room);
}
static void release(void *state) { vxl_bspline_release(state); }
static uint64_t pool_bytes(const void *state, uint32_t level, int unused, uint8_t *want, uint32_t *count)
{
    (void)unused;
    return vxl_paged_bspline_bytes(state, level, want, count);
}
void vxl_bspline_init(vxl_bspline_state *bs, vxl_gpu *g, vxl_storage_state *st)
{
    bs->gpu = g;
    bs->storage = st;
    /* the coefficients are computed on the CPU from the bricks (bspline_bricks.c): no residency of their own */
    st->derived[VXL_DERIVED_BSPLINE] = (vxl_derived){
        .state = bs, .whole = whole, .per_brick = per_brick, .release = release, .pool_bytes = pool_bytes,
        .page_tex = &bs->page_tex, .pool_dims = bs->pool_dims, .page_unit = VXL_CPAGE_UNIT,
        .page_name = "u_cpage", .dims_name = "u_cpool_dims"};
    vxl_holding_register(g, VXL_HOLD_BSPLINE, vxl_holding_counter, &bs->bytes);
}
