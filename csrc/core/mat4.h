/* mat4.h - 4x4 double matrices, column-major (m[col*4 + row]), as OpenGL. */
#ifndef VXL_MAT4_H
#define VXL_MAT4_H

void vxl_mat4_identity(double m[16]);
void vxl_mat4_mul(double out[16], const double a[16], const double b[16]); /* a*b */
/* Returns 0 if singular or not finite. */
int vxl_mat4_invert(double out[16], const double m[16]);
void vxl_mat4_transform(const double m[16], const double in[4], double out[4]);
void vxl_mat4_from_float(double out[16], const float in[16]);
void vxl_mat4_to_float(float out[16], const double in[16]);
int vxl_mat4_is_finite(const double m[16]);
void vxl_mat4_look_at(double out[16], const double eye[3], const double center[3], const double up[3]);
void vxl_mat4_perspective(double out[16], double fovy_rad, double aspect, double znear, double zfar);
/* Upper-left 3x3 inverse transpose, column-major; 0 if singular. */
int vxl_mat3_normal_matrix(float out[9], const double m[16]);

#endif
