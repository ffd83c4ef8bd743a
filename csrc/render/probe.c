/* probe.c - vxl_probe_gradients: runs gradients.glsl in a compute shader at
 * caller-given points, so accuracy is measured on the shader itself. */
#include <math.h>
#include <string.h>

#include "renderer_internal.h"
#include "voxlight_dev.h"

#define MAX_PROBE_POINTS (1u << 24)

typedef struct probe_job {
    vxl_renderer *r;
    const vxl_render_params *p;
    const float *points;
    uint32_t n;
    float *out;
} probe_job;

static int job_probe(void *arg)
{
    probe_job *j = arg;
    vxl_renderer *r = j->r;
    vxl_gl *gl = &r->gpu.gl;
    if (!r->storage.has_volume) return vxl_fail(&r->gpu.err, VXL_ERR_STATE, "no volume: call vxl_renderer_set_volume first");
    vxl_render_params params; /* read up to the caller's struct_size, never past */
    int rc = vxl_render_params_read(&params, j->p, &r->gpu.err);
    if (rc) return rc;
    const vxl_render_params *p = &params;
    if (p->filter >= VXL_FILTER_COUNT) return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "unknown filter %u", p->filter);
    float d = p->sample_distance == 0 ? 1.0f : p->sample_distance;
    if (!(d >= 1e-3f && d <= 64))
        return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "sample_distance = %g is out of range", d);
    for (uint32_t i = 0; i < 3 * j->n; i++)
        if (!isfinite(j->points[i]))
            return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "probe point %u is not finite", i / 3);
    GLuint prog;
    rc = r->storage.ops->check_filter(&r->storage, p->filter, VXL_CLASSIFY_POST);
    if (!rc) rc = r->storage.ops->prepare(&r->storage, NULL);
    if (!rc) rc = vxl_program_get(&r->gpu, VXL_PROG_PROBE, p->filter, r->storage.ops->sample_flags(&r->storage), &prog);
    if (rc) return rc;
    gl->GetError();
    rc = vxl_bind_volume_textures(r, prog, p->filter, (int)p->gradient_store);
    if (rc) return rc;
    GLsizeiptr bytes = (GLsizeiptr)j->n * 3 * (GLsizeiptr)sizeof(float);
    gl->BindBuffer(GL_SHADER_STORAGE_BUFFER, r->gpu.ssbo[0]);
    gl->BufferData(GL_SHADER_STORAGE_BUFFER, bytes, j->points, GL_STATIC_DRAW);
    gl->BindBufferBase(GL_SHADER_STORAGE_BUFFER, VXL_SSBO_PROBE_POINTS, r->gpu.ssbo[0]);
    gl->BindBuffer(GL_SHADER_STORAGE_BUFFER, r->gpu.ssbo[1]);
    gl->BufferData(GL_SHADER_STORAGE_BUFFER, bytes, NULL, GL_DYNAMIC_READ);
    gl->BindBufferBase(GL_SHADER_STORAGE_BUFFER, VXL_SSBO_PROBE_RESULTS, r->gpu.ssbo[1]);
    gl->Uniform1ui(gl->GetUniformLocation(prog, "u_count"), j->n);
    vxl_uniform_i(&r->gpu, prog, "u_sequential", p->reuse_gradients != 0);
    vxl_uniform_f(&r->gpu, prog, "u_sample_distance", d);
    gl->DispatchCompute(p->reuse_gradients ? 1 : (j->n + 63) / 64, 1, 1);
    gl->MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    gl->GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, bytes, j->out);
    gl->UseProgram(0);
    return vxl_gl_check(&r->gpu, "probing gradients");
}

int vxl_probe_gradients(vxl_renderer *r, const vxl_render_params *p, const float *points, uint32_t n, float *out)
{
    if (!r) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer is NULL");
    if (n == 0) return VXL_OK;
    if (!points || !out) return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT, "points or out is NULL");
    if (n > MAX_PROBE_POINTS) return vxl_fail(&r->gpu.err, VXL_ERR_LIMIT, "%u probe points exceed %u", n, MAX_PROBE_POINTS);
    probe_job j = {r, p, points, n, out};
    int rc = vxl_gl_thread_call(&r->thread, job_probe, &j);
    if (rc) vxl_publish_error(&r->gpu.err);
    return rc;
}

typedef struct skip_grid_job {
    vxl_renderer *r;
    uint32_t *dims, *brick;
    float *out;
    size_t max_floats;
} skip_grid_job;

/* On the GL thread: the grid is the skipping state's, which frames write. */
static int job_skip_grid(void *arg)
{
    skip_grid_job *j = arg;
    const vxl_bricks *b = &j->r->skipping.bricks;
    if (!b->minmax)
        return vxl_fail(&j->r->gpu.err, VXL_ERR_STATE, "no skipping grid yet: set a volume and render with skipping");
    memcpy(j->dims, b->dims, sizeof b->dims);
    if (j->brick) *j->brick = b->size;
    size_t n = 2 * (size_t)b->dims[0] * b->dims[1] * b->dims[2];
    if (j->out) memcpy(j->out, b->minmax, (n < j->max_floats ? n : j->max_floats) * sizeof(float));
    return VXL_OK;
}

int vxl_probe_skip_grid(vxl_renderer *r, uint32_t dims[3], uint32_t *brick, float *out, size_t max_floats)
{
    if (!r || !dims) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "renderer or dims is NULL");
    skip_grid_job j = {r, dims, brick, out, max_floats};
    int rc = vxl_gl_thread_call(&r->thread, job_skip_grid, &j);
    if (rc) vxl_publish_error(&r->gpu.err);
    return rc;
}
