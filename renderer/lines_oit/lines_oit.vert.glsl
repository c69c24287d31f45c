// lines_oit.vert.glsl — a vertex of the swept tube mesh (lines/sl_tube_mesh.h):
// centre + unit offset * radius (the `radius` parameter for every tube).
#include "gpu/glsl/camera.glsl"

layout(location = 0) in vec3 a_centre;
layout(location = 1) in vec3 a_offset;
layout(location = 2) in vec3 a_normal;
layout(location = 4) in uint a_source;

layout(std430, binding = 1) readonly buffer sl_oit_scalars { float oit_scalars[]; };

uniform float u_radius;

out vec3 v_position;
out vec3 v_normal;
out float v_scalar;

void main()
{
    vec3 p = a_centre + a_offset * u_radius;
    v_position = p;
    v_normal = a_normal;
    v_scalar = oit_scalars[a_source];
    gl_Position = sl_view_projection * vec4(p, 1.0);
}
