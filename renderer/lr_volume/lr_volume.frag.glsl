// lr_volume.frag.glsl — technique lr_volume: one ray per pixel through an LR-spline volume,
// evaluated exactly from its Bézier blocks (lrspline/lr_bezier.glsl) at every sample; the
// model is README.md's. The ray is trimmed to the domain box and starts at the eye when
// inside. Segments [t, t + dt) are sampled at their midpoint; dt is u_dt (uniform) or the
// smallest side of the element at t times u_adapt (adaptive, paper Eq. 4: 2^-depth),
// the last segment shortened to the exit, every segment's opacity corrected for its
// length: alpha' = 1 - (1 - alpha)^(dt / u_ref), u_ref the smallest element side (the
// unit the transfer function's opacity is given for, as volume_dvr's voxel spacing).
// composite: front to back until alpha reaches u_alpha_stop (early ray termination),
// colour times I = max(0.4, |l . n|) with shading (n the unit gradient, l the view ray:
// a headlight; paper). mip: the largest value, then the transfer function. Empty-space
// skipping: composite jumps over elements whose hull maps to zero opacity (lr_visible,
// from the CPU per transfer function), mip over elements whose hull maximum cannot raise
// the running maximum. The element at a point is reused while the point stays in its box
// (else lr_find_element). Skipping keeps the uniform lattice, so it changes no sample
// there. u_over_target 0: the background is composited here (C + (1 - A) background, opaque,
// blending off). 1 (streamline tubes drawn before, lr_volume_streamlines.c): the ray also
// ends at the eye distance of u_opaque_depth (their reversed-Z depth, 0 = none), the output
// is premultiplied (C, A) for blending (ONE, ONE_MINUS_SRC_ALPHA) over the target, and the
// depth is max(tube, volume). With u_jitter, every segment is sampled at the pixel's offset
// u in [0, 1) of it (sl_volume_jitter of the pixel: the same per frame) instead of its
// midpoint, against wood-grain. Variants: LR_MODE 0 composite, 1 mip; lr_bezier.glsl's.
#include "gpu/glsl/camera.glsl"
#include "lrspline/lr_find.glsl"
#include "volume/volume_ray.glsl"
#include "volume/volume_tf.glsl"

#ifndef LR_MODE
#define LR_MODE 0
#endif

uniform vec3 u_background;
uniform int u_adaptive;        // 1: adaptive step
uniform float u_adapt;         // 2^-depth
uniform float u_dt;            // uniform step (world)
uniform float u_ref;           // opacity reference length (world)
uniform float u_alpha_stop;
uniform int u_shading;
uniform int u_skipping;
uniform int u_max_steps;       // guard against a stalled ray
uniform int u_over_target;     // 1: blend over geometry drawn before (see the header)
uniform sampler2D u_opaque_depth; // that geometry's reversed-Z depth (texelFetch, level 0)
uniform int u_jitter;          // 1: sample at the pixel's offset in each segment, 0: at midpoints

layout(std430, binding = 5) buffer lr_rows { uint lr_row_counts[]; };  // per row: taken, skipped
layout(std430, binding = 4) readonly buffer lr_visible { uint lr_visible_data[]; }; // per element: 1 visible

layout(location = 0) out vec4 o_color;

bool lr_in_box(vec3 p, vec3 lo, vec3 hi)
{
    return all(greaterThanEqual(p, lo)) && all(lessThanEqual(p, hi));
}

