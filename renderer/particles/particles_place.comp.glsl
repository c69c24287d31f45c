// particles_place.comp.glsl — feature location (the paper's Algorithm 1).
//
// One invocation per lattice point r = s (i,j,k) in voxel coordinates
// (s = u_lattice_step voxels). Each tests its edges to r + s e_a (a = x, y, z)
// inside the grid with the half-open rule (f < iso) != (f_n < iso) on the
// trilinear field, refines the crossing by 8 bisections and a secant step
// and, with PT_EMIT 1, writes a particle there: id 3 lin(r) + a (the key of
// the deterministic order), normal -grad f/|grad f|, step lambda0. PT_EMIT 0
// only counts. Both variants see the same values, so the counts agree.
// One shared counter per work group and one global atomicAdd per group;
// the order of the emitted particles is not deterministic (the id sort after
// it is). Dispatched in chunks: u_first is the first lattice index, or with
// u_tiled the first entry of pt_tiles: one work group per listed tile of
// 4x4x4 lattice points (tile t = (x, y, z) packed x + tx (y + ty z)), the
// tiles whose voxels may straddle the isovalue (particles_system.c).
layout(local_size_x = 64) in;

#include "particles/particles_common.glsl"
#include "particles/particles_field.glsl"

layout(std430, binding = 0) buffer pt_counter { uint pt_count; };
#if PT_EMIT
layout(std430, binding = 1) writeonly buffer pt_out { pt_particle pt_emitted[]; };
layout(std430, binding = 2) writeonly buffer pt_keys_out { uint pt_keys[]; };
layout(std430, binding = 3) writeonly buffer pt_values_out { uint pt_values[]; };
uniform uint u_capacity;
#endif

uniform float u_iso;
uniform float u_lattice_step;
uniform ivec3 u_lattice_dims;
uniform uint u_first;
uniform uint u_total;
uniform bool u_tiled;
uniform uvec3 u_tile_dims;
layout(std430, binding = 4) readonly buffer pt_tile_list { uint pt_tiles[]; };
uniform float u_gmin;          // |grad f| (world) below this: emitted dead
uniform float u_lambda0;

shared uint group_count;
shared uint group_base;

float edge_value(vec3 r, vec3 e, float t)
{
    vec3 g;
    return pt_trilinear(r + t * e, g);
}

void main()
{
    if (gl_LocalInvocationIndex == 0u)
        group_count = 0u;
    barrier();

    uint lx = uint(u_lattice_dims.x), ly = uint(u_lattice_dims.y);
    uint lin;
    bool inside;
    ivec3 idx;
    if (u_tiled) {
        uint t = pt_tiles[u_first + gl_WorkGroupID.x], l = gl_LocalInvocationIndex;
        uvec3 tile = uvec3(t % u_tile_dims.x, (t / u_tile_dims.x) % u_tile_dims.y, t / (u_tile_dims.x * u_tile_dims.y));
        idx = ivec3(4u * tile + uvec3(l & 3u, (l >> 2) & 3u, l >> 4));
        inside = all(lessThan(idx, u_lattice_dims));
        lin = uint(idx.x) + lx * (uint(idx.y) + ly * uint(idx.z));
    } else {
        lin = u_first + gl_GlobalInvocationID.x;
        inside = lin < u_total;
        idx = ivec3(lin % lx, (lin / lx) % ly, lin / (lx * ly));
    }
    vec3 r = vec3(idx) * u_lattice_step;
    vec3 g0;
    float f0 = inside ? pt_trilinear(r, g0) : 0.0;
    bool crosses[3] = bool[3](false, false, false);
    float f1s[3] = float[3](0.0, 0.0, 0.0);
    uint mine = 0u;
    for (int a = 0; a < 3; a++) {
        if (!inside || idx[a] + 1 >= u_lattice_dims[a])
            continue;
        vec3 e = vec3(0.0);
        e[a] = u_lattice_step;
        vec3 g1;
        float f1 = pt_trilinear(r + e, g1);
        f1s[a] = f1;
        if (!pt_finite(f0) || !pt_finite(f1))
            continue;
        if ((f0 < u_iso) != (f1 < u_iso)) {
            crosses[a] = true;
            mine++;
        }
    }
    uint local_base = atomicAdd(group_count, mine);
    barrier();
    if (gl_LocalInvocationIndex == 0u)
        group_base = atomicAdd(pt_count, group_count);
    barrier();
#if PT_EMIT
    uint slot = group_base + local_base;
    for (int a = 0; a < 3; a++) {
        if (!crosses[a])
            continue;
        vec3 e = vec3(0.0);
        e[a] = u_lattice_step;
        // Bracket [lo, hi] with f(lo) and f(hi) on either side of iso.
        float lo = 0.0, hi = 1.0, flo = f0, fhi = f1s[a];
        bool lo_below = flo < u_iso;
        for (int k = 0; k < 8; k++) {
            float mid = 0.5 * (lo + hi);
            float fm = edge_value(r, e, mid);
            if ((fm < u_iso) == lo_below) {
                lo = mid;
                flo = fm;
            } else {
                hi = mid;
                fhi = fm;
            }
        }
        float t = fhi != flo ? lo + (u_iso - flo) / (fhi - flo) * (hi - lo) : 0.5 * (lo + hi);
        t = clamp(t, lo, hi);
        vec3 u = r + t * e;
        vec3 gu;
        pt_trilinear(u, gu);
        vec3 gw = pt_world_gradient(gu);
        float gl = length(gw);
        bool ok = gl >= u_gmin && pt_finite3(gw);
        if (slot < u_capacity) {
            pt_particle q;
            q.p = vec4(u * u_spacing, ok ? u_lambda0 : PT_DEAD);
            q.n = vec4(ok ? -gw / gl : vec3(0.0, 0.0, 1.0), uintBitsToFloat(0x7f800000u));
            pt_emitted[slot] = q;
            pt_keys[slot] = 3u * lin + uint(a);
            pt_values[slot] = slot;
        }
        slot++;
    }
#endif
}
