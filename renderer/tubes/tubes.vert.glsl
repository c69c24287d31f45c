// tubes.vert.glsl — pass-through of one Hermite node (Russig et al. 3.2), with the radius resolved:
// the data's radius and derivative times radius_scale, or the `radius` parameter (derivative 0).
layout(location = 0) in vec4 a_position_radius;   // p.xyz relative to the dataset origin, r
layout(location = 1) in vec4 a_tangent_dradius;   // dp/dt, dr/dt over one segment
layout(location = 2) in vec2 a_scalar;            // c, dc/dt

uniform float u_radius;
uniform float u_radius_scale;
uniform int u_data_radii;

out vec4 v_position_radius;
out vec4 v_tangent_dradius;
out vec2 v_scalar;

void main()
{
    float r = u_data_radii != 0 ? a_position_radius.w * u_radius_scale : u_radius;
    float dr = u_data_radii != 0 ? a_tangent_dradius.w * u_radius_scale : 0.0;
    v_position_radius = vec4(a_position_radius.xyz, r);
    v_tangent_dradius = vec4(a_tangent_dradius.xyz, dr);
    v_scalar = a_scalar;
}
