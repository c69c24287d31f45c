// tubes_hit.glsl — the pixel's ray against the sub-segment this fragment belongs to, and the
// shading of its hit (Russig et al. 3.2, "Intersection", "Shading"), shared by the one-pass
// shader (tubes.frag.glsl) and the two passes after the occluder pre-pass (tubes_depth.frag.glsl,
// tubes_shade.frag.glsl), so that all of them find bit-for-bit the same hits. The ray is rebuilt
// from gl_FragCoord exactly as core/sl_camera.h defines it and re-centred on the sub-segment's
// first control point, so that float error scales with the segment, not the scene.
#include "gpu/glsl/camera.glsl"
#include "gpu/glsl/lighting.glsl"
#include "gpu/glsl/colormap.glsl"
#include "tubes/tubes_intersect.glsl"

flat in vec3 g_b0, g_b1, g_b2;
flat in vec3 g_r;
flat in vec2 g_c;
flat in float g_cm;

#include "gpu/glsl/line_style.glsl"

struct tubes_hit {
    vec3 d;        // unit ray direction
    float l, t;    // ray distance and sub-segment parameter of the nearest entry
    float depth;   // reversed-Z depth: never in front of the raster depth (depth_less)
};

// The nearest entry beyond the near plane; false when the ray misses the sweep.
bool tubes_pixel_hit(out tubes_hit h)
{
    h.d = normalize(sl_ray_direction(gl_FragCoord.xy));
    vec3 o = sl_eye.xyz - g_b0;   // eye relative to the sub-segment
    vec3 q0 = -o, q1 = (g_b1 - g_b0) - o, q2 = (g_b2 - g_b0) - o;
    float df = dot(h.d, sl_forward.xyz);
    float l_min = sl_near.x / max(df, 1e-30);
    h.l = 0.0;
    h.t = 0.0;
    h.depth = 0.0;
    if (!tubes_intersect(q0, q1, q2, g_r, h.d, l_min, h.l, h.t))
        return false;
    h.depth = min(sl_near.x / (h.l * df), gl_FragCoord.z);
    return true;
}

// Lambert + Blinn-Phong with the normal hit - p(t), the colour the scalar spline through the colormap.
vec4 tubes_shade_hit(tubes_hit h)
{
    vec3 o = sl_eye.xyz - g_b0;
    vec3 q0 = -o, q1 = (g_b1 - g_b0) - o, q2 = (g_b2 - g_b0) - o;
    float s = 1.0 - h.t, t = h.t;
    vec3 centre = s * s * q0 + 2.0 * s * t * q1 + t * t * q2;
    vec3 n = h.l * h.d - centre;
    float nl = length(n);
    n = nl > 0.0 ? n / nl : -h.d;
    float scalar = s * s * g_c.x + 2.0 * s * t * g_cm + t * t * g_c.y;
    vec3 base = u_use_colormap != 0 ? sl_colormap(u_colormap, scalar, u_scalar_range) : u_color;
    vec3 light = normalize(u_light_eye.x * sl_right.xyz + u_light_eye.y * sl_up.xyz - u_light_eye.z * sl_forward.xyz);
    sl_material m = sl_material(u_material.x, u_material.y, u_material.z, u_material.w);
    return vec4(sl_shade(base, n, light, -h.d, m), 1.0);
}
