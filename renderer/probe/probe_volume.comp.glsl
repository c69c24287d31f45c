// probe_volume.comp.glsl — a scalar volume at points, read as volume_dvr reads it:
// volume/volume_sample.glsl's sl_volume_value (the texture unit's trilinear filter on the
// texture of renderer/volume, the data value by u_value_map). Input per point: its voxel
// coordinate (computed in double on the CPU and rounded, as volume_dvr's eye), inside the
// box. Output per point: vec4(value, 0, 0, 0). Dispatch ceil(u_count / 64) groups.
#include "volume/volume_sample.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 1) readonly buffer probe_in { vec4 probe_points[]; };
layout(std430, binding = 2) writeonly buffer probe_out { vec4 probe_result[]; };
uniform int u_count;

void main()
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_count)
        return;
    probe_result[i] = vec4(sl_volume_value(probe_points[i].xyz), 0.0, 0.0, 0.0);
}
