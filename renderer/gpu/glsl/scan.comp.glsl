// scan.comp.glsl — exclusive prefix sum of uints, the kernels of sl_gpu_scan
// (gpu/scan.c), in blocks of SCAN_BLOCK = 4096 values: each of the 256
// invocations sums 16 consecutive values in registers, one invocation scans
// the 256 totals in shared memory, and each invocation writes its 16 results.
// Two barriers per block: on llvmpipe (a work group runs as one CPU thread
// that switches between invocations at each barrier) that is what costs, not
// the serial 256-step loop (measured on 2 cores under load: a bin table of
// 2^22 + 1 entries by prefix sum, mostly this scan, took 36 ms, against
// 371 ms with the former 512-value Blelloch tree of 18 barriers per block). SCAN_PASS 1 scans each block of `scan_data` (each
// value first capped to u_cap; 0xFFFFFFFF = no cap) into `scan_out` and writes
// the block's total to `scan_sums`; the C side scans the block totals the same
// way (recursively) and SCAN_PASS 2 adds each block's scanned total to its
// elements. scan_data and scan_out may be the same buffer: every element is
// read and written by the same invocation, the read before the first barrier.
// Sums wrap modulo 2^32.
#define SCAN_PER_INVOCATION 16u
#define SCAN_BLOCK 4096u
layout(local_size_x = 256) in;

layout(std430, binding = 0) readonly buffer scan_in { uint scan_data[]; };
layout(std430, binding = 1) buffer scan_result { uint scan_out[]; };
layout(std430, binding = 2) buffer scan_block_sums { uint scan_sums[]; };
uniform uint u_n;
uniform uint u_cap;
uniform uint u_group_base;   // first block of this dispatch chunk (gpu/dispatch.c)

shared uint invocation_prefix[256];

void main()
{
    uint lid = gl_LocalInvocationID.x, block = u_group_base + gl_WorkGroupID.x;
    uint first = block * SCAN_BLOCK + lid * SCAN_PER_INVOCATION;
#if SCAN_PASS == 1
    uint prefix[SCAN_PER_INVOCATION];
    uint total = 0u;
    for (uint k = 0u; k < SCAN_PER_INVOCATION; k++) {
        uint i = first + k;
        prefix[k] = total;
        total += i < u_n ? min(scan_data[i], u_cap) : 0u;
    }
    invocation_prefix[lid] = total;
    barrier();
    if (lid == 0u) {
        uint sum = 0u;
        for (uint t = 0u; t < 256u; t++) {
            uint c = invocation_prefix[t];
            invocation_prefix[t] = sum;
            sum += c;
        }
        scan_sums[block] = sum;
    }
    barrier();
    uint offset = invocation_prefix[lid];
    for (uint k = 0u; k < SCAN_PER_INVOCATION; k++)
        if (first + k < u_n)
            scan_out[first + k] = offset + prefix[k];
#else
    uint offset = scan_sums[block];
    for (uint k = 0u; k < SCAN_PER_INVOCATION; k++)
        if (first + k < u_n)
            scan_out[first + k] += offset;
#endif
}
