/* slices.c - the slicing comparison modes: texture-based volume
 * rendering as the textbooks teach it (Engel et al., Real-Time Volume
 * Graphics, ch. 3), on the ray caster's sampling, classification, gradient
 * and shading GLSL (shaders/render/slices.frag includes the same lib/ files).
 *
 * Both modes draw planes n . p = c (voxel space, n unit) spaced `step`
 * voxels apart, each as the polygon where it cuts the volume box (proxy
 * geometry, computed here on the CPU per frame), front to back:
 *  - SLICES2D: object-aligned stacks. n is the voxel axis closest to the
 *    viewing direction, chosen per frame, so the stack switches where two
 *    components are equal (45 degrees): the popping the lecture predicts. At
 *    step 1 the planes are the voxel layers, so a slice is a bilinear 2D
 *    texture; other steps interpolate between layers (intermediate slices).
 *    The distance between samples along a ray grows as 1/cos of the angle to
 *    the axis, up to sqrt(3) at the diagonal.
 *  - SLICES3D: view-aligned planes (normal along the view axis), clipped to
 *    the box: constant spacing along the view axis, no popping.
 * Each fragment corrects its opacity for its own distance to the next plane
 * along its ray (step / |n . dir|), as the ray caster does for its step.
 *
 * Compositing: the fragment shader reads the pixel's accumulated colour and
 * depth from the framebuffer's own textures (image load/store) and writes
 * them back, with a barrier between slices. A plane's polygon covers each
 * pixel once, so no two fragments of one draw touch one pixel. Blending
 * could composite colour, but not the depth where the accumulated opacity
 * first passes depth_threshold, which needs the accumulated opacity. */
#include "slices.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mat4.h"

#define MAX_POLY 12 /* a plane cuts at most 6 box edges; a plane through corners repeats points */

int vxl_slices_check(vxl_renderer *r, const vxl_frame *f)
{
    if (f->classify == VXL_CLASSIFY_PREINT)
        return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT,
                        "technique %s cannot use classify mode preint (a slice samples points, not segments); "
                        "use post or pre",
                        vxl_technique_name(f->technique));
    /* the slices shade with shade() (Phong); shadows and scattering need the
     * illumination volumes the ray caster binds */
    if (f->shading && f->shading_model != VXL_SHADING_PHONG)
        return vxl_fail(&r->gpu.err, VXL_ERR_INVALID_ARGUMENT,
                        "technique %s shades with the phong model only, not %s; use the ray caster for it",
                        vxl_technique_name(f->technique), vxl_shading_model_name(f->shading_model));
    return VXL_OK;
}

/* The eye in voxel space: its position (w = 1) for a perspective camera,
 * for an orthographic one the unit viewing direction (w = 0). */
static void eye_in_voxels(const vxl_frame *f, const double mv[16], double eye[4])
{
    double inv[16];
    vxl_mat4_invert(inv, mv); /* frame.c refused a singular view * model */
    int ortho = f->proj[11] == 0.0 && f->proj[15] != 0.0;
    const double origin[4] = {0, 0, 0, 1}, forward[4] = {0, 0, -1, 0};
    vxl_mat4_transform(inv, ortho ? forward : origin, eye);
    if (ortho) {
        double len = sqrt(eye[0] * eye[0] + eye[1] * eye[1] + eye[2] * eye[2]);
        for (int a = 0; a < 3; a++) eye[a] /= len;
        eye[3] = 0;
    } else {
        for (int a = 0; a < 3; a++) eye[a] /= eye[3];
        eye[3] = 1;
    }
}

typedef struct slice {
    double c, key; /* plane offset; distance from the eye (front first) */
} slice;

static int by_key(const void *a, const void *b)
{
    double x = ((const slice *)a)->key, y = ((const slice *)b)->key;
    return x < y ? -1 : x > y;
}

/* The polygon where plane n . p = c cuts the box [-0.5, dims - 0.5]^3, its
 * corners in order around it; returns how many (< 3: none). */
