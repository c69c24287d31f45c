// tubes_mesh.vert.glsl — places a swept-circle vertex: centre + offset * radius.
// The radius is the data's (per vertex) or the `radius` parameter when the
// data gives none (a_radius < 0), so a radius change does not rebuild the mesh.
#include "gpu/glsl/camera.glsl"

layout(location = 0) in vec3 a_centre;
layout(location = 1) in vec3 a_offset;   // unit direction from the centre line to the surface
layout(location = 2) in vec3 a_normal;   // unit surface normal (== a_offset on the mantle)
layout(location = 3) in float a_radius;  // < 0: use u_radius
layout(location = 4) in uint a_source;   // vertex index in the line set

layout(std430, binding = 1) readonly buffer sl_scalars { float scalars[]; };

uniform float u_radius;
uniform float u_radius_scale;

out vec3 v_position;
out vec3 v_normal;
out float v_scalar;

void main()
{
    float r = (a_radius < 0.0 ? u_radius : a_radius * u_radius_scale);
    vec3 p = a_centre + a_offset * r;
    v_position = p;
    v_normal = a_normal;
    v_scalar = scalars[a_source];
    gl_Position = sl_view_projection * vec4(p, 1.0);
}
