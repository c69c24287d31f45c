// particles_hatch.comp.glsl — the hatch strokes of one set (the paper's sec.
// 4.2.3; docs/particles_plan.md §1.8), one invocation per alive particle i:
//   direction s_i: fixed (u_mode 1): s' = the normalized projection of
//     u_direction into i's tangent plane (t1 of the basis where |P s| < 0.1);
//     curvature (u_mode 0): over the neighbours j within u_sigma on the same
//     side (i included), m_j = P_i k_j normalized (k_j the main principal
//     direction: that of the larger |kappa|), T = sum rho_j m_j m_j^T (2x2,
//     sign-free: k and -k are the same line), e = T's dominant eigenvector
//     with e.s' >= 0, w = sum rho_j / #j, s_i = normalize(w e + (1 - w) s');
//     s' where sum rho_j = 0;
//   cross c_i: s_i rotated about n_i by u_cross_angle;
//   trace: u_segments K segments of length u_step centred on the particle
//     (ceil(K/2) forward along +s, floor(K/2) backward along -s), the
//     direction projected into the B-spline tangent plane at each vertex,
//     each vertex moved back onto the trilinear surface by one Newton step
//     (capped at u_step/2); where the field is flat or not finite the last
//     vertex repeats. Per vertex: x (local world) and the B-spline (k1, k2)
//     as packHalf2x16 in the bits of w (for a curvature transfer function).
layout(local_size_x = 64) in;

#include "gpu/glsl/camera.glsl"
#include "particles/particles_record.glsl"
#include "particles/particles_field.glsl"
#include "particles/particles_project.glsl"
#include "particles/particles_bins.glsl"

layout(std430, binding = 5) readonly buffer pt_table { uint pt_start[]; };
layout(std430, binding = 6) writeonly buffer pt_strokes { vec4 pt_vertex[]; };

uniform uint u_count;
uniform int u_mode;            // 0 curvature, 1 fixed
uniform vec3 u_direction;      // s_T, world
uniform float u_step;          // segment length, world
uniform int u_segments;        // K
uniform int u_cross;           // 1: a cross stroke too
uniform float u_cross_angle;   // radians
uniform float u_eps;           // flat curvature, 1/world
uniform float u_sigma;         // smoothing radius, world
uniform vec3 u_box_world;
uniform float u_gmin;

vec3 fixed_direction(vec3 n, vec3 t1)
{
    vec3 s = u_direction - n * dot(n, u_direction);
    return length(s) < 0.1 * max(length(u_direction), 1e-30) ? t1 : normalize(s);
}

// The main principal direction of record r: e1 when |k1| >= |k2|, else e2.
vec3 main_direction(pt_record r)
{
    vec3 e1 = r.e1_k2.xyz;
    return abs(r.n_k1.w) >= abs(r.e1_k2.w) ? e1 : cross(r.n_k1.xyz, e1);
}

vec3 smoothed_direction(uint i, vec3 p, vec3 n, vec3 t1, vec3 t2, vec3 s_fixed)
{
    float t11 = 0.0, t12 = 0.0, t22 = 0.0, sum_rho = 0.0, count = 0.0;
    float s2 = u_sigma * u_sigma;
    ivec3 b = pt_bin_of(p);
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++) {
            ivec3 row = b + ivec3(0, dy, dz);
            if (any(lessThan(row.yz, ivec2(0))) || any(greaterThanEqual(row.yz, u_bin_dims.yz)))
                continue;
            int x0 = max(b.x - 1, 0), x1 = min(b.x + 1, u_bin_dims.x - 1);
            uint first = pt_start[pt_bin_index(ivec3(x0, row.yz))];
            uint last = min(pt_start[pt_bin_index(ivec3(x1, row.yz)) + 1u], u_count);
            for (uint j = first; j < last; j++) {
                pt_record o = pt_rec[j];
                vec3 dv = o.x.xyz - p;
                if (dot(dv, dv) > s2 || dot(n, o.n_k1.xyz) <= 0.0)
                    continue;
                count += 1.0;
                float rho = pt_reliability(o.n_k1.w, o.e1_k2.w, u_eps);
                vec3 k = main_direction(o);
                vec2 m = vec2(dot(k, t1), dot(k, t2));
                float ml = length(m);
                if (!(rho > 0.0) || !(ml > 1e-6))
                    continue;
                m /= ml;
                t11 += rho * m.x * m.x;
                t12 += rho * m.x * m.y;
                t22 += rho * m.y * m.y;
                sum_rho += rho;
            }
        }
    if (!(sum_rho > 0.0))
        return s_fixed;
    float theta = 0.5 * atan(2.0 * t12, t11 - t22);
    vec3 e = cos(theta) * t1 + sin(theta) * t2;
    if (dot(e, s_fixed) < 0.0)
        e = -e;
    float w = sum_rho / count;
    vec3 s = w * e + (1.0 - w) * s_fixed;
    return length(s) > 1e-6 ? normalize(s) : e;
}

