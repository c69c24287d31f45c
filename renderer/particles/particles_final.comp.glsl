// particles_final.comp.glsl — what the styles draw with, after the last
// redistribution step and the settle pass (particles_settle.comp.glsl): per
// particle (in bin order, with the bin table),
//   the B-spline normal n = -grad f/|grad f|, the principal curvatures
//   k1 >= k2 and the direction e1 of k1 (world units: 1/length), from the
//   64-tap tricubic B-spline (particles_field.glsl);
//   the distance to the nearest alive neighbour on the same side within the
//   27 bins (-1 when there is none), for the mean spacing the marks scale by.
// Record: x (local world, w = 1 alive / 0 dead), n + k1, e1 + k2. A particle
// whose B-spline gradient vanishes or is not finite keeps its trilinear normal
// and gets k1 = k2 = 0 (no curvature: reliability 0).
layout(local_size_x = 64) in;

#include "particles/particles_common.glsl"
#include "particles/particles_field.glsl"
#include "particles/particles_bins.glsl"

struct pt_record {
    vec4 x;
    vec4 n_k1;
    vec4 e1_k2;
};

layout(std430, binding = 1) readonly buffer pt_in { pt_particle pt_src[]; };
layout(std430, binding = 5) readonly buffer pt_table { uint pt_start[]; };
layout(std430, binding = 6) writeonly buffer pt_records { pt_record pt_out[]; };
layout(std430, binding = 7) writeonly buffer pt_nn { float pt_nearest[]; };

uniform uint u_count;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count)
        return;
    pt_particle q = pt_src[i];
    pt_record r;
    if (!pt_alive(q)) {
        r.x = vec4(q.p.xyz, 0.0);
        r.n_k1 = vec4(q.n.xyz, 0.0);
        r.e1_k2 = vec4(1.0, 0.0, 0.0, 0.0);
        pt_out[i] = r;
        pt_nearest[i] = -1.0;
        return;
    }
    vec3 p = q.p.xyz;
    vec3 gu;
    mat3 hu;
    pt_bspline(p / u_spacing, gu, hu);
    vec3 g = pt_world_gradient(gu);
    mat3 h = pt_world_hessian(hu);
    vec3 n = q.n.xyz, e1 = vec3(1.0, 0.0, 0.0);
    float k1 = 0.0, k2 = 0.0;
    float gl = length(g);
    if (gl > 0.0 && pt_finite(gl) && pt_finite3(h[0]) && pt_finite3(h[1]) && pt_finite3(h[2])) {
        pt_curvature(g, h, n, k1, k2, e1);
        if (!(pt_finite(k1) && pt_finite(k2) && pt_finite3(e1))) {
            n = q.n.xyz;
            k1 = k2 = 0.0;
            e1 = vec3(1.0, 0.0, 0.0);
        }
    }
    r.x = vec4(p, 1.0);
    r.n_k1 = vec4(n, k1);
    r.e1_k2 = vec4(e1, k2);
    pt_out[i] = r;

    float best = 3.0e38;
    ivec3 b = pt_bin_of(p);
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++) {
            ivec3 row = b + ivec3(0, dy, dz);
            if (any(lessThan(row.yz, ivec2(0))) || any(greaterThanEqual(row.yz, u_bin_dims.yz)))
                continue;
            int x0 = max(b.x - 1, 0), x1 = min(b.x + 1, u_bin_dims.x - 1);
            uint first = pt_start[pt_bin_index(ivec3(x0, row.yz))];
            uint last = pt_start[pt_bin_index(ivec3(x1, row.yz)) + 1u];
            for (uint j = first; j < last; j++) {
                if (j == i)
                    continue;
                pt_particle o = pt_src[j];
                if (dot(q.n.xyz, o.n.xyz) <= 0.0)
                    continue;
                vec3 dv = p - o.p.xyz;
                best = min(best, dot(dv, dv));
            }
        }
    pt_nearest[i] = best < 3.0e38 ? sqrt(best) : -1.0;
}
