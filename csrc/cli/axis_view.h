/* axis_view.h - the CLI's cameras: --view x|-x|y|-y|z|-z looks
 * along a world axis, framing the volume's world box, and --ortho makes
 * the projection orthographic. Pure math over the box (no library state),
 * header-only so the CLI, the tests and the benchmark share it (the CLI is
 * one translation unit: any other .c file in csrc/cli would be linked into
 * the library).
 *
 * View a looks from the +a side towards -a (`z`: from above, down onto the
 * xy plane) and `-a` from the -a side towards +a. The image's up is +z for
 * the x and y views and +y for the z views; right completes a right-handed
 * frame (z: +x right, +y up; x: +y right; y: -x right). The box's extent
 * across the view fills the image along the tighter of its two sides (both
 * when the aspect ratios agree): orthographically exactly, so with image
 * pixels one voxel wide the rays pass through voxel centres; in perspective
 * the box's near face is framed that way. */
#ifndef VXL_AXIS_VIEW_H
#define VXL_AXIS_VIEW_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#define VXL_AXIS_VIEW_NONE (-1)

/* "x" -> 0, "-x" -> 1, "y" -> 2, "-y" -> 3, "z" -> 4, "-z" -> 5; -1 otherwise. */
static inline int vxl_axis_view_from_name(const char *s)
{
    static const char *const names[6] = {"x", "-x", "y", "-y", "z", "-z"};
    for (int i = 0; s && i < 6; i++)
        if (!strcmp(s, names[i])) return i;
    return VXL_AXIS_VIEW_NONE;
}

/* The world box of a volume: its voxel box [-0.5, dim - 0.5]^3 through the
 * voxel -> world affine (column-major, as vxl_volume_info.affine). */
static inline void vxl_axis_view_box(const uint32_t dims[3], const double affine[16], double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (int c = 0; c < 8; c++) {
        double v[3] = {(c & 1) ? dims[0] - 0.5 : -0.5, (c & 2) ? dims[1] - 0.5 : -0.5, (c & 4) ? dims[2] - 0.5 : -0.5};
        for (int a = 0; a < 3; a++) {
            double w = affine[a] * v[0] + affine[4 + a] * v[1] + affine[8 + a] * v[2] + affine[12 + a];
            lo[a] = w < lo[a] ? w : lo[a];
            hi[a] = w > hi[a] ? w : hi[a];
        }
    }
}

/* The view's unit vectors: back (towards the eye), right and up. */
static inline void vxl_axis_view_frame(int view, double back[3], double right[3], double up[3])
{
    int axis = view / 2;
    double s = (view & 1) ? -1.0 : 1.0;
    memset(back, 0, 3 * sizeof *back);
    memset(up, 0, 3 * sizeof *up);
    back[axis] = s;
    up[axis == 2 ? 1 : 2] = 1;
    /* right = up x back */
    right[0] = up[1] * back[2] - up[2] * back[1];
    right[1] = up[2] * back[0] - up[0] * back[2];
    right[2] = up[0] * back[1] - up[1] * back[0];
}

/* Orthographic projection of the view-space box [l, r] x [b, t] x [-f, -n] (column-major, GL's). */
static inline void vxl_axis_view_ortho(float m[16], double l, double r, double b, double t, double n, double f)
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = (float)(2 / (r - l));
    m[5] = (float)(2 / (t - b));
    m[10] = (float)(-2 / (f - n));
    m[12] = (float)(-(r + l) / (r - l));
    m[13] = (float)(-(t + b) / (t - b));
    m[14] = (float)(-(f + n) / (f - n));
    m[15] = 1;
}

/* view (0..5, vxl_axis_view_from_name) onto the world box [lo, hi], for a
 * w x h image: world -> view and view -> clip matrices, column-major. */
static inline void vxl_axis_view_camera(int view, int ortho, const double lo[3], const double hi[3], uint32_t w,
                                        uint32_t h, float view_m[16], float proj[16])
{
    double back[3], right[3], up[3], c[3], half[3];
    vxl_axis_view_frame(view, back, right, up);
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5 * (lo[a] + hi[a]);
        half[a] = 0.5 * (hi[a] - lo[a]);
    }
    double hr = 0, hu = 0, hd = 0; /* half extents across (right, up) and along the view */
    for (int a = 0; a < 3; a++) {
        hr += fabs(right[a]) * half[a];
        hu += fabs(up[a]) * half[a];
        hd += fabs(back[a]) * half[a];
    }
    double aspect = (double)w / (double)h;
    if (hr / hu > aspect) hu = hr / aspect;
    else hr = hu * aspect;
    const double tan_y = tan(15.0 * M_PI / 180.0); /* the default camera's 30 degree field of view */
    /* eye to the near face: any positive gap orthographically, the framing distance in perspective */
    double gap = ortho ? hd + hu : hu / tan_y;
    double dist = gap + hd, eye[3];
    for (int a = 0; a < 3; a++) eye[a] = c[a] + dist * back[a];
    memset(view_m, 0, 16 * sizeof *view_m);
    for (int a = 0; a < 3; a++) {
        view_m[4 * a + 0] = (float)right[a];
        view_m[4 * a + 1] = (float)up[a];
        view_m[4 * a + 2] = (float)back[a];
    }
    view_m[12] = (float)-(right[0] * eye[0] + right[1] * eye[1] + right[2] * eye[2]);
    view_m[13] = (float)-(up[0] * eye[0] + up[1] * eye[1] + up[2] * eye[2]);
    view_m[14] = (float)-(back[0] * eye[0] + back[1] * eye[1] + back[2] * eye[2]);
    view_m[15] = 1;
    double n = 0.5 * gap, f = dist + hd + 0.5 * gap;
    if (ortho) {
        vxl_axis_view_ortho(proj, -hr, hr, -hu, hu, n, f);
    } else {
        memset(proj, 0, 16 * sizeof *proj);
        proj[0] = (float)(1 / (tan_y * aspect));
        proj[5] = (float)(1 / tan_y);
        proj[10] = (float)((f + n) / (n - f));
        proj[11] = -1;
        proj[14] = (float)(2 * f * n / (n - f));
    }
}

/* --ortho without --view: an orthographic projection for a camera `view_m`
 * (e.g. the default one), framing the box's bounding sphere in the tighter
 * image side, as the default perspective camera frames it. */
static inline void vxl_axis_view_ortho_for(const float view_m[16], const double lo[3], const double hi[3], uint32_t w,
                                           uint32_t h, float proj[16])
{
    double cv[3] = {view_m[12], view_m[13], view_m[14]}, r2 = 0;
    for (int a = 0; a < 3; a++) r2 += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    for (int row = 0; row < 3; row++)
        for (int a = 0; a < 3; a++) cv[row] += view_m[4 * a + row] * 0.5 * (lo[a] + hi[a]);
    double radius = sqrt(r2) * 1.02, aspect = (double)w / (double)h;
    double hu = aspect < 1 ? radius / aspect : radius, hr = hu * aspect;
    vxl_axis_view_ortho(proj, cv[0] - hr, cv[0] + hr, cv[1] - hu, cv[1] + hu, -cv[2] - 1.5 * radius,
                        -cv[2] + 1.5 * radius);
}

#endif
