// ribbons_probe.comp.glsl — a test probe, not part of any frame: runs the halo functions
// of ribbons_halo.glsl on buffers of cases, so tests/unit/test_ribbons_halo.c checks the
// shader code itself against the CPU reference (tests/support/ribbons_reference.h).
// and the twist-line functions of ribbons_twist.glsl. Case k: in_camera[k] = (c.xyz, w),
// in_point[k] = (p.xy, -, -), in_twist[k] = (a, fw, k, w_r) with in_point[k].z the slope;
// out_points[k] = (p_max.xy, p_max2.xy), out_lambda[k] = (found ? 1 : 0, lambda, twist
// width along phi, twist cover).
#include "ribbons/ribbons_halo.glsl"
#include "ribbons/ribbons_twist.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer probe_camera { vec4 in_camera[]; };
layout(std430, binding = 1) readonly buffer probe_point { vec4 in_point[]; };
layout(std430, binding = 2) writeonly buffer probe_points { vec4 out_points[]; };
layout(std430, binding = 3) writeonly buffer probe_lambda { vec4 out_lambda[]; };
layout(std430, binding = 4) readonly buffer probe_twist { vec4 in_twist[]; };

uniform uint u_count;

void main()
{
    uint k = gl_GlobalInvocationID.x;
    if (k >= u_count)
        return;
    vec4 cw = in_camera[k];
    vec2 a, b;
    bool found = sl_ribbon_silhouette(cw.xyz, cw.w, a, b);
    float lambda = found ? sl_ribbon_halo_lambda(in_point[k].xy, cw.xyz, cw.w, a, b) : 0.0;
    vec4 tw = in_twist[k];
    float width = sl_ribbon_twist_width(tw.w, in_point[k].z);
    float cover = sl_ribbon_twist_cover(tw.x, tw.y, max(int(tw.z), 1), width);
    out_points[k] = vec4(a, b);
    out_lambda[k] = vec4(found ? 1.0 : 0.0, lambda, width, cover);
}
