/* matcap.c - the MatCap texture (matcap.h). Linear filtering: the lookup at
 * the normal is a bilinear read of the image, as Blender's viewport does. */
#include "matcap.h"

#include "hash.h"
#include "holdings.h"

void vxl_matcap_init(vxl_matcap_state *m, vxl_gpu *g)
{
    m->gpu = g;
    vxl_holding_register(g, VXL_HOLD_MATCAP, vxl_holding_counter, &m->bytes);
}

void vxl_matcap_release(vxl_matcap_state *m)
{
    if (m->tex) m->gpu->gl.DeleteTextures(1, &m->tex);
    m->tex = 0;
    m->key = 0;
    m->bytes = 0;
}

uint64_t vxl_matcap_key(const vxl_frame *f)
{
    if (f->matcap_key) return f->matcap_key;
    uint64_t h = 1469598103934665603ull;
    const uint32_t size[2] = {f->matcap_width, f->matcap_height};
    h = vxl_fnv(h, size, sizeof size);
    h = vxl_fnv(h, f->matcap_rgba, (size_t)f->matcap_width * f->matcap_height * 4 * sizeof(float));
    return h ? h : 1;
}

int vxl_matcap_prepare(vxl_matcap_state *m, const vxl_frame *f, GLuint prog)
{
    if (!f->matcap_rgba) return VXL_OK;
    vxl_gl *gl = &m->gpu->gl;
    uint64_t key = vxl_matcap_key(f);
    if (!m->tex || key != m->key) {
        uint64_t bytes = (uint64_t)f->matcap_width * f->matcap_height * 4 * sizeof(float);
        vxl_matcap_release(m); /* what it held is not charged against its replacement */
        int rc = vxl_holdings_ask(m->gpu, VXL_HOLD_MATCAP, bytes, NULL, "the %ux%u MatCap image", f->matcap_width,
                                  f->matcap_height);
        if (rc) return rc;
        gl->GetError();
        m->tex = vxl_texture_new(m->gpu, GL_TEXTURE_2D, GL_LINEAR);
        gl->TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, (GLsizei)f->matcap_width, (GLsizei)f->matcap_height, 0, GL_RGBA,
                       GL_FLOAT, f->matcap_rgba);
        rc = vxl_gl_check(m->gpu, "uploading the MatCap");
        if (rc) {
            vxl_matcap_release(m);
            return rc;
        }
        m->key = key;
        m->bytes = bytes;
    }
    gl->ActiveTexture(GL_TEXTURE0 + VXL_MATCAP_UNIT);
    gl->BindTexture(GL_TEXTURE_2D, m->tex);
    vxl_uniform_i(m->gpu, prog, "u_matcap", VXL_MATCAP_UNIT);
    return VXL_OK;
}
