/* bspline.c - coefficients of the interpolating cubic B-spline for the
 * `cubic` gradient filter, computed on the GL side once per volume
 * (shaders/compute/bspline_prefilter.comp) and kept until the volume changes. */
#include <stdlib.h>

#include "holdings.h"
#include "renderer_internal.h"

void vxl_bspline_release(vxl_renderer *r)
{
    const GLuint tex[2] = {r->bspline.tex, r->bspline.page_tex}; /* the volume or pool, and a pool's page table */
    r->gl.DeleteTextures(2, tex); /* 0 is ignored */
    r->bspline.tex = r->bspline.page_tex = 0;
    r->bspline.bytes = 0;
    free(r->bspline.covered); /* bricked: the coefficient bricks made */
    r->bspline.covered = NULL;
}

static GLuint groups8(uint32_t n) { return (n + 7) / 8; }

int vxl_bspline_ensure(vxl_renderer *r)
{
    if (r->bspline.tex) return VXL_OK;
    vxl_gl *gl = &r->gl;
    uint64_t n = (uint64_t)r->dims[0] * r->dims[1] * r->dims[2];
    int rc = vxl_holdings_ask(r, VXL_HOLD_BSPLINE, n * 4, NULL, "cubic B-spline coefficients");
    if (rc) return rc;
    GLuint copy_prog, axis_prog;
    rc = vxl_program_get(r, VXL_PROG_BSPLINE_COPY, 0, 0, &copy_prog);
    if (!rc) rc = vxl_program_get(r, VXL_PROG_BSPLINE_AXIS, 0, 0, &axis_prog);
    if (rc) return rc;
    gl->GetError();
    r->bspline.tex = vxl_texture_new(r, GL_TEXTURE_3D, GL_LINEAR);
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, (GLsizei)r->dims[0], (GLsizei)r->dims[1], (GLsizei)r->dims[2], 0,
                   GL_RED, GL_FLOAT, NULL);
    gl->BindImageTexture(VXL_IMAGE_OUT, r->bspline.tex, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32F);
    gl->UseProgram(copy_prog);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, r->storage.volume_tex);
    vxl_uniform_i(r, copy_prog, "u_volume", VXL_VOLUME_UNIT);
    gl->DispatchCompute(groups8(r->dims[1]), groups8(r->dims[2]), 1);
    gl->MemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    gl->UseProgram(axis_prog);
    for (int axis = 0; axis < 3; axis++) {
        uint32_t u = axis == 0 ? r->dims[1] : r->dims[0], v = axis == 2 ? r->dims[1] : r->dims[2];
        vxl_uniform_i(r, axis_prog, "u_axis", axis);
        gl->DispatchCompute(groups8(u), groups8(v), 1);
        gl->MemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    }
    gl->UseProgram(0);
    rc = vxl_gl_check(r, "prefiltering cubic B-spline coefficients");
    if (rc) {
        vxl_bspline_release(r);
        return rc;
    }
    r->bspline.bytes = n * 4;
    return VXL_OK;
}
