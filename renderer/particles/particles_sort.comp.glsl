// particles_sort.comp.glsl — the kernels of pt_sort_pairs (particles_sort.c):
// an LSD radix sort of (key, value) u32 pairs with 4-bit digits and a bitonic
// sort of the pairs as (key, value) uvec2s. PT_SORT_STAGE selects one kernel:
//  1 radix histogram: per work group of 1024 keys, the count of each digit
//    (key >> u_shift) & 15 → radix_hist[digit * u_groups + group];
//  2 radix scatter: after the exclusive scan of radix_hist (digit-major, so it
//    holds each (digit, group)'s first output slot), each key goes to that slot
//    plus its rank among the equal digits before it in the group: stable;
//  3 bitonic local: a block of 1024 pairs in shared memory, either the whole
//    network up to k = 1024 (u_k == 0) or the stages j = 512..1 of level u_k;
//    bit 0 of u_flags reads the caller's keys/values (padding past u_n with
//    0xFFFFFFFF pairs), bit 1 writes the first u_n pairs back to them;
//  4 bitonic global: one compare-exchange of level u_k at distance u_j >= 1024.
// Every kernel adds u_group_base (dispatch chunk, gpu/dispatch.c) to its group.
#define RADIX_DIGITS 16u
#define RADIX_KEYS_PER_INVOCATION 4u
#define RADIX_GROUP_KEYS 1024u
#define BITONIC_BLOCK 1024u

layout(location = 0) uniform uint u_group_base;
layout(location = 1) uniform uint u_n;
layout(location = 2) uniform uint u_shift_or_k;  // radix: digit shift; bitonic: level k
layout(location = 3) uniform uint u_groups_or_j; // radix: work groups in all; bitonic: distance j
layout(location = 4) uniform uint u_flags;       // bitonic local: 1 read input, 2 write output

#if PT_SORT_STAGE == 1 || PT_SORT_STAGE == 2
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer src_key_block { uint src_keys[]; };
layout(std430, binding = 1) readonly buffer src_value_block { uint src_values[]; };
layout(std430, binding = 2) writeonly buffer dst_key_block { uint dst_keys[]; };
layout(std430, binding = 3) writeonly buffer dst_value_block { uint dst_values[]; };
layout(std430, binding = 4) buffer radix_hist_block { uint radix_hist[]; };
#else
layout(local_size_x = 512) in;
layout(std430, binding = 0) buffer key_block { uint keys[]; };
layout(std430, binding = 1) buffer value_block { uint values[]; };
layout(std430, binding = 5) buffer pair_block { uvec2 pairs[]; };
#endif

#if PT_SORT_STAGE == 1
shared uint digit_count[RADIX_DIGITS];

void main()
{
    uint lid = gl_LocalInvocationID.x, group = u_group_base + gl_WorkGroupID.x;
    if (lid < RADIX_DIGITS)
        digit_count[lid] = 0u;
    barrier();
    uint first = group * RADIX_GROUP_KEYS + lid * RADIX_KEYS_PER_INVOCATION;
    for (uint j = 0u; j < RADIX_KEYS_PER_INVOCATION; j++)
        if (first + j < u_n)
            atomicAdd(digit_count[(src_keys[first + j] >> u_shift_or_k) & 15u], 1u);
    barrier();
    if (lid < RADIX_DIGITS)
        radix_hist[lid * u_groups_or_j + group] = digit_count[lid];
}

#elif PT_SORT_STAGE == 2
// Per invocation, 16 digit counters packed two per uint (16 bits each: a group
// holds 1024 keys, so no half overflows and packed sums carry nothing).
shared uint packed_prefix[8u * 256u];
shared uint digit_base[RADIX_DIGITS];