void main()
{
    vec3 d = normalize(sl_ray_direction(gl_FragCoord.xy));
    vec3 eye = sl_eye.xyz;
    vec3 inv_d = sl_volume_safe_inverse(d);
    vec2 tb = sl_volume_ray_box(eye, inv_d, u_lr_domain_lo, u_lr_domain_hi);
    float t0 = max(tb.x, 0.0), t1 = tb.y;
    float opaque = 0.0;
    if (u_over_target != 0) {
        opaque = texelFetch(u_opaque_depth, ivec2(gl_FragCoord.xy), 0).r;
        if (opaque > 0.0)
            t1 = min(t1, sl_distance_of_depth(opaque, d));
    }
    if (!(t1 > t0))
        discard;
    uint taken = 0u, skipped = 0u;
#if LR_MODE == 0
    vec3 C = vec3(0.0);
    float A = 0.0, depth_t = -1.0;
#else
    float vmax = -1.0 / 0.0;
    bool any = false;
#endif
    float off = u_jitter != 0 ? sl_volume_jitter(gl_FragCoord.xy) : 0.5; // sample position in a segment
    float t = t0;
    int ks = 0;                // uniform: segments so far (t = t0 + ks dt, no accumulated rounding)
    int e = -1;
    vec3 elo = vec3(0.0), ehi = vec3(0.0);
    for (int it = 0; it < u_max_steps && t < t1; it++) {
        vec3 ps = clamp(eye + t * d, u_lr_domain_lo, u_lr_domain_hi);
        if (e < 0 || !lr_in_box(ps, elo, ehi)) {
            e = lr_find_element(ps);
            if (e < 0)
                break;
            elo = lr_box_data[e].lo.xyz;
            ehi = lr_box_data[e].hi.xyz;
        }
        vec3 side = ehi - elo;
        float dt = u_adaptive != 0 ? min(min(side.x, side.y), side.z) * u_adapt : u_dt;
        if (u_skipping != 0) {
#if LR_MODE == 0
            bool skip = lr_visible_data[e] == 0u;
#else
            bool skip = lr_box_data[e].hi.w <= vmax;
#endif
            float texit = min(sl_volume_ray_box(eye, inv_d, elo, ehi).y, t1);
            // Uniform: the segments whose samples lie before the exit (the lattice and the
            // samples stay those without skipping); adaptive: a new segment from the exit.
            float k = u_adaptive != 0 ? max(ceil((texit - t) / dt), 1.0) : ceil((texit - t) / dt - off);
            if (skip && k >= 1.0) {
                ks += int(k);
                t = u_adaptive != 0 ? max(texit, t) + 1e-4 * min(min(side.x, side.y), side.z) : t0 + float(ks) * dt;
                skipped += uint(k);
                e = -1;
                continue;
            }
        }
        float seg = min(dt, t1 - t);
        float tm = u_adaptive != 0 || seg < dt ? t + off * seg : t0 + (float(ks) + off) * dt;
        vec3 pm = clamp(eye + tm * d, u_lr_domain_lo, u_lr_domain_hi);
        int es = lr_in_box(pm, elo, ehi) ? e : lr_find_element(pm);
        ks++;
        t = u_adaptive != 0 || seg < dt ? t + seg : t0 + float(ks) * dt;
        if (es < 0)
            continue;
        taken++;
#if LR_MODE == 0
        vec3 g;
        float v = lr_value_gradient(es, pm, g);
        vec4 c = sl_volume_tf(v);
        if (c.a > 0.0) {
            float a = sl_volume_opacity_correct(c.a, seg / u_ref);
            vec3 rgb = c.rgb;
            if (u_shading != 0) {
                float gl = length(g);
                float I = gl > 0.0 ? max(0.4, abs(dot(d, g / gl))) : 1.0;
                rgb *= I;
            }
            C += (1.0 - A) * a * rgb;
            A += (1.0 - A) * a;
            if (A > 0.5 && depth_t < 0.0)
                depth_t = tm;
            if (A >= u_alpha_stop)
                break;
        }
#else
        vmax = max(vmax, lr_value(es, pm));
        any = true;
#endif
    }
    uint y = uint(gl_FragCoord.y);
    atomicAdd(lr_row_counts[2u * y], taken);
    atomicAdd(lr_row_counts[2u * y + 1u], skipped);
#if LR_MODE == 0
    if (!(A > 0.0))
        discard;
    float depth = depth_t >= 0.0 ? sl_depth_of(eye + depth_t * d) : 0.0;
    o_color = u_over_target != 0 ? vec4(C, A) : vec4(C + (1.0 - A) * u_background, 1.0);
    gl_FragDepth = max(opaque, depth);
#else
    if (!any)
        discard;
    vec4 c = sl_volume_tf(vmax);
    o_color = u_over_target != 0 ? vec4(c.a * c.rgb, c.a) : vec4(c.a * c.rgb + (1.0 - c.a) * u_background, 1.0);
    gl_FragDepth = opaque;
#endif
}
