/* compressed_pool.c - compressed storage on the GL side: the code pool
 * (R8UI, every data brick, slot = data index, same slot layout as a data
 * pool), the palettes, and deferred filtering: the bricks a frame needs are
 * decoded (palette[code]) into the ordinary data pool, a small linear cache
 * the PAGED ray caster filters with hardware trilinear
 * (shaders/compute/decode_bricks.comp). Filtering the codes themselves would be
 * wrong: reconstruction is a table lookup, not linear in the codes. */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "compress.h"
#include "clock.h"
#include "storage.h"

static uint32_t palette_rows(uint32_t n) { return (n + VXL_PALETTES_PER_ROW - 1) / VXL_PALETTES_PER_ROW; }

uint64_t vxl_code_bytes_for(const vxl_storage_state *st, const vxl_pages *pg)
{
    const uint64_t e = vxl_page_edge(pg);
    uint32_t slots[3];
    if (!vxl_pool_layout(st, pg->n_data, (uint32_t)e, slots) || palette_rows(pg->n_data) > (uint32_t)st->gpu->info.max_3d_texture_size)
        return UINT64_MAX;
    return slots[0] * e * slots[1] * e * slots[2] * e +
           (uint64_t)palette_rows(pg->n_data) * VXL_PALETTES_PER_ROW * VXL_PALETTE_SIZE * sizeof(float);
}

void vxl_compressed_release(vxl_storage_state *st)
{
    if (st->code_tex && st->code_tex != st->pool_tex) st->gpu->gl.DeleteTextures(1, &st->code_tex);
    if (st->palette_tex) st->gpu->gl.DeleteTextures(1, &st->palette_tex);
    st->code_tex = st->palette_tex = 0;
    st->code_bytes = 0;
    memset(st->code_slots, 0, sizeof st->code_slots);
}

/* Compresses the full-resolution bricks and uploads codes and palettes; the
 * CPU copies go (the GL side decodes from its own codes from now on). */
int vxl_compressed_upload(vxl_storage_state *st)
{
    vxl_gl *gl = &st->gpu->gl;
    vxl_pages *pg = &st->levels[0];
    const uint32_t e = vxl_page_edge(pg);
    vxl_compressed c;
    int rc = vxl_compress_pages(&c, pg, &st->gpu->err);
    if (rc) return rc;
    free(pg->data);
    pg->data = NULL;
    vxl_pool_layout(st, c.n, e, st->code_slots); /* checked by the plan */
    gl->GetError();
    st->code_tex = vxl_texture_new(st->gpu, GL_TEXTURE_3D, GL_NEAREST); /* integer textures cannot be filtered */
    gl->TexImage3D(GL_TEXTURE_3D, 0, GL_R8UI, (GLsizei)(st->code_slots[0] * e), (GLsizei)(st->code_slots[1] * e),
                   (GLsizei)(st->code_slots[2] * e), 0, GL_RED_INTEGER, GL_UNSIGNED_BYTE, NULL);
    for (uint32_t k = 0; k < c.n; k++) {
        uint32_t o[3];
        vxl_slot_origin(k, st->code_slots, e, o);
        gl->TexSubImage3D(GL_TEXTURE_3D, 0, (GLint)o[0], (GLint)o[1], (GLint)o[2], (GLsizei)e, (GLsizei)e, (GLsizei)e,
                          GL_RED_INTEGER, GL_UNSIGNED_BYTE, c.codes + (size_t)k * c.voxels);
    }
    /* palettes are consecutive rows of 256: 16 of them fill one texel row as they lie */
    const uint32_t rows = palette_rows(c.n);
    float *pal = calloc((size_t)rows * VXL_PALETTES_PER_ROW * VXL_PALETTE_SIZE + 1, sizeof *pal);
    if (!pal) {
        vxl_compressed_free(&c);
        return vxl_fail(&st->gpu->err, VXL_ERR_NO_MEMORY, "out of memory for the palettes");
    }
    memcpy(pal, c.palette, (size_t)c.n * VXL_PALETTE_SIZE * sizeof *pal);
    vxl_compressed_free(&c);
    st->palette_tex = vxl_texture_new(st->gpu, GL_TEXTURE_2D, GL_NEAREST);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, VXL_PALETTES_PER_ROW * VXL_PALETTE_SIZE, (GLsizei)(rows ? rows : 1), 0,
                   GL_RED, GL_FLOAT, pal);
    free(pal);
    st->code_bytes = vxl_code_bytes_for(st, pg);
    return vxl_gl_check(st->gpu, "uploading the compressed bricks");
}

static double now_ms(void) { return vxl_monotonic_s() * 1e3; }

/* Deferred filtering, step one: decodes code slot source[k] into slot k of
 * the cache (pool_tex, `slots` per axis), for k < count. */
int vxl_compressed_decode(vxl_storage_state *st, const int32_t *source, uint32_t count, const uint32_t slots[3])
{
    vxl_gl *gl = &st->gpu->gl;
    const vxl_pages *pg = &st->levels[0];
    const uint32_t e = vxl_page_edge(pg);
    GLuint prog;
    int rc = vxl_program_get(st->gpu, VXL_PROG_DECODE_BRICKS, 0, pg->bytes_per_voxel - 1, &prog);
    if (rc) return rc;
    const double t0 = now_ms();
    gl->BindBuffer(GL_SHADER_STORAGE_BUFFER, st->gpu->ssbo[1]);
    gl->BufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(count ? count : 1) * (GLsizeiptr)sizeof(int32_t), source,
                   GL_STATIC_DRAW);
    gl->BindBufferBase(GL_SHADER_STORAGE_BUFFER, VXL_SSBO_BRICK_LIST, st->gpu->ssbo[1]);
    gl->UseProgram(prog);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_CODE_UNIT);
    gl->BindTexture(GL_TEXTURE_3D, st->code_tex);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_PALETTE_UNIT);
    gl->BindTexture(GL_TEXTURE_2D, st->palette_tex);
    gl->ActiveTexture(GL_TEXTURE0 + VXL_VOLUME_UNIT);
    vxl_uniform_i(st->gpu, prog, "u_codes", VXL_CODE_UNIT);
    vxl_uniform_i(st->gpu, prog, "u_palette", VXL_PALETTE_UNIT);
    vxl_uniform_i(st->gpu, prog, "u_edge", (int)e);
    vxl_uniform_i(st->gpu, prog, "u_count", (int)count);
    gl->Uniform3i(gl->GetUniformLocation(prog, "u_cache_slots"), (GLint)slots[0], (GLint)slots[1], (GLint)slots[2]);
    gl->Uniform3i(gl->GetUniformLocation(prog, "u_code_slots"), (GLint)st->code_slots[0], (GLint)st->code_slots[1],
                  (GLint)st->code_slots[2]);
    gl->BindImageTexture(VXL_IMAGE_OUT, st->pool_tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, vxl_texel_internal_format(pg->bytes_per_voxel));
    vxl_dispatch_bricks(st, prog, 0, count, e);
    gl->MemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    gl->Finish(); /* the decode time is a reported number */
    st->decode_ms = now_ms() - t0;
    gl->UseProgram(0);
    return vxl_gl_check(st->gpu, "decoding compressed bricks");
}
