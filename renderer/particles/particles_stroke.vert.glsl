// particles_stroke.vert.glsl — hatch strokes (the paper's sec. 4.2.3): one
// screen-space quad of constant pixel width per stroke segment, 6 vertices
// pulled by gl_VertexID from the stroke buffer (particles_hatch.comp.glsl):
// quad q = (particle i, stroke s, segment k). A quad is culled (all its
// vertices off screen) when the particle is hidden (with hidden-surface
// removal: its id does not hold its pixel in the id target) or its tone asks
// for no such stroke. Tone: b = d = max(0, n.l), n facing the viewer, for
// dark ink (1 - d for light ink, which draws where the light is): b >=
// u_hatch_threshold no stroke, u_cross_threshold <= b < u_hatch_threshold the
// main stroke, below that main + cross. The quad covers the segment's
// capsule of radius u_half_width + 1 px (round joins by overlap, one pixel of
// coverage ramp); depth is the segment's, interpolated. Colour: the ink, or
// with curvature colouring the set's 2D transfer function at the (k1, k2)
// stored with the segment's first vertex (particles_tf2d.glsl).
#include "gpu/glsl/camera.glsl"
#include "particles/particles_record.glsl"
#include "particles/particles_tf2d.glsl"

layout(std430, binding = 6) readonly buffer pt_strokes { vec4 pt_vertex[]; };

uniform usampler2D u_ids;
uniform int u_hsr;
uniform vec3 u_light_world;      // unit, towards the light
uniform int u_ink_dark;
uniform vec3 u_ink;
uniform int u_segments;          // K
uniform int u_strokes;           // 1 or 2 per particle
uniform float u_half_width;      // px
uniform float u_hatch_threshold, u_cross_threshold;

noperspective out vec2 v_px;     // along (from the segment's start) and across, px
flat out float v_length;         // segment length, px
flat out vec3 v_color;

void cull()
{
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    v_px = vec2(0.0);
    v_length = 0.0;
    v_color = vec3(0.0);
}

vec2 window_of(vec4 clip)
{
    return (clip.xy / clip.w * 0.5 + 0.5) * sl_viewport.xy;
}

void main()
{
    int quad = gl_VertexID / 6, corner = gl_VertexID % 6;
    int per_particle = u_strokes * u_segments;
    int i = quad / per_particle, rest = quad % per_particle;
    int stroke = rest / u_segments, segment = rest % u_segments;
    pt_record r = pt_rec[i];
    vec3 p = pt_view_position(r);
    vec4 clip = sl_view_projection * vec4(p, 1.0);
    if (!(clip.w > 0.0)) {
        cull();
        return;
    }
    if (u_hsr != 0) {
        ivec2 px = ivec2(floor(window_of(clip)));
        if (any(lessThan(px, ivec2(0))) || any(greaterThanEqual(px, ivec2(sl_viewport.xy))) ||
            texelFetch(u_ids, px, 0).r != uint(i) + 1u) {
            cull();
            return;
        }
    }
    vec3 n = r.n_k1.xyz;
    if (dot(n, sl_eye.xyz - p) < 0.0)
        n = -n;
    float d = max(dot(n, u_light_world), 0.0);
    float b = u_ink_dark != 0 ? d : 1.0 - d;
    if (b >= u_hatch_threshold || (stroke == 1 && b >= u_cross_threshold)) {
        cull();
        return;
    }
    int base = (i * u_strokes + stroke) * (u_segments + 1) + segment;
    vec3 a = u_volume_offset + pt_vertex[base].xyz, c = u_volume_offset + pt_vertex[base + 1].xyz;
    vec4 ca = sl_view_projection * vec4(a, 1.0), cc = sl_view_projection * vec4(c, 1.0);
    if (!(ca.w > 0.0) || !(cc.w > 0.0) || a == c) {
        cull();
        return;
    }
    vec2 wa = window_of(ca), wc = window_of(cc);
    float len = length(wc - wa);
    vec2 along = len > 1e-4 ? (wc - wa) / len : vec2(1.0, 0.0);
    vec2 across = vec2(-along.y, along.x);
    float h = u_half_width + 1.0;
    // Corners: 0 (start, -), 1 (end, -), 2 (end, +), 0, 2, 3 (start, +).
    const int end_of[6] = int[6](0, 1, 1, 0, 1, 0);
    const float side_of[6] = float[6](-1.0, -1.0, 1.0, -1.0, 1.0, 1.0);
    int e = end_of[corner];
    float side = side_of[corner];
    vec4 ce = e == 0 ? ca : cc;
    vec2 w = (e == 0 ? wa - h * along : wc + h * along) + side * h * across;
    v_px = vec2(e == 0 ? -h : len + h, side * h);
    v_length = len;
    vec2 k = unpackHalf2x16(floatBitsToUint(pt_vertex[base].w));
    v_color = pt_curvature_color(u_ink, k.x, k.y);
    vec2 ndc = w / sl_viewport.xy * 2.0 - 1.0;
    gl_Position = vec4(ndc * ce.w, ce.z, ce.w);
}
