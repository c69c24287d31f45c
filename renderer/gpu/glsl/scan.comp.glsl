// scan.comp.glsl — exclusive prefix sum of uints, the kernels of sl_gpu_scan
// (gpu/scan.c): blocks of 512 values scanned in shared memory (Blelloch
// up-sweep / down-sweep). SCAN_PASS 1 scans each block of `scan_data` (each
// value first capped to u_cap; 0xFFFFFFFF = no cap) into `scan_out` and
// writes the block's total to `scan_sums`; the C side scans the block totals
// the same way (recursively) and SCAN_PASS 2 adds each block's scanned total
// to its elements. scan_data and scan_out may be the same buffer: every
// element is read and written by the same invocation, the read before the
// block's first barrier. Sums wrap modulo 2^32.
layout(local_size_x = 256) in;

layout(std430, binding = 0) readonly buffer scan_in { uint scan_data[]; };
layout(std430, binding = 1) buffer scan_result { uint scan_out[]; };
layout(std430, binding = 2) buffer scan_block_sums { uint scan_sums[]; };
uniform uint u_n;
uniform uint u_cap;
uniform uint u_group_base;   // first block of this dispatch chunk (scan.c: dispatch_chunked)

shared uint tmp[512];

void main()
{
    uint lid = gl_LocalInvocationID.x, block = u_group_base + gl_WorkGroupID.x;
    uint base = block * 512u;
#if SCAN_PASS == 1
    for (uint k = 0u; k < 2u; k++) {
        uint i = base + lid + k * 256u;
        tmp[lid + k * 256u] = i < u_n ? min(scan_data[i], u_cap) : 0u;
    }
    uint offset = 1u;
    for (uint d = 256u; d > 0u; d >>= 1u) {
        barrier();
        if (lid < d) {
            uint ai = offset * (2u * lid + 1u) - 1u, bi = offset * (2u * lid + 2u) - 1u;
            tmp[bi] += tmp[ai];
        }
        offset <<= 1u;
    }
    barrier();
    if (lid == 0u) {
        scan_sums[block] = tmp[511];
        tmp[511] = 0u;
    }
    for (uint d = 1u; d < 512u; d <<= 1u) {
        offset >>= 1u;
        barrier();
        if (lid < d) {
            uint ai = offset * (2u * lid + 1u) - 1u, bi = offset * (2u * lid + 2u) - 1u;
            uint t = tmp[ai];
            tmp[ai] = tmp[bi];
            tmp[bi] += t;
        }
    }
    barrier();
    for (uint k = 0u; k < 2u; k++) {
        uint i = base + lid + k * 256u;
        if (i < u_n)
            scan_out[i] = tmp[lid + k * 256u];
    }
#else
    for (uint k = 0u; k < 2u; k++) {
        uint i = base + lid + k * 256u;
        if (i < u_n)
            scan_out[i] += scan_sums[block];
    }
#endif
}
