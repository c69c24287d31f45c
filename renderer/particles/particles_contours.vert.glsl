// particles_contours.vert.glsl — one contour segment (instance) as a
// screen-space quad of constant width: 6 vertices (two triangles) around
// the projected segment, u_width / 2 + 1 px to each side and beyond each
// end (the round caps and the coverage ramp of particles_contours.frag.glsl).
// The end points move u_depth_bias (world) towards the eye first, so the
// line is not buried in the marks of the surface it outlines; the depth
// is the segment's, interpolated. A segment behind the eye is dropped.
#include "gpu/glsl/camera.glsl"
#include "particles/particles_contours.glsl"

layout(std430, binding = 2) readonly buffer pt_segments { pt_segment pt_seg[]; };

uniform float u_width;         // px
uniform float u_depth_bias;    // world

noperspective out vec2 v_local;  // px: along the segment from its start, across it
flat out float v_length;         // px

const vec2 corners[6] = vec2[6](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 0), vec2(1, 1), vec2(0, 1));

void main()
{
    pt_segment s = pt_seg[gl_InstanceID];
    vec3 a = s.a.xyz + u_depth_bias * normalize(sl_eye.xyz - s.a.xyz);
    vec3 b = s.b.xyz + u_depth_bias * normalize(sl_eye.xyz - s.b.xyz);
    vec4 ca = sl_view_projection * vec4(a, 1.0), cb = sl_view_projection * vec4(b, 1.0);
    v_length = 0.0;
    v_local = vec2(0.0);
    if (!(ca.w > 0.0 && cb.w > 0.0)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    vec2 half_size = 0.5 * sl_viewport.xy;
    vec2 sa = ca.xy / ca.w * half_size, sb = cb.xy / cb.w * half_size;
    vec2 d = sb - sa;
    float len = length(d);
    vec2 dir = len > 1e-6 ? d / len : vec2(1.0, 0.0);
    vec2 across_dir = vec2(-dir.y, dir.x);
    float ext = 0.5 * u_width + 1.0;
    vec2 q = corners[gl_VertexID];
    float along = q.x == 0.0 ? -ext : len + ext;
    float across = q.y == 0.0 ? -ext : ext;
    vec4 c = mix(ca, cb, len > 1e-6 ? clamp(along / len, 0.0, 1.0) : 0.0);
    vec2 spx = sa + dir * along + across_dir * across;
    gl_Position = vec4(spx / half_size * c.w, c.z, c.w);
    v_local = vec2(along, across);
    v_length = len;
}
