// particles_contours.comp.glsl — contours (the paper's sec. 4.2.4; plan
// sec. 1.9), per frame, one invocation per alive particle of the set. A
// particle that passes the visibility test (particles_visible.glsl, with
// hidden-surface removal) is selected by Kindlmann's thickness-controlled
// test on the normal section towards the viewer: v = unit(eye - p),
// c = n.v, v_t = v - c n, k_v = v_t G v_t / |v_t|^2 (G = k1 e1e1 + k2 e2e2,
// e2 = n x e1), T = u_band (world):
//   the osculating circle of that section (centre p - n / k_v; v lies in
//   its plane) has a contour point seen from the eye when the eye is
//   outside it (dist + 2 c / k_v > 0): select iff
//   |c| <= sqrt(T |k_v| (2 - T |k_v|)) (1 when T |k_v| >= 1), i.e. the
//   particle projects within T of that contour; the centre moves onto it,
//   x_c = p + ((|v_t| - 1) n - c v_t / |v_t|) / k_v (the plan's first-order
//   move -c v_t / (|v_t| k_v) plus the circle's drop towards its centre,
//   exact on a sphere: the first-order move alone lands up to T outside);
//   a move longer than PT_MAX_SHIFT mean spacings is not trusted (drawn
//   nowhere);
//   elsewhere (k_v = 0, or the eye inside the circle) the plan's rule for
//   flat and concave sections: |c| <= min(1, T / sigma), not moved.
// It appends the segment x_c -+ u_length / 2 t along the contour direction
// t = unit(n x G v_t), conjugate to v (n.v stays 0 to first order; n x v
// where G v_t vanishes), and counts it in the instance count of the
// indirect command (6 vertices per instance), so no read-back is needed.
layout(local_size_x = 256) in;

#include "gpu/glsl/camera.glsl"
#include "particles/particles_record.glsl"
#include "particles/particles_visible.glsl"
#include "particles/particles_contours.glsl"

const float PT_MAX_SHIFT = 8.0;

layout(std430, binding = 2) writeonly buffer pt_segments { pt_segment pt_seg[]; };
layout(std430, binding = 3) buffer pt_command { uint pt_cmd_count, pt_cmd_instances, pt_cmd_first, pt_cmd_base; };

uniform usampler2D u_ids;
uniform int u_hsr;
uniform uint u_count;
uniform float u_band;          // T, world
uniform float u_length;        // segment length, world
uniform float u_flat_limit;    // min(1, T / sigma)
uniform float u_mean_spacing;  // world

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count)
        return;
    pt_record r = pt_rec[i];
    vec3 p = pt_view_position(r);
    vec4 clip = sl_view_projection * vec4(p, 1.0);
    if (!(clip.w > 0.0) || (u_hsr != 0 && !pt_hsr_visible(u_ids, clip, i + 1u)))
        return;
    vec3 n = r.n_k1.xyz, e1 = r.e1_k2.xyz, e2 = cross(n, e1);
    float k1 = r.n_k1.w, k2 = r.e1_k2.w;
    vec3 to_eye = sl_eye.xyz - p;
    float dist = length(to_eye);
    vec3 v = to_eye / dist;
    float c = dot(n, v);
    vec3 vt = v - c * n;
    float w = length(vt);
    if (!(w > 1e-6))
        return;
    float a1 = dot(vt, e1), a2 = dot(vt, e2);
    vec3 gvt = k1 * a1 * e1 + k2 * a2 * e2;
    float kv = (k1 * a1 * a1 + k2 * a2 * a2) / (w * w);
    vec3 xc = p;
    if (kv != 0.0 && dist + 2.0 * c / kv > 0.0) {
        float tk = u_band * abs(kv);
        float limit = tk >= 1.0 ? 1.0 : sqrt(tk * (2.0 - tk));
        if (abs(c) > limit)
            return;
        vec3 shift = ((w - 1.0) * n - c * vt / w) / kv;
        if (length(shift) > PT_MAX_SHIFT * u_mean_spacing)
            return;
        xc = p + shift;
    } else if (abs(c) > u_flat_limit) {
        return;
    }
    vec3 t = cross(n, gvt);
    if (!(dot(t, t) > 1e-12 * dot(gvt, gvt)))
        t = cross(n, v);
    t = normalize(t);
    uint slot = atomicAdd(pt_cmd_instances, 1u);
    pt_seg[slot] = pt_segment(vec4(xc - 0.5 * u_length * t, 1.0), vec4(xc + 0.5 * u_length * t, 1.0));
}
