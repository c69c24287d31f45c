// ribbons_mesh.vert.glsl — vertex stage of `pipeline = mesh`: the static CPU mesh of
// ribbons_mesh.c (per vertex a copy of its point's three packed vec4, the point and the ring
// slot) placed by the same ribbons_vertex.glsl code as pulling, so width_ratio,
// min_thickness, min_pixels, radius and the helicity rotation stay uniforms here too.
#include "gpu/glsl/camera.glsl"
#include "ribbons/ribbons_vertex.glsl"

layout(std430, binding = 1) readonly buffer sl_scalars { float scalars[]; };

layout(location = 0) in vec4 a_pos_radius;
layout(location = 1) in vec4 a_normal_twist;
layout(location = 2) in vec4 a_tangent_slope;
layout(location = 3) in uvec2 a_point_slot;

void main()
{
    sl_ribbon_emit(sl_ribbon_point(a_pos_radius, a_normal_twist, a_tangent_slope, scalars[a_point_slot.x]),
                   u_ring[a_point_slot.y]);
}
