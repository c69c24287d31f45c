// probe_vectors.comp.glsl — a regular vector field at world points, read as the streamline
// integrator reads it in single precision: flow/flow_field_regular.glsl's field() (texelFetch
// trilinear on flow's RGBA32F texture, the CPU's order of operations). Input per point: its
// world position inside the domain. Output per point: vec4(vx, vy, vz, 0). Dispatch
// ceil(u_count / 64) groups.
#define SL_PREC 0
#include "flow/flow_real.glsl"
#include "flow/flow_field_regular.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 1) readonly buffer probe_in { vec4 probe_points[]; };
layout(std430, binding = 2) writeonly buffer probe_out { vec4 probe_result[]; };
uniform int u_count;

void main()
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_count)
        return;
    probe_result[i] = vec4(field(probe_points[i].xyz), 0.0);
}
