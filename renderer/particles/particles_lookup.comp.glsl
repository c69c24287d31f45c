// particles_lookup.comp.glsl — the kernels of pt_bin_table (particles_sort.c):
// start[b] = the first index i with sorted_keys[i] >= b, for b in [0, u_bins].
// PT_LOOKUP_STAGE 1 (prefix_sum, first half): one atomicAdd per key < u_bins
// into the zeroed start[] (the exclusive scan of gpu/scan.c then turns the
// counts into starts; key order does not matter). PT_LOOKUP_STAGE 2
// (binary_search, the paper's): one invocation per bin, lower_bound over the
// sorted keys. u_group_base: the dispatch chunk's first group (gpu/dispatch.c).
layout(local_size_x = 256) in;

layout(location = 0) uniform uint u_group_base;
layout(location = 1) uniform uint u_n;
layout(location = 2) uniform uint u_bins;

layout(std430, binding = 0) readonly buffer key_block { uint sorted_keys[]; };
layout(std430, binding = 1) buffer start_block { uint start[]; };

void main()
{
    uint i = (u_group_base + gl_WorkGroupID.x) * 256u + gl_LocalInvocationID.x;
#if PT_LOOKUP_STAGE == 1
    if (i < u_n && sorted_keys[i] < u_bins)
        atomicAdd(start[sorted_keys[i]], 1u);
#else
    if (i > u_bins)
        return;
    uint lo = 0u, hi = u_n;
    while (lo < hi) {
        uint mid = lo + ((hi - lo) >> 1u);
        if (sorted_keys[mid] < i)
            lo = mid + 1u;
        else
            hi = mid;
    }
    start[i] = lo;
#endif
}
