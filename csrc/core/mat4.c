/* mat4.c - the small amount of linear algebra the camera needs, in double so
 * extreme near/far planes and affines survive until the final float cast. */
#include "mat4.h"

#include <math.h>
#include <string.h>

void vxl_mat4_identity(double m[16])
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = m[5] = m[10] = m[15] = 1.0;
}

void vxl_mat4_mul(double out[16], const double a[16], const double b[16])
{
    double r[16];
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double s = 0;
            for (int k = 0; k < 4; k++) s += a[k * 4 + row] * b[c * 4 + k];
            r[c * 4 + row] = s;
        }
    memcpy(out, r, sizeof r);
}

int vxl_mat4_is_finite(const double m[16])
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(m[i])) return 0;
    return 1;
}

/* Gauss-Jordan with partial pivoting. */
int vxl_mat4_invert(double out[16], const double m[16])
{
    double a[4][8];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            a[r][c] = m[c * 4 + r];
            a[r][c + 4] = r == c;
        }
    double scale = 0;
    for (int i = 0; i < 16; i++) scale = fmax(scale, fabs(m[i]));
    if (!(scale > 0) || !isfinite(scale)) return 0;
    for (int c = 0; c < 4; c++) {
        int p = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[p][c])) p = r;
        if (!(fabs(a[p][c]) > scale * 1e-300)) return 0;
        if (p != c)
            for (int k = 0; k < 8; k++) {
                double t = a[c][k];
                a[c][k] = a[p][k];
                a[p][k] = t;
            }
        double inv = 1.0 / a[c][c];
        for (int k = 0; k < 8; k++) a[c][k] *= inv;
        for (int r = 0; r < 4; r++) {
            if (r == c) continue;
            double f = a[r][c];
            if (f != 0)
                for (int k = 0; k < 8; k++) a[r][k] -= f * a[c][k];
        }
    }
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) out[c * 4 + r] = a[r][c + 4];
    return vxl_mat4_is_finite(out);
}

void vxl_mat4_transform(const double m[16], const double in[4], double out[4])
{
    double r[4];
    for (int row = 0; row < 4; row++)
        r[row] = m[row] * in[0] + m[4 + row] * in[1] + m[8 + row] * in[2] + m[12 + row] * in[3];
    memcpy(out, r, sizeof r);
}

void vxl_mat4_from_float(double out[16], const float in[16])
{
    for (int i = 0; i < 16; i++) out[i] = in[i];
}

void vxl_mat4_to_float(float out[16], const double in[16])
{
    for (int i = 0; i < 16; i++) out[i] = (float)in[i];
}

static void normalize3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0)
        for (int i = 0; i < 3; i++) v[i] /= l;
}

static void cross3(double o[3], const double a[3], const double b[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

void vxl_mat4_look_at(double m[16], const double eye[3], const double center[3], const double up[3])
{
    double f[3] = {center[0] - eye[0], center[1] - eye[1], center[2] - eye[2]}, s[3], u[3];
    normalize3(f);
    cross3(s, f, up);
    normalize3(s);
    cross3(u, s, f);
    vxl_mat4_identity(m);
    for (int i = 0; i < 3; i++) {
        m[i * 4 + 0] = s[i];
        m[i * 4 + 1] = u[i];
        m[i * 4 + 2] = -f[i];
    }
    m[12] = -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    m[13] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    m[14] = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
}

void vxl_mat4_perspective(double m[16], double fovy, double aspect, double n, double f)
{
    double t = 1.0 / tan(fovy / 2);
    memset(m, 0, 16 * sizeof *m);
    m[0] = t / aspect;
    m[5] = t;
    m[10] = (f + n) / (n - f);
    m[11] = -1;
    m[14] = 2 * f * n / (n - f);
}

int vxl_mat3_normal_matrix(float out[9], const double m[16])
{
    /* inverse transpose of the 3x3 = cofactor matrix / det */
    double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6], i = m[10];
    double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    double D = -(b * i - c * h), E = a * i - c * g, F = -(a * h - b * g);
    double G = b * f - c * e, H = -(a * f - c * d), I = a * e - b * d;
    double det = a * A + b * B + c * C;
    if (!(fabs(det) > 0) || !isfinite(det)) return 0;
    /* (M^-1)^T = cofactor / det; cofactor rows: (A B C), (D E F), (G H I) */
    double cof[3][3] = {{A, B, C}, {D, E, F}, {G, H, I}};
    /* Only directions matter; rescale so huge or tiny affines stay in float range. */
    double mx = 0;
    for (int row = 0; row < 3; row++)
        for (int col = 0; col < 3; col++) mx = fmax(mx, fabs(cof[row][col] / det));
    if (!(mx > 0) || !isfinite(mx)) return 0;
    for (int row = 0; row < 3; row++)
        for (int col = 0; col < 3; col++) out[col * 3 + row] = (float)(cof[row][col] / det / mx);
    return 1;
}
