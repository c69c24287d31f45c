// tubes.geom.glsl — one Hermite segment in, two quadratic sub-segments out, each as the
// camera-facing faces of its tight oriented bounding box (Russig et al. 3.2, "Segment
// subdivision" and "Silhouettes"). Frame: x along b3 - b1, y the tangent b2 - b1 projected
// off x (any orthogonal vector when collinear), z = x cross y; extents from the analytic
// extrema of q -+ r of both sign combinations, so negative radius splines stay covered.
// Only faces whose plane has the eye outside are emitted (at most 3, each pixel once); when
// the eye is inside a box, or the near plane cuts it (its eye-facing faces would be clipped
// where rays enter), one full-screen quad at the near depth is emitted instead, so the
// fragment depth never exceeds the raster depth (layout(depth_less) holds).
#include "gpu/glsl/camera.glsl"

layout(lines) in;
layout(triangle_strip, max_vertices = 24) out;

in vec4 v_position_radius[];
in vec4 v_tangent_dradius[];
in vec2 v_scalar[];

uniform int u_frustum_cull;
uniform float u_rect_pixels; // small_box_pixels: boxes spanning at most this many pixels become one rectangle

flat out vec3 g_b0, g_b1, g_b2; // Bezier control points of the sub-segment (relative to origin)
flat out vec3 g_r;              // Bezier controls of the radius
flat out vec2 g_c;              // colour scalar at the sub-segment's ends (linear in t for a
                                // quadratic whose middle control is the mean, else see g_cm)
flat out float g_cm;            // middle colour control

// Min and max over t in [0,1] of the quadratic Bezier with controls f0, f1, f2.
vec2 bezier_range(float f0, float f1, float f2)
{
    vec2 m = vec2(min(f0, f2), max(f0, f2));
    float den = f0 - 2.0 * f1 + f2;
    if (den != 0.0) {
        float t = (f0 - f1) / den;
        if (t > 0.0 && t < 1.0) {
            float s = 1.0 - t;
            float v = s * s * f0 + 2.0 * s * t * f1 + t * t * f2;
            m = vec2(min(m.x, v), max(m.y, v));
        }
    }
    return m;
}

vec3 any_orthogonal(vec3 x)
{
    vec3 a = abs(x.x) < 0.57 ? vec3(1, 0, 0) : (abs(x.y) < 0.57 ? vec3(0, 1, 0) : vec3(0, 0, 1));
    return normalize(cross(x, a));
}

void emit_vertex(vec3 p, vec3 b0, vec3 b1, vec3 b2, vec3 r, vec3 c)
{
    gl_Position = sl_view_projection * vec4(p, 1.0);
    g_b0 = b0; g_b1 = b1; g_b2 = b2; g_r = r; g_c = c.xz; g_cm = c.y;
    EmitVertex();
}

void emit_screen(vec3 b0, vec3 b1, vec3 b2, vec3 r, vec3 c)
{
    const vec2 q[4] = vec2[4](vec2(-1, -1), vec2(1, -1), vec2(-1, 1), vec2(1, 1));
    for (int i = 0; i < 4; i++) {
        gl_Position = vec4(q[i], 1.0, 1.0);
        g_b0 = b0; g_b1 = b1; g_b2 = b2; g_r = r; g_c = c.xz; g_cm = c.y;
        EmitVertex();
    }
    EndPrimitive();
}