void main()
{
    uint lid = gl_LocalInvocationID.x, group = u_group_base + gl_WorkGroupID.x;
    uint first = group * RADIX_GROUP_KEYS + lid * RADIX_KEYS_PER_INVOCATION;
    uint key[RADIX_KEYS_PER_INVOCATION], rank_in_invocation[RADIX_KEYS_PER_INVOCATION];
    uint counts[8] = uint[8](0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u);
    for (uint j = 0u; j < RADIX_KEYS_PER_INVOCATION; j++) {
        key[j] = first + j < u_n ? src_keys[first + j] : 0u;
        uint digit = (key[j] >> u_shift_or_k) & 15u, half_shift = (digit & 1u) * 16u;
        rank_in_invocation[j] = (counts[digit >> 1u] >> half_shift) & 0xFFFFu;
        if (first + j < u_n)
            counts[digit >> 1u] += 1u << half_shift;
    }
    for (uint r = 0u; r < 8u; r++)
        packed_prefix[r * 256u + lid] = counts[r];
    if (lid < RADIX_DIGITS)
        digit_base[lid] = radix_hist[lid * u_groups_or_j + group];
    barrier();
    // Exclusive scan over the invocations, one row of packed counters per
    // invocation 0..7: serial, but the 8 rows run side by side in one SIMD
    // vector on llvmpipe, and it costs 2 barriers instead of a tree's 16.
    if (lid < 8u) {
        uint sum = 0u;
        for (uint t = 0u; t < 256u; t++) {
            uint c = packed_prefix[lid * 256u + t];
            packed_prefix[lid * 256u + t] = sum;
            sum += c;
        }
    }
    barrier();
    for (uint j = 0u; j < RADIX_KEYS_PER_INVOCATION; j++) {
        if (first + j >= u_n)
            break;
        uint digit = (key[j] >> u_shift_or_k) & 15u;
        uint before = (packed_prefix[(digit >> 1u) * 256u + lid] >> ((digit & 1u) * 16u)) & 0xFFFFu;
        uint slot = digit_base[digit] + before + rank_in_invocation[j];
        dst_keys[slot] = key[j];
        dst_values[slot] = src_values[first + j];
    }
}

#elif PT_SORT_STAGE == 3
shared uvec2 block[BITONIC_BLOCK];

bool after(uvec2 a, uvec2 b) { return a.x > b.x || (a.x == b.x && a.y > b.y); }

// Stage (k, j) on the pair of this invocation; `base` is the block's first index.
void compare_exchange(uint base, uint k, uint j)
{
    uint p = gl_LocalInvocationID.x;
    uint i = ((p & ~(j - 1u)) << 1u) | (p & (j - 1u)), l = i + j;
    uvec2 a = block[i], b = block[l];
    bool ascending = ((base + i) & k) == 0u;
    if (after(a, b) == ascending) {
        block[i] = b;
        block[l] = a;
    }
}

void main()
{
    uint lid = gl_LocalInvocationID.x, base = (u_group_base + gl_WorkGroupID.x) * BITONIC_BLOCK;
    for (uint e = lid; e < BITONIC_BLOCK; e += 512u) {
        uint g = base + e;
        if ((u_flags & 1u) != 0u)
            block[e] = g < u_n ? uvec2(keys[g], values[g]) : uvec2(0xFFFFFFFFu);
        else
            block[e] = pairs[g];
    }
    if (u_shift_or_k == 0u) {
        for (uint k = 2u; k <= BITONIC_BLOCK; k <<= 1u)
            for (uint j = k >> 1u; j > 0u; j >>= 1u) {
                barrier();
                compare_exchange(base, k, j);
            }
    } else {
        for (uint j = BITONIC_BLOCK >> 1u; j > 0u; j >>= 1u) {
            barrier();
            compare_exchange(base, u_shift_or_k, j);
        }
    }
    barrier();
    for (uint e = lid; e < BITONIC_BLOCK; e += 512u) {
        uint g = base + e;
        if ((u_flags & 2u) == 0u) {
            pairs[g] = block[e];
        } else if (g < u_n) {
            keys[g] = block[e].x;
            values[g] = block[e].y;
        }
    }
}

#elif PT_SORT_STAGE == 4
bool after(uvec2 a, uvec2 b) { return a.x > b.x || (a.x == b.x && a.y > b.y); }

void main()
{
    uint p = (u_group_base + gl_WorkGroupID.x) * 512u + gl_LocalInvocationID.x;
    uint j = u_groups_or_j, k = u_shift_or_k;
    uint i = ((p & ~(j - 1u)) << 1u) | (p & (j - 1u)), l = i + j;
    uvec2 a = pairs[i], b = pairs[l];
    if (after(a, b) == ((i & k) == 0u)) {
        pairs[i] = b;
        pairs[l] = a;
    }
}
#endif
