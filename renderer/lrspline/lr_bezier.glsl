// lr_bezier.glsl — evaluation of an LR-spline volume's Bézier blocks on the GPU (issue 15):
// de Casteljau per direction (x, then y, then z) on the block of one element, value and
// gradient (scalar) or value and Jacobian (vector), in single precision; with LR_DOUBLE 1
// also in double (core in GLSL 4.00+, on llvmpipe too) from the double buffers. Layout (std430) and the
// derivation of the blocks: renderer/lrspline/sl_lr_bezier.h. The orders LR_O0..2 (1..4)
// and LR_DIM (1 or 3) are compile-time constants (sl_lr_bezier_defines), so every loop has
// constant bounds and unrolls. Any p is accepted (the block's polynomial is extended);
// the element comes from lr_find_element (lrspline/lr_find.glsl). Coordinates are world
// = parameter coordinates.
#ifndef LR_O0
#define LR_O0 2
#endif
#ifndef LR_O1
#define LR_O1 2
#endif
#ifndef LR_O2
#define LR_O2 2
#endif
#ifndef LR_DIM
#define LR_DIM 1
#endif
#ifndef LR_DOUBLE
#define LR_DOUBLE 0
#endif

const int LR_STRIDE = LR_O0 * LR_O1 * LR_O2 * LR_DIM;

struct lr_box { vec4 lo; vec4 hi; };          // xyz: element box; lo.w, hi.w: value hull
layout(std430, binding = 6) readonly buffer lr_boxes { lr_box lr_box_data[]; };
layout(std430, binding = 7) readonly buffer lr_coefs { float lr_coef_data[]; };
uniform int u_lr_element_count;
uniform vec3 u_lr_domain_lo;
uniform vec3 u_lr_domain_hi;

// de Casteljau on w[0..N-1] of type T at u (type S): value v and derivative dv in u.
#define LR_DECASTELJAU(NAME, N, T, S)                                        \
    void NAME(T w[N], S u, out T v, out T dv)                                \
    {                                                                        \
        for (int r = N - 1; r >= 2; r--)                                     \
            for (int i = 0; i < r; i++)                                      \
                w[i] = mix(w[i], w[i + 1], u);                               \
        v = (N == 1) ? w[0] : mix(w[0], w[min(1, N - 1)], u);                \
        dv = S(N - 1) * (w[min(1, N - 1)] - w[0]);                           \
    }

// The block of element e at p: value and the partial derivatives d0, d1, d2 in world x, y, z.
// T: the coefficient type (S for scalars, V3 for vectors), FETCH(i) the coefficient i.
#define LR_EVAL(NAME, T, S, V3, BOX, FETCH, DC0, DC1, DC2)                   \
    void NAME(int e, V3 p, out T value, out T d0, out T d1, out T d2)        \
    {                                                                        \
        V3 lo = V3(BOX[e].lo.xyz), h = V3(BOX[e].hi.xyz) - lo;               \
        V3 u = (p - lo) / h;                                                 \
        int base = e * LR_STRIDE;                                            \
        T vz[LR_O2], yz[LR_O2], xz[LR_O2];                                   \
        for (int k = 0; k < LR_O2; k++) {                                    \
            T vy[LR_O1], xy[LR_O1];                                          \
            for (int j = 0; j < LR_O1; j++) {                                \
                T w[LR_O0];                                                  \
                for (int i = 0; i < LR_O0; i++)                              \
                    w[i] = FETCH(base + ((k * LR_O1 + j) * LR_O0 + i) * LR_DIM); \
                DC0(w, u.x, vy[j], xy[j]);                                   \
            }                                                                \
            T unused;                                                        \
            DC1(vy, u.y, vz[k], yz[k]);                                      \
            DC1(xy, u.y, xz[k], unused);                                     \
        }                                                                    \
        T unused2;                                                           \
        DC2(vz, u.z, value, d2);                                             \
        DC2(yz, u.z, d1, unused2);                                           \
        DC2(xz, u.z, d0, unused2);                                           \
        d0 /= h.x;                                                           \
        d1 /= h.y;                                                           \
        d2 /= h.z;                                                           \
    }

