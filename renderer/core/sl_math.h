/* sl_math.h — small vector and matrix math, double precision by default.
 *
 * Cameras, bounds and references are computed in double; a matrix is turned
 * into float only when it is uploaded (sl_mat4_to_float). Matrices are
 * column-major like GLSL: m[col*4 + row]. Header-only, no allocation.
 */
#ifndef SL_MATH_H
#define SL_MATH_H

#include <math.h>

typedef struct sl_vec3 { double x, y, z; } sl_vec3;
typedef struct sl_mat4 { double m[16]; } sl_mat4;

#define SL_PI 3.14159265358979323846

static inline sl_vec3 sl_v3(double x, double y, double z) { return (sl_vec3){x, y, z}; }
static inline sl_vec3 sl_v3_add(sl_vec3 a, sl_vec3 b) { return sl_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline sl_vec3 sl_v3_sub(sl_vec3 a, sl_vec3 b) { return sl_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline sl_vec3 sl_v3_scale(sl_vec3 a, double s) { return sl_v3(a.x * s, a.y * s, a.z * s); }
static inline double sl_v3_dot(sl_vec3 a, sl_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline sl_vec3 sl_v3_cross(sl_vec3 a, sl_vec3 b)
{
    return sl_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double sl_v3_length(sl_vec3 a) { return sqrt(sl_v3_dot(a, a)); }
/* Returns a unit vector, or the zero vector when a has no length. */
static inline sl_vec3 sl_v3_normalize(sl_vec3 a)
{
    double l = sl_v3_length(a);
    return l > 0.0 ? sl_v3_scale(a, 1.0 / l) : sl_v3(0, 0, 0);
}
static inline int sl_v3_is_finite(sl_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

static inline sl_mat4 sl_mat4_identity(void)
{
    sl_mat4 r = {{0}};
    r.m[0] = r.m[5] = r.m[10] = r.m[15] = 1.0;
    return r;
}

static inline sl_mat4 sl_mat4_mul(sl_mat4 a, sl_mat4 b)
{
    sl_mat4 r;
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += a.m[k * 4 + row] * b.m[c * 4 + k];
            r.m[c * 4 + row] = s;
        }
    return r;
}

/* Transforms the point p (w = 1) and returns xyz / w. */
static inline sl_vec3 sl_mat4_transform_point(sl_mat4 a, sl_vec3 p)
{
    double v[4];
    for (int row = 0; row < 4; row++)
        v[row] = a.m[row] * p.x + a.m[4 + row] * p.y + a.m[8 + row] * p.z + a.m[12 + row];
    return sl_v3(v[0] / v[3], v[1] / v[3], v[2] / v[3]);
}

static inline void sl_mat4_to_float(sl_mat4 a, float out[16])
{
    for (int i = 0; i < 16; i++)
        out[i] = (float)a.m[i];
}

#endif
