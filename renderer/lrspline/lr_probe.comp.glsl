// lr_probe.comp.glsl — evaluates an LR-spline volume at a list of points on the GPU (tests
// and probes): per point the element found by lr_find_element, then the value and gradient
// (magnitude and its gradient for vectors; with LR_DIM 3 also the vector and Jacobian)
// from the Bézier block, in single precision, or in double with LR_DOUBLE 1.
// Output per point (std430, LR_PROBE_STRIDE = 20 floats): [0] element (as float, -1
// outside), [1] value, [2..4] gradient, [5..7] vector value, [8 + 3j + c] d f_c / d x_j.
// The double variant writes doubles: [1..4] (scalar) or [5..16] (vector). Dispatch: ceil(count / 64) groups.
#include "lrspline/lr_find.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 1) readonly buffer lr_probe_in { vec4 lr_probe_points[]; };
#if LR_DOUBLE
#define LR_OUT double
#else
#define LR_OUT float
#endif
layout(std430, binding = 2) writeonly buffer lr_probe_out { LR_OUT lr_probe_result[]; };
uniform int u_count;

void main()
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_count)
        return;
    vec3 p = lr_probe_points[i].xyz;
    int e = lr_find_element(p);
    int o = i * 20;
    for (int k = 0; k < 20; k++)
        lr_probe_result[o + k] = LR_OUT(0.0);
    lr_probe_result[o] = LR_OUT(e);
    if (e < 0)
        return;
#if LR_DOUBLE
#if LR_DIM == 1
    dvec3 gd;
    double vd = lr_value_gradient_d(e, dvec3(p), gd);
    lr_probe_result[o + 1] = vd;
    lr_probe_result[o + 2] = gd.x;
    lr_probe_result[o + 3] = gd.y;
    lr_probe_result[o + 4] = gd.z;
#else
    dmat3 Jd;
    dvec3 fd = lr_value_jacobian_d(e, dvec3(p), Jd);
    for (int c = 0; c < 3; c++) {
        lr_probe_result[o + 5 + c] = fd[c];
        for (int j = 0; j < 3; j++)
            lr_probe_result[o + 8 + j * 3 + c] = Jd[j][c];
    }
#endif
#else
    vec3 g;
    float v = lr_value_gradient(e, p, g);
    lr_probe_result[o + 1] = v;
    lr_probe_result[o + 2] = g.x;
    lr_probe_result[o + 3] = g.y;
    lr_probe_result[o + 4] = g.z;
#if LR_DIM == 3
    mat3 J;
    vec3 f = lr_value_jacobian(e, p, J);
    for (int c = 0; c < 3; c++) {
        lr_probe_result[o + 5 + c] = f[c];
        for (int j = 0; j < 3; j++)
            lr_probe_result[o + 8 + j * 3 + c] = J[j][c];
    }
#endif
#endif
}
