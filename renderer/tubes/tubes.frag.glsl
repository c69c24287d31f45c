// tubes.frag.glsl — casts the pixel's ray at one quadratic sub-segment's sphere sweep, keeps
// the nearest entry beyond the near plane, writes its depth and shades it with Lambert +
// Blinn-Phong, the normal being hit - p(t) and the colour the scalar spline through a
// colormap (Russig et al. 3.2, "Intersection", "Shading"). The ray is rebuilt from
// gl_FragCoord exactly as core/sl_camera.h defines it, and re-centred on the sub-segment's
// first control point so that float error scales with the segment, not the scene.
#include "gpu/glsl/camera.glsl"
#include "gpu/glsl/lighting.glsl"
#include "gpu/glsl/colormap.glsl"
#include "tubes/tubes_intersect.glsl"

flat in vec3 g_b0, g_b1, g_b2;
flat in vec3 g_r;
flat in vec2 g_c;
flat in float g_cm;

uniform sampler2D u_colormap;
uniform vec2 u_scalar_range;
uniform int u_use_colormap;
uniform vec3 u_color;
uniform vec3 u_light_eye;
uniform vec4 u_material;

layout(depth_less) out float gl_FragDepth;
layout(location = 0) out vec4 o_color;

void main()
{
    vec3 d = normalize(sl_ray_direction(gl_FragCoord.xy));
    vec3 o = sl_eye.xyz - g_b0;   // eye relative to the sub-segment
    vec3 q0 = -o, q1 = (g_b1 - g_b0) - o, q2 = (g_b2 - g_b0) - o;
    float df = dot(d, sl_forward.xyz);
    float l_min = sl_near.x / max(df, 1e-30);
    float l, t;
    if (!tubes_intersect(q0, q1, q2, g_r, d, l_min, l, t))
        discard;
    float s = 1.0 - t;
    vec3 centre = s * s * q0 + 2.0 * s * t * q1 + t * t * q2;
    vec3 n = l * d - centre;
    float nl = length(n);
    n = nl > 0.0 ? n / nl : -d;
    float scalar = s * s * g_c.x + 2.0 * s * t * g_cm + t * t * g_c.y;
    vec3 base = u_use_colormap != 0 ? sl_colormap(u_colormap, scalar, u_scalar_range) : u_color;
    vec3 light = normalize(u_light_eye.x * sl_right.xyz + u_light_eye.y * sl_up.xyz - u_light_eye.z * sl_forward.xyz);
    sl_material m = sl_material(u_material.x, u_material.y, u_material.z, u_material.w);
    o_color = vec4(sl_shade(base, n, light, -d, m), 1.0);
    gl_FragDepth = min(sl_near.x / (l * df), gl_FragCoord.z);
}
