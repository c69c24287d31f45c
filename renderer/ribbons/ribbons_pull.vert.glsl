// ribbons_pull.vert.glsl — programmable pulling (Neuhauser et al., Sec. 5, Fig. 7 top): no
// vertex attributes; vertex gl_VertexID (basevertex included, GL 4.5 11.1.3.9) is ring j =
// id % N of dataset point id / N, fetched from the std430 buffers ribbons_prep.c packs.
// Mantle and cap passes share this shader (the cap pass only changes the fragment normal).
#include "gpu/glsl/camera.glsl"
#include "ribbons/ribbons_ring.glsl"

layout(std430, binding = 1) readonly buffer sl_scalars { float scalars[]; };
layout(std430, binding = 2) readonly buffer rb_points { vec4 pos_radius[]; };
layout(std430, binding = 3) readonly buffer rb_frames { vec4 normal_twist[]; };
layout(std430, binding = 4) readonly buffer rb_tangents { vec4 tangent_slope[]; };

uniform uint u_sides;
uniform vec2 u_ring[32];          // (cos, sin) of 2 pi j / N, from double
uniform float u_radius;
uniform float u_radius_scale;
uniform float u_twist_scale;      // f
uniform int u_rotate;             // 1: helicity frame (n rotated by f R)

out vec3 v_position;
out vec3 v_centre;
out vec3 v_n;
out vec3 v_t;
out float v_r;
out float v_w;
out float v_twist;                // R
out float v_slope;                // dR/ds
out float v_scalar;

void main()
{
    uint point = uint(gl_VertexID) / u_sides;
    uint j = uint(gl_VertexID) % u_sides;
    vec4 P = pos_radius[point];
    vec4 F = normal_twist[point];
    vec4 T = tangent_slope[point];
    float r = P.w < 0.0 ? u_radius : P.w * u_radius_scale;
    vec3 n = u_rotate != 0 ? sl_ribbon_rotate(F.xyz, T.xyz, u_twist_scale * F.w) : F.xyz;
    vec3 b = cross(T.xyz, n);
    float w = sl_ribbon_w(P.xyz, r);
    vec3 p = sl_ribbon_place(P.xyz, n, b, u_ring[j], r, w);
    v_position = p;
    v_centre = P.xyz;
    v_n = n;
    v_t = T.xyz;
    v_r = r;
    v_w = w;
    v_twist = F.w;
    v_slope = T.w;
    v_scalar = scalars[point];
    gl_Position = sl_view_projection * vec4(p, 1.0);
}
