/* transmittance.c - the scene points' transmittance to a light
 * (transmittance.h): the scene depth up, one compute pass, the image back. */
#include "transmittance.h"

#include "holdings.h"
#include "mat4.h"

/* The depth and result textures at the frame's size (kept while it holds). */
static int ensure_images(vxl_illumination_state *s, uint32_t w, uint32_t h)
{
    vxl_gl *gl = &s->gpu->gl;
    if (s->transmittance_tex && s->image_w == w && s->image_h == h) return VXL_OK;
    if (s->scene_depth_tex) gl->DeleteTextures(1, &s->scene_depth_tex);
    if (s->transmittance_tex) gl->DeleteTextures(1, &s->transmittance_tex);
    s->scene_depth_tex = s->transmittance_tex = 0;
    s->image_w = s->image_h = 0;
    s->image_bytes = 0;
    const uint64_t bytes = (uint64_t)w * h * 4 * 2;
    int rc = vxl_holdings_ask(s->gpu, VXL_HOLD_SCENE_SHADOWS, bytes + vxl_shadow_maps_bytes(&s->shadows), NULL,
                              "the %ux%u scene transmittance images", w, h);
    if (rc) return rc;
    s->scene_depth_tex = vxl_texture_new(s->gpu, GL_TEXTURE_2D, GL_NEAREST);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, (GLsizei)w, (GLsizei)h, 0, GL_RED, GL_FLOAT, NULL);
    s->transmittance_tex = vxl_texture_new(s->gpu, GL_TEXTURE_2D, GL_NEAREST);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, (GLsizei)w, (GLsizei)h, 0, GL_RED, GL_FLOAT, NULL);
    s->image_w = w;
    s->image_h = h;
    s->image_bytes = bytes;
    return vxl_gl_check(s->gpu, "allocating the scene transmittance images");
}

/* view space -> voxel space, and clip -> view space, as the shader takes them. */
static int matrices(const vxl_frame *f, float view_to_voxel[16], float inv_proj[16])
{
    double mv[16], inv_mv[16], inv_p[16];
    vxl_mat4_mul(mv, f->view, f->model);
    if (!vxl_mat4_invert(inv_mv, mv) || !vxl_mat4_invert(inv_p, f->proj)) return 0;
    vxl_mat4_to_float(view_to_voxel, inv_mv);
    vxl_mat4_to_float(inv_proj, inv_p);
    return 1;
}

int vxl_scene_transmittance_pass(vxl_illumination_state *s, const vxl_frame *f, int light, float *out)
{
    vxl_gl *gl = &s->gpu->gl;
    if (!s->in_use || light < 0 || light >= f->light_count || !f->scene_depth)
        return vxl_fail(&s->gpu->err, VXL_ERR_STATE, "the scene transmittance needs the light's illumination volume");
    float view_to_voxel[16], inv_proj[16];
    if (!matrices(f, view_to_voxel, inv_proj))
        return vxl_fail(&s->gpu->err, VXL_ERR_INVALID_ARGUMENT, "the projection or view * model matrix is singular");
    GLuint prog;
    int rc = ensure_images(s, f->width, f->height);
    if (!rc) rc = vxl_program_get(s->gpu, VXL_PROG_SCENE_TRANSMITTANCE, 0, 0, &prog);
    if (rc) return rc;
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCENE_DEPTH_UNIT);
    gl->BindTexture(GL_TEXTURE_2D, s->scene_depth_tex);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, (GLsizei)f->width, (GLsizei)f->height, 0, GL_RED, GL_FLOAT, f->scene_depth);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_ILLUMINATION_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, s->tex);
    gl->UseProgram(prog);
    vxl_illumination_bind(s, prog, f); /* lib/illumination.glsl's uniforms, as the ray caster gets them */
    const float dims[3] = {(float)s->storage->geom.dims[0], (float)s->storage->geom.dims[1], (float)s->storage->geom.dims[2]};
    gl->Uniform3fv(gl->GetUniformLocation(prog, "u_dims"), 1, dims);
    gl->UniformMatrix4fv(gl->GetUniformLocation(prog, "u_view_to_voxel"), 1, GL_FALSE, view_to_voxel);
    gl->UniformMatrix4fv(gl->GetUniformLocation(prog, "u_inv_proj"), 1, GL_FALSE, inv_proj);
    gl->Uniform2f(gl->GetUniformLocation(prog, "u_viewport"), (float)f->width, (float)f->height);
    vxl_uniform_i(s->gpu, prog, "u_light", light);
    vxl_uniform_i(s->gpu, prog, "u_scene_depth", VXL_SCENE_DEPTH_UNIT);
    gl->BindImageTexture(VXL_IMAGE_OUT, s->transmittance_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    gl->DispatchCompute((f->width + 7) / 8, (f->height + 7) / 8, 1);
    gl->MemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT); /* the readback after image stores */
    gl->ActiveTexture(GL_TEXTURE0 + VXL_SCRATCH_UNIT);
    gl->BindTexture(GL_TEXTURE_2D, s->transmittance_tex);
    gl->PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl->GetTexImage(GL_TEXTURE_2D, 0, GL_RED, GL_FLOAT, out);
    gl->PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl->BindImageTexture(VXL_IMAGE_OUT, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    gl->UseProgram(0);
    return vxl_gl_check(s->gpu, "computing the scene transmittance");
}