static int cut_box(const uint32_t dims[3], const double n[3], double c, float out[MAX_POLY][3])
{
    double pts[MAX_POLY][3], centre[3] = {0, 0, 0};
    int count = 0;
    for (int e = 0; e < 12; e++) {
        int axis = e / 4, o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
        double p0[3], p1[3];
        p0[o1] = p1[o1] = (e & 1) ? dims[o1] - 0.5 : -0.5;
        p0[o2] = p1[o2] = (e & 2) ? dims[o2] - 0.5 : -0.5;
        p0[axis] = -0.5;
        p1[axis] = dims[axis] - 0.5;
        double d0 = n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2] - c;
        double d1 = n[0] * p1[0] + n[1] * p1[1] + n[2] * p1[2] - c;
        if ((d0 < 0) == (d1 < 0) || d0 == d1) continue;
        double t = d0 / (d0 - d1);
        for (int a = 0; a < 3; a++) {
            pts[count][a] = p0[a] + t * (p1[a] - p0[a]);
            centre[a] += pts[count][a];
        }
        count++;
    }
    if (count < 3) return 0;
    for (int a = 0; a < 3; a++) centre[a] /= count;
    /* order by angle about the centre in a basis (u, v) of the plane */
    double u[3] = {0, 0, 0};
    u[fabs(n[0]) < 0.9 ? 0 : 1] = 1;
    double d = u[0] * n[0] + u[1] * n[1] + u[2] * n[2], ul = 0;
    for (int a = 0; a < 3; a++) u[a] -= d * n[a], ul += u[a] * u[a];
    for (int a = 0; a < 3; a++) u[a] /= sqrt(ul);
    double v[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
    double ang[MAX_POLY];
    for (int i = 0; i < count; i++) {
        double q[3] = {pts[i][0] - centre[0], pts[i][1] - centre[1], pts[i][2] - centre[2]};
        ang[i] = atan2(q[0] * v[0] + q[1] * v[1] + q[2] * v[2], q[0] * u[0] + q[1] * u[1] + q[2] * u[2]);
    }
    for (int i = 1; i < count; i++) /* insertion sort: at most 12 */
        for (int j = i; j > 0 && ang[j] < ang[j - 1]; j--) {
            double t = ang[j];
            ang[j] = ang[j - 1];
            ang[j - 1] = t;
            for (int a = 0; a < 3; a++) t = pts[j][a], pts[j][a] = pts[j - 1][a], pts[j - 1][a] = t;
        }
    for (int i = 0; i < count; i++)
        for (int a = 0; a < 3; a++) out[i][a] = (float)pts[i][a];
    return count;
}

/* The planes' normal for this frame. */
static void slice_normal(const vxl_frame *f, const uint32_t dims[3], const double mv[16], const double eye[4],
                         double n[3])
{
    if (f->technique == VXL_TECHNIQUE_SLICES3D) {
        /* the view axis: view-space z as a function of voxel position is
         * row 2 of mv, whose gradient is the planes' normal */
        double len = sqrt(mv[2] * mv[2] + mv[6] * mv[6] + mv[10] * mv[10]);
        n[0] = mv[2] / len;
        n[1] = mv[6] / len;
        n[2] = mv[10] / len;
        return;
    }
    /* SLICES2D: the stack whose axis has the largest component of the
     * viewing direction (towards the box centre for a perspective camera) */
    double d[3];
    for (int a = 0; a < 3; a++) d[a] = eye[3] != 0 ? (dims[a] - 1) * 0.5 - eye[a] : eye[a];
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (fabs(d[a]) > fabs(d[axis])) axis = a;
    n[0] = n[1] = n[2] = 0;
    n[axis] = 1;
}

