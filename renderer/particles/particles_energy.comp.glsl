// particles_energy.comp.glsl — one redistribution step (the paper's sec.
// 4.1.2 III with Eq. 1-2; the energy of Meyer et al. as README.md states it).
//
// Reads the particles in bin order (pt_src, gathered) and the bin table
// start[b] (bin b holds [start[b], start[b+1])), writes the moved particles
// to pt_dst at the same index (a Jacobi step: every particle sees the
// others' old positions) and each work group's energy sum to
// pt_group_energy[gl_WorkGroupID.x] (a fixed binary tree: deterministic).
// Per alive particle i:
//   neighbours j: alive, in the 27 bins around i's, |p_i - p_j| < sigma and
//     on the same side (n_i . n_j > 0);
//   E_i = sum phi(d), phi(d) = cot(pi d / 2 sigma) + pi d / 2 sigma - pi/2,
//   F_i = sum psi(d) (p_i - p_j)/d, psi = (pi / 2 sigma) cot^2(pi d / 2 sigma),
//     d clamped below at 0.05 sigma; coincident pairs push apart along a
//     direction from a hash of their indices (antisymmetric);
//   lambda_i grows x1.25 while E_i does not rise, halves when it does;
//   step 1 (Eq. 1): move by lambda_i F_i projected onto the tangent plane,
//     at most sigma/4, clamped into the volume box (a surface may leave the
//     volume through a face: its particles slide along that face);
//   step 2 (Eq. 2): one Newton step back onto f = iso on the trilinear
//     field, at most sigma/2, staying in the box (particles_project.glsl).
// |grad f| below u_gmin or a non-finite value kills the particle.
layout(local_size_x = 256) in;

#include "particles/particles_common.glsl"
#include "particles/particles_field.glsl"
#include "particles/particles_bins.glsl"
#include "particles/particles_project.glsl"

layout(std430, binding = 1) readonly buffer pt_in { pt_particle pt_src[]; };
layout(std430, binding = 4) writeonly buffer pt_out { pt_particle pt_dst[]; };
layout(std430, binding = 5) readonly buffer pt_table { uint pt_start[]; };
layout(std430, binding = 6) writeonly buffer pt_energy { float pt_group_energy[]; };

uniform uint u_count;
uniform float u_sigma;
uniform float u_gmin;
uniform vec3 u_box_world;      // local-world extent of the volume box (voxel centres)

shared float partial[256];

// A unit vector orthogonal to n from the pair (lo, hi): the same for both
// members of the pair, so their pushes are opposite.
vec3 pair_direction(uint lo, uint hi, vec3 n)
{
    uint h = lo * 0x9E3779B1u ^ (hi + 0x7F4A7C15u) * 0x85EBCA77u;
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12;
    float angle = float(h & 0xFFFFu) * (2.0 * PT_PI / 65536.0);
    vec3 t1, t2;
    pt_tangent_basis(n, t1, t2);
    return cos(angle) * t1 + sin(angle) * t2;
}

void main()
{
    uint i = gl_GlobalInvocationID.x;
    float energy = 0.0;
    if (i < u_count) {
        pt_particle q = pt_src[i];
        if (pt_alive(q)) {
            vec3 p = q.p.xyz, n = q.n.xyz;
            float k = PT_PI / (2.0 * u_sigma), d_min = 0.05 * u_sigma;
            vec3 force = vec3(0.0);
            ivec3 b = pt_bin_of(p);
            for (int dz = -1; dz <= 1; dz++)
                for (int dy = -1; dy <= 1; dy++) {
                    ivec3 row = b + ivec3(0, dy, dz);
                    if (any(lessThan(row.yz, ivec2(0))) || any(greaterThanEqual(row.yz, u_bin_dims.yz)))
                        continue;
                    // The three bins of a row along x are contiguous in the table.
                    int x0 = max(b.x - 1, 0), x1 = min(b.x + 1, u_bin_dims.x - 1);
                    uint first = pt_start[pt_bin_index(ivec3(x0, row.yz))];
                    uint last = pt_start[pt_bin_index(ivec3(x1, row.yz)) + 1u];
                    for (uint j = first; j < last; j++) {
                        if (j == i)
                            continue;
                        pt_particle o = pt_src[j];
                        vec3 dv = p - o.p.xyz;
                        float d2 = dot(dv, dv);
                        if (d2 >= u_sigma * u_sigma || dot(n, o.n.xyz) <= 0.0)
                            continue;
                        float d = sqrt(d2);
                        vec3 dir;
                        if (d < 1e-6 * u_sigma)
                            dir = (i < j ? 1.0 : -1.0) * pair_direction(min(i, j), max(i, j), n);
                        else
                            dir = dv / d;
                        float x = k * max(d, d_min);
                        float c = cos(x) / sin(x);
                        energy += c + x - 0.5 * PT_PI;
                        force += k * c * c * dir;
                    }
                }
            float lambda = q.p.w;
            lambda = energy <= q.n.w ? min(1.25 * lambda, 0.5 * u_sigma * u_sigma)
                                     : max(0.5 * lambda, u_sigma * u_sigma / 1024.0);
            vec3 v = lambda * force;
            vec3 vt = v - n * dot(n, v);
            float vl = length(vt);
            if (vl > 0.25 * u_sigma)
                vt *= 0.25 * u_sigma / vl;
            // Positions stay in the volume box (a surface may leave through a face).
            vec3 p1 = clamp(p + vt, vec3(0.0), u_box_world);
            vec3 g;
            pt_particle r;
            bool ok = pt_reproject(p1, 0.5 * u_sigma, u_gmin, u_box_world, g);
            if (ok)
                pt_polish(p1, 0.5 * u_sigma, u_box_world);
            if (!ok) {
                r.p = vec4(p, PT_DEAD);
                r.n = q.n;
            } else {
                r.p = vec4(p1, lambda);
                r.n = vec4(-normalize(g), energy);
            }
            pt_dst[i] = r;
        } else {
            pt_dst[i] = q;
        }
    }
    partial[gl_LocalInvocationIndex] = energy;
    barrier();
    for (uint s = 128u; s > 0u; s >>= 1) {
        if (gl_LocalInvocationIndex < s)
            partial[gl_LocalInvocationIndex] += partial[gl_LocalInvocationIndex + s];
        barrier();
    }
    if (gl_LocalInvocationIndex == 0u)
        pt_group_energy[gl_WorkGroupID.x] = partial[0];
}
