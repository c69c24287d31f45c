// ribbons_vertex.glsl — what every ribbons vertex stage (pulling and mesh vertex shaders, the
// geometry shader) hands the one fragment shader: a point's frame and widths (RibbonPoint,
// from the three packed vec4 of ribbons_prep.c: radius -1 = u_radius, the helicity rotation
// theta = f R, b = t x n, w' of ribbons_ring.glsl) and, per ring slot (cos, sin) of u_ring,
// the placed vertex with its varyings and gl_Position. Needs camera.glsl.
#include "ribbons/ribbons_ring.glsl"

uniform vec2 u_ring[32];          // (cos, sin) of 2 pi j / N, from double; flat: (0, -1), (0, 1)
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

struct RibbonPoint {
    vec3 x, n, b, t;
    float r, w, twist, slope, scalar;
};

RibbonPoint sl_ribbon_point(vec4 P, vec4 F, vec4 T, float scalar)
{
    RibbonPoint q;
    q.x = P.xyz;
    q.r = P.w < 0.0 ? u_radius : P.w * u_radius_scale;
    q.t = T.xyz;
    q.n = u_rotate != 0 ? sl_ribbon_rotate(F.xyz, T.xyz, u_twist_scale * F.w) : F.xyz;
    q.b = cross(T.xyz, q.n);
    q.w = sl_ribbon_w(P.xyz, q.r);
    q.twist = F.w;
    q.slope = T.w;
    q.scalar = scalar;
    return q;
}

// Writes the varyings and gl_Position of ring slot cs of q.
void sl_ribbon_emit(RibbonPoint q, vec2 cs)
{
    vec3 p = sl_ribbon_place(q.x, q.n, q.b, cs, q.r, q.w);
    v_position = p;
    v_centre = q.x;
    v_n = q.n;
    v_t = q.t;
    v_r = q.r;
    v_w = q.w;
    v_twist = q.twist;
    v_slope = q.slope;
    v_scalar = q.scalar;
    gl_Position = sl_view_projection * vec4(p, 1.0);
}