int vxl_slices_draw(vxl_renderer *r, const vxl_frame *f, GLuint prog)
{
    vxl_gl *gl = &r->gpu.gl;
    double mv[16], mvp[16], eye[4], n[3];
    vxl_mat4_mul(mv, f->view, f->model);
    vxl_mat4_mul(mvp, f->proj, mv);
    eye_in_voxels(f, mv, eye);
    slice_normal(f, r->storage.geom.dims, mv, eye, n);
    const double s = f->step;

    /* the planes on the lattice c = k * step that cross the box */
    double cmin = INFINITY, cmax = -INFINITY;
    for (int k = 0; k < 8; k++) {
        double c = 0;
        for (int a = 0; a < 3; a++) c += n[a] * (((k >> a) & 1) ? r->storage.geom.dims[a] - 0.5 : -0.5);
        cmin = fmin(cmin, c);
        cmax = fmax(cmax, c);
    }
    double k0 = floor(cmin / s) + 1, k1 = ceil(cmax / s) - 1;
    if (!(k1 >= k0)) return VXL_OK;
    size_t count = (size_t)(k1 - k0) + 1;
    if (count > (size_t)f->max_steps) count = (size_t)f->max_steps; /* frame.c's bound on samples per ray */
    slice *sl = malloc(count * sizeof *sl);
    if (!sl) return vxl_fail(&r->gpu.err, VXL_ERR_NO_MEMORY, "out of memory for %zu slices", count);
    double ne = n[0] * eye[0] + n[1] * eye[1] + n[2] * eye[2];
    for (size_t i = 0; i < count; i++) {
        sl[i].c = (k0 + (double)i) * s;
        /* perspective: distance of the plane from the eye; orthographic:
         * how far along the viewing direction */
        sl[i].key = eye[3] != 0 ? fabs(sl[i].c - ne) : sl[i].c * ne;
    }
    qsort(sl, count, sizeof *sl, by_key);

    float mvp_f[16], eye_f[4] = {(float)eye[0], (float)eye[1], (float)eye[2], (float)eye[3]};
    float n_f[3] = {(float)n[0], (float)n[1], (float)n[2]};
    vxl_mat4_to_float(mvp_f, mvp);
    gl->UniformMatrix4fv(gl->GetUniformLocation(prog, "u_mvp"), 1, GL_FALSE, mvp_f);
    gl->Uniform4fv(gl->GetUniformLocation(prog, "u_eye"), 1, eye_f);
    gl->Uniform3fv(gl->GetUniformLocation(prog, "u_slice_normal"), 1, n_f);
    gl->Uniform1f(gl->GetUniformLocation(prog, "u_slice_spacing"), (float)s);
    GLint poly_loc = gl->GetUniformLocation(prog, "u_poly");

    /* the attachments are read and written as images, so nothing is written
     * through the fragment outputs */
    const GLenum none[2] = {GL_NONE, GL_NONE}, bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    gl->DrawBuffers(2, none);
    gl->BindImageTexture(VXL_IMAGE_SLICE_ACCUM, r->color_tex, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    gl->BindImageTexture(VXL_IMAGE_SLICE_DEPTH, r->depth_tex, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32F);
    gl->MemoryBarrier(GL_ALL_BARRIER_BITS); /* the clear, before the first read */
    for (size_t i = 0; i < count; i++) {
        float poly[MAX_POLY][3];
        int m = cut_box(r->storage.geom.dims, n, sl[i].c, poly);
        if (!m) continue;
        gl->Uniform3fv(poly_loc, m, &poly[0][0]);
        gl->DrawArrays(GL_TRIANGLE_FAN, 0, m);
        gl->MemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT); /* this slice, before the next reads it */
    }
    gl->MemoryBarrier(GL_ALL_BARRIER_BITS); /* before render.c reads the attachments back */
    gl->BindImageTexture(VXL_IMAGE_SLICE_ACCUM, 0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    gl->BindImageTexture(VXL_IMAGE_SLICE_DEPTH, 0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32F);
    gl->DrawBuffers(2, bufs);
    free(sl);
    return VXL_OK;
}
