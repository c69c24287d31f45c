// lr_lookup_probe.comp.glsl — one lr_find_element per point: the GPU side of
// test_lr_lookup_gpu and bench-lr-lookup. Points: packed xyz floats
// (binding 0), results: int per point (binding 1). u_group_base: the chunk's
// first group (sl_gpu_dispatch_chunked).
layout(local_size_x = 64) in;

#include "lrspline/lr_lookup.glsl"

layout(std430, binding = 0) readonly buffer LrProbePoints { float lr_probe_points[]; };
layout(std430, binding = 1) writeonly buffer LrProbeResults { int lr_probe_results[]; };
uniform uint u_group_base;
uniform uint u_count;

void main()
{
    uint i = (gl_WorkGroupID.x + u_group_base) * 64u + gl_LocalInvocationID.x;
    if (i >= u_count)
        return;
    vec3 p = vec3(lr_probe_points[3u * i], lr_probe_points[3u * i + 1u], lr_probe_points[3u * i + 2u]);
    lr_probe_results[i] = lr_find_element(p);
}
