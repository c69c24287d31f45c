// volume_march.frag.glsl — one ray per pixel through a scalar volume: ray setup, the march
// (volume_march.glsl), output. The ray is clipped to the box (and clip box) in voxel
// coordinates and starts at the eye when inside.
// SL_FOCUS 0 (volume_dvr): writes the final colour C + (1 - A) background (blending off)
// and the depth: iso hit, composite where alpha first exceeds 0.5, else 0.
// SL_FOCUS 1 (focus + context, docs/particles_plan.md §1.11): the interval is also clipped
// to the sphere u_focus (world metric: t is the world distance along the unit direction in
// either space) and ended at the eye distance of u_opaque_depth (reversed-Z depth of marks
// drawn before, 0 = none); writes premultiplied (C, A) for blending (ONE,
// ONE_MINUS_SRC_ALPHA) over the target and the depth max(mark, marcher's). Pixels with an
// empty interval or nothing composited are discarded. Variants: volume_march.glsl's and
// SL_FOCUS 0/1 (no defaults: volume_march.c always defines all four).
#include "gpu/glsl/camera.glsl"
#include "volume/volume_march.glsl"

uniform vec3 u_eye_v;            // eye in voxel coordinates
uniform vec3 u_box_lo, u_box_hi; // voxel coordinates, clip box applied
#if SL_FOCUS
uniform vec4 u_focus;            // xyz: eye - sphere centre (world), w: radius (world)
uniform sampler2D u_opaque_depth; // the marks' reversed-Z depth per pixel (texelFetch, level 0)
#else
uniform vec3 u_background;
#endif

layout(location = 0) out vec4 o_color;

#if SL_FOCUS
// The ray eye + t d (d unit) against the sphere |p - c| = r, o = eye - c:
// (t_enter, t_exit), or an empty interval when it misses.
vec2 sl_march_ray_sphere(vec3 o, vec3 d, float r)
{
    float b = dot(o, d), c = dot(o, o) - r * r, disc = b * b - c;
    if (!(disc >= 0.0))
        return vec2(1.0, 0.0);
    float h = sqrt(disc);
    return vec2(-b - h, -b + h);
}
#endif

void main()
{
    vec3 d = normalize(sl_ray_direction(gl_FragCoord.xy));
    vec3 rd = d * u_inv_spacing;
    vec2 tb = sl_volume_ray_box(u_eye_v, sl_volume_safe_inverse(rd), u_box_lo, u_box_hi);
    float t0 = max(tb.x, 0.0), t1 = tb.y;
#if SL_FOCUS
    vec2 ts = sl_march_ray_sphere(u_focus.xyz, d, u_focus.w);
    t0 = max(t0, ts.x);
    t1 = min(t1, ts.y);
    float mark = texelFetch(u_opaque_depth, ivec2(gl_FragCoord.xy), 0).r;
    if (mark > 0.0)
        t1 = min(t1, sl_distance_of_depth(mark, d));
#endif
    if (!(t1 > t0))
        discard;
    sl_march_result r = sl_volume_march(u_eye_v, d, t0, t1);
    if (!r.covered)
        discard;
    float depth = r.depth_t >= 0.0 ? sl_depth_of(sl_eye.xyz + r.depth_t * d) : 0.0;
#if SL_FOCUS
    o_color = vec4(r.C, r.A);
    gl_FragDepth = max(mark, depth);
#else
    o_color = vec4(r.C + (1.0 - r.A) * u_background, 1.0);
    gl_FragDepth = depth;
#endif
}
