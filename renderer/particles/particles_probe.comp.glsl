// particles_probe.comp.glsl — TEST PROBE, not used by the technique: runs the
// shipped functions of particles_field.glsl at given voxel coordinates so
// tests/render/particles/test_particles_probe.c can compare them with the
// double-precision references of tests/support/particles_reference.h.
// Per point i (u_count of them, voxel coordinates at pt_u[i].xyz):
//   out[5i+0] = (trilinear f, trilinear gradient per voxel)
//   out[5i+1] = (B-spline f, B-spline gradient per voxel)
//   out[5i+2..4] = the B-spline Hessian per voxel, columns 0..2
// and, from the world gradient and Hessian the probe is given instead
// (pt_g[i], pt_h[3i..3i+2]), curv[2i] = (k1, k2, 0, 0), curv[2i+1] = e1.
layout(local_size_x = 64) in;

#include "particles/particles_field.glsl"

layout(std430, binding = 0) readonly buffer pt_points { vec4 pt_u[]; };
layout(std430, binding = 1) writeonly buffer pt_results { vec4 pt_out[]; };
layout(std430, binding = 2) readonly buffer pt_gradients { vec4 pt_g[]; };
layout(std430, binding = 3) readonly buffer pt_hessians { vec4 pt_h[]; };
layout(std430, binding = 4) writeonly buffer pt_curvatures { vec4 pt_curv[]; };

uniform uint u_count;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count)
        return;
    vec3 u = pt_u[i].xyz;
    vec3 gt, gb;
    mat3 hb;
    float ft = pt_trilinear(u, gt);
    float fb = pt_bspline(u, gb, hb);
    pt_out[5u * i] = vec4(ft, gt);
    pt_out[5u * i + 1u] = vec4(fb, gb);
    pt_out[5u * i + 2u] = vec4(hb[0], 0.0);
    pt_out[5u * i + 3u] = vec4(hb[1], 0.0);
    pt_out[5u * i + 4u] = vec4(hb[2], 0.0);
    vec3 n, e1;
    float k1, k2;
    mat3 h = mat3(pt_h[3u * i].xyz, pt_h[3u * i + 1u].xyz, pt_h[3u * i + 2u].xyz);
    pt_curvature(pt_g[i].xyz, h, n, k1, k2, e1);
    pt_curv[2u * i] = vec4(k1, k2, 0.0, 0.0);
    pt_curv[2u * i + 1u] = vec4(e1, 0.0);
}