#if LR_DIM == 1
#define LR_T float
#define LR_FETCH(i) lr_coef_data[i]
#else
#define LR_T vec3
#define LR_FETCH(i) vec3(lr_coef_data[i], lr_coef_data[(i) + 1], lr_coef_data[(i) + 2])
#endif
LR_DECASTELJAU(lr_dc0, LR_O0, LR_T, float)
LR_DECASTELJAU(lr_dc1, LR_O1, LR_T, float)
LR_DECASTELJAU(lr_dc2, LR_O2, LR_T, float)
LR_EVAL(lr_eval_block, LR_T, float, vec3, lr_box_data, LR_FETCH, lr_dc0, lr_dc1, lr_dc2)

#if LR_DIM == 1
// Scalar value and world gradient of element e at p.
float lr_value_gradient(int e, vec3 p, out vec3 gradient)
{
    float v, dx, dy, dz;
    lr_eval_block(e, p, v, dx, dy, dz);
    gradient = vec3(dx, dy, dz);
    return v;
}
float lr_value(int e, vec3 p)
{
    vec3 g;
    return lr_value_gradient(e, p, g);
}
#else
// Vector value and Jacobian of element e at p: column j = d f / d x_j, so J[j][c] = d f_c / d x_j.
vec3 lr_value_jacobian(int e, vec3 p, out mat3 jacobian)
{
    vec3 v, dx, dy, dz;
    lr_eval_block(e, p, v, dx, dy, dz);
    jacobian = mat3(dx, dy, dz);
    return v;
}
// The magnitude (the scalar the volume techniques render) and its gradient J^T f / |f|.
float lr_value_gradient(int e, vec3 p, out vec3 gradient)
{
    mat3 J;
    vec3 v = lr_value_jacobian(e, p, J);
    float m = length(v);
    gradient = m > 0.0 ? vec3(dot(J[0], v), dot(J[1], v), dot(J[2], v)) / m : vec3(0.0);
    return m;
}
float lr_value(int e, vec3 p)
{
    mat3 J;
    return length(lr_value_jacobian(e, p, J));
}
#endif

#if LR_DOUBLE
struct lr_box_d { dvec4 lo; dvec4 hi; };
layout(std430, binding = 8) readonly buffer lr_boxes_d { lr_box_d lr_box_data_d[]; };
layout(std430, binding = 9) readonly buffer lr_coefs_d { double lr_coef_data_d[]; };
#if LR_DIM == 1
#define LR_TD double
#define LR_FETCH_D(i) lr_coef_data_d[i]
#else
#define LR_TD dvec3
#define LR_FETCH_D(i) dvec3(lr_coef_data_d[i], lr_coef_data_d[(i) + 1], lr_coef_data_d[(i) + 2])
#endif
LR_DECASTELJAU(lr_dc0_d, LR_O0, LR_TD, double)
LR_DECASTELJAU(lr_dc1_d, LR_O1, LR_TD, double)
LR_DECASTELJAU(lr_dc2_d, LR_O2, LR_TD, double)
LR_EVAL(lr_eval_block_d, LR_TD, double, dvec3, lr_box_data_d, LR_FETCH_D, lr_dc0_d, lr_dc1_d, lr_dc2_d)
#if LR_DIM == 1
double lr_value_gradient_d(int e, dvec3 p, out dvec3 gradient)
{
    double v, dx, dy, dz;
    lr_eval_block_d(e, p, v, dx, dy, dz);
    gradient = dvec3(dx, dy, dz);
    return v;
}
#else
dvec3 lr_value_jacobian_d(int e, dvec3 p, out dmat3 jacobian)
{
    dvec3 v, dx, dy, dz;
    lr_eval_block_d(e, p, v, dx, dy, dz);
    jacobian = dmat3(dx, dy, dz);
    return v;
}
#endif
#endif