// (k1, k2) and the unit B-spline normal at x; false where the field is flat
// or not finite.
bool surface_at(vec3 x, out vec3 n, out float k1, out float k2)
{
    vec3 gu;
    mat3 hu;
    pt_bspline(x / u_spacing, gu, hu);
    vec3 g = pt_world_gradient(gu);
    mat3 h = pt_world_hessian(hu);
    float gl = length(g);
    n = vec3(0.0);
    k1 = k2 = 0.0;
    if (!(gl > u_gmin) || !pt_finite(gl) || !pt_finite3(h[0]) || !pt_finite3(h[1]) || !pt_finite3(h[2]))
        return false;
    vec3 e1;
    pt_curvature(g, h, n, k1, k2, e1);
    if (!(pt_finite(k1) && pt_finite(k2))) {
        k1 = k2 = 0.0;
        n = -g / gl;
    }
    return true;
}

vec4 stroke_vertex(vec3 x, float k1, float k2)
{
    return vec4(x, uintBitsToFloat(packHalf2x16(vec2(k1, k2))));
}

// Half a stroke from the seed p (normal n) along +-dir: `steps` vertices
// written at base + centre + side * k, k = 1 .. steps.
void trace(uint base, int centre, int side, int steps, vec3 p, vec3 n, vec3 dir, vec4 seed)
{
    vec3 x = p, d = dir * float(side);
    vec4 last = seed;
    bool stopped = false;
    for (int k = 1; k <= steps; k++) {
        if (!stopped) {
            vec3 q = x + u_step * d;
            vec3 g;
            bool ok = pt_reproject(q, 0.5 * u_step, u_gmin, u_box_world, g);
            vec3 nq;
            float k1, k2;
            ok = ok && surface_at(q, nq, k1, k2);
            vec3 dq = d - nq * dot(nq, d);
            if (!ok || !(length(dq) > 1e-6) || any(lessThan(q, vec3(0.0))) || any(greaterThan(q, u_box_world))) {
                stopped = true;
            } else {
                dq = normalize(dq);
                if (dot(dq, d) < 0.0)
                    dq = -dq;
                x = q;
                d = dq;
                last = stroke_vertex(q, k1, k2);
            }
        }
        pt_vertex[base + uint(centre + side * k)] = last;
    }
}

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count)
        return;
    pt_record r = pt_rec[i];
    vec3 p = r.x.xyz, n = r.n_k1.xyz;
    vec3 t1, t2;
    pt_tangent_basis(n, t1, t2);
    vec3 s = fixed_direction(n, t1);
    if (u_mode == 0)
        s = smoothed_direction(i, p, n, t1, t2, s);
    int strokes = 1 + u_cross;
    int centre = u_segments / 2;
    vec4 seed = stroke_vertex(p, r.n_k1.w, r.e1_k2.w);
    for (int k = 0; k < strokes; k++) {
        vec3 dir = k == 0 ? s : cos(u_cross_angle) * s + sin(u_cross_angle) * cross(n, s);
        uint base = (i * uint(strokes) + uint(k)) * uint(u_segments + 1);
        pt_vertex[base + uint(centre)] = seed;
        trace(base, centre, 1, u_segments - centre, p, n, dir, seed);
        trace(base, centre, -1, centre, p, n, dir, seed);
    }
}