void emit_box(vec3 b0, vec3 b1, vec3 b2, vec3 r, vec3 c)
{
    vec3 chord = b2 - b0;
    vec3 tan1 = b1 - b0;
    float scale = max(max(length(chord), length(tan1)), max(max(abs(r.x), abs(r.y)), abs(r.z)));
    vec3 x;
    if (length(chord) > 1e-6 * scale)
        x = normalize(chord);
    else if (length(tan1) > 1e-6 * scale)
        x = normalize(tan1);
    else
        x = vec3(1, 0, 0);
    // y: the tangent off x, unless that is rounding noise. The noise of v scales with the
    // control points' magnitude (they are relative to the dataset origin), not with |tan1|:
    // a nearly collinear fold (a tangent tilted by 1e-7) left v ~ 6e-8 of noise above a
    // threshold of 1e-6 |tan1|, and normalize(noise) is no vector orthogonal to x; the box
    // then missed part of the sweep (0.05 r depth errors). Hence the threshold on the
    // larger of both, and y is made orthogonal to x again whatever chose it.
    vec3 v = tan1 - x * dot(tan1, x);
    float noise = 1e-5 * max(max(length(tan1), length(b0)), max(length(b1), length(b2)));
    vec3 y = length(v) > noise ? normalize(v) : any_orthogonal(x);
    y = normalize(y - x * dot(y, x));
    vec3 z = normalize(cross(x, y));
    mat3 axes = mat3(x, y, z);
    vec3 lo, hi;
    for (int a = 0; a < 3; a++) {
        float q0 = dot(b0, axes[a]), q1 = dot(b1, axes[a]), q2 = dot(b2, axes[a]);
        vec2 m = bezier_range(q0 - r.x, q1 - r.y, q2 - r.z);
        vec2 p = bezier_range(q0 + r.x, q1 + r.y, q2 + r.z);
        lo[a] = min(m.x, p.x);
        hi[a] = max(m.y, p.y);
    }
    // Pad for float rounding of the frame and the extents; a box never
    // collapses to zero thickness.
    float pad = 1e-5 * max(max(hi.x - lo.x, hi.y - lo.y), hi.z - lo.z) +
                1e-6 * max(max(abs(lo.x), abs(hi.x)), max(max(abs(lo.y), abs(hi.y)), max(abs(lo.z), abs(hi.z))));
    lo -= vec3(pad);
    hi += vec3(pad);

    vec3 corner[8];
    vec4 clip[8];
    for (int i = 0; i < 8; i++) {
        vec3 e = vec3((i & 1) != 0 ? hi.x : lo.x, (i & 2) != 0 ? hi.y : lo.y, (i & 4) != 0 ? hi.z : lo.z);
        corner[i] = axes * e;
        clip[i] = sl_view_projection * vec4(corner[i], 1.0);
    }
    vec3 eye = transpose(axes) * sl_eye.xyz;
    bool inside = all(greaterThan(eye, lo)) && all(lessThan(eye, hi));
    // A box that the near plane cuts (some corners before it, some beyond;
    // reversed-Z: z > w is before the near plane or behind the eye) loses the
    // clipped part of its eye-facing faces, and rays entering the box there
    // would see nothing: treat it as "eye inside" too.
    int before_near = 0;
    for (int i = 0; i < 8; i++)
        before_near += clip[i].z > clip[i].w ? 1 : 0;
    if (inside || (before_near > 0 && before_near < 8)) {
        emit_screen(b0, b1, b2, r, c);
        return;
    }
    if (u_frustum_cull != 0) {
        // Outside one clip plane with all 8 corners: invisible. Reversed-Z
        // near plane: visible needs z <= w; there is no far plane.
        bvec4 out_all = bvec4(true);
        bool out_near = true;
        for (int i = 0; i < 8; i++) {
            vec4 h = clip[i];
            out_all = bvec4(out_all.x && h.x < -h.w, out_all.y && h.x > h.w,
                            out_all.z && h.y < -h.w, out_all.w && h.y > h.w);
            out_near = out_near && h.z > h.w;
        }
        if (any(out_all) || out_near)
            return;
    }
    // A box that covers only a few pixels: one screen-aligned rectangle
    // around its projection, at the depth of its nearest corner (fewer
    // vertices and triangles than up to three faces; the fragment shader
    // decides coverage exactly either way).
    if (u_rect_pixels > 0.0) {
        bool front = true;
        vec2 lo2 = vec2(1e30), hi2 = vec2(-1e30);
        float zmax = 0.0;
        for (int i = 0; i < 8; i++) {
            front = front && clip[i].w > 0.0 && clip[i].z <= clip[i].w;
            vec3 ndc = clip[i].xyz / clip[i].w;
            lo2 = min(lo2, ndc.xy);
            hi2 = max(hi2, ndc.xy);
            zmax = max(zmax, ndc.z);
        }
        vec2 size = (hi2 - lo2) * 0.5 * sl_viewport.xy;
        if (front && size.x * size.y <= u_rect_pixels) {
            const vec2 q[4] = vec2[4](vec2(0, 0), vec2(1, 0), vec2(0, 1), vec2(1, 1));
            for (int i = 0; i < 4; i++) {
                gl_Position = vec4(mix(lo2, hi2, q[i]), zmax, 1.0);
                g_b0 = b0; g_b1 = b1; g_b2 = b2; g_r = r; g_c = c.xz; g_cm = c.y;
                EmitVertex();
            }
            EndPrimitive();
            return;
        }
    }
    // Faces: axis a, side s (0: lo, 1: hi). Corner index bit a = side.
    // Vertex order within a face is a strip over the two other axes.
    for (int a = 0; a < 3; a++) {
        for (int s = 0; s < 2; s++) {
            bool facing = s == 0 ? eye[a] < lo[a] : eye[a] > hi[a];
            if (!facing)
                continue;
            int b = (a + 1) % 3, cidx = (a + 2) % 3;
            int base = s << a;
            int i0 = base, i1 = base | (1 << b), i2 = base | (1 << cidx), i3 = base | (1 << b) | (1 << cidx);
            emit_vertex(corner[i0], b0, b1, b2, r, c);
            emit_vertex(corner[i1], b0, b1, b2, r, c);
            emit_vertex(corner[i2], b0, b1, b2, r, c);
            emit_vertex(corner[i3], b0, b1, b2, r, c);
            EndPrimitive();
        }
    }
}

void main()
{
    vec3 p0 = v_position_radius[0].xyz, p1 = v_position_radius[1].xyz;
    vec3 t0 = v_tangent_dradius[0].xyz, t1 = v_tangent_dradius[1].xyz;
    // Hermite -> Bezier (c1 = c2 = 1/3), split into two quadratics joined C1 at the mean.
    vec3 a2 = p0 + t0 / 3.0, b2 = p1 - t1 / 3.0, m = 0.5 * (a2 + b2);
    float r0 = v_position_radius[0].w, r1 = v_position_radius[1].w;
    float ra2 = r0 + v_tangent_dradius[0].w / 3.0, rb2 = r1 - v_tangent_dradius[1].w / 3.0;
    float rm = 0.5 * (ra2 + rb2);
    float c0 = v_scalar[0].x, c1 = v_scalar[1].x;
    float ca2 = c0 + v_scalar[0].y / 3.0, cb2 = c1 - v_scalar[1].y / 3.0, cm = 0.5 * (ca2 + cb2);
    emit_box(p0, a2, m, vec3(r0, ra2, rm), vec3(c0, ca2, cm));
    emit_box(m, b2, p1, vec3(rm, rb2, r1), vec3(cm, cb2, c1));
}
