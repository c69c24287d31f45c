// particles_bins.comp.glsl — the bin keys of a redistribution step and the
// gather into bin order (the paper's sec. 4.1.2 steps I-II, around the sort).
//
// PT_PASS 0 (keys): per particle i of u_count, key = its bin (a regular grid
// of cube bins of side u_bin_size over the volume box, positions clamped into
// the edge bins) or u_bins for a dead particle, value = i.
// PT_PASS 1 (gather): out[j] = in[values[j]], so the energy pass reads the
// particles of one bin contiguously.
layout(local_size_x = 256) in;

#include "particles/particles_common.glsl"
#include "particles/particles_bins.glsl"

layout(std430, binding = 1) readonly buffer pt_in { pt_particle pt_src[]; };
layout(std430, binding = 2) buffer pt_keys_buf { uint pt_keys[]; };
layout(std430, binding = 3) buffer pt_values_buf { uint pt_values[]; };
#if PT_PASS == 1
layout(std430, binding = 4) writeonly buffer pt_out { pt_particle pt_dst[]; };
#endif

uniform uint u_count;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count)
        return;
#if PT_PASS == 0
    pt_particle q = pt_src[i];
    pt_keys[i] = pt_alive(q) ? pt_bin_index(pt_bin_of(q.p.xyz)) : u_bins;
    pt_values[i] = i;
#else
    pt_dst[i] = pt_src[pt_values[i]];
#endif
}
