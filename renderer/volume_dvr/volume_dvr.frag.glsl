// volume_dvr.frag.glsl — one ray per pixel through a scalar volume (README.md: the model).
// The ray is clipped to the box (and clip box) in voxel coordinates, starts at the eye
// when inside, and is sampled at the midpoints of segments dt long (the last one
// shorter, with its own opacity correction) or, with jitter, at a per-pixel offset in
// [0, 1) of each segment. composite: front-to-back emission–absorption until alpha
// reaches u_alpha_stop; mip: the largest value, then the transfer function; iso: the
// first sign change of value - iso between samples (the first at the box entry),
// refined by bisection and a final secant step, shaded. Empty-space skipping jumps to
// the first sample past a brick whose mask is 0 (composite: zero opacity for every
// value in it; iso: iso outside its range) or, for mip, whose maximum cannot raise the
// running maximum — the same samples are kept, so the image is unchanged. NaN samples
// are transparent (iso: no crossing next to them). Writes the final colour (blending
// off) and the depth: iso hit, composite where alpha first exceeds 0.5, else 0.
#include "gpu/glsl/camera.glsl"
#include "gpu/glsl/lighting.glsl"
#include "volume/volume_ray.glsl"
#include "volume/volume_sample.glsl"
#include "volume/volume_tf.glsl"

uniform vec3 u_eye_v;            // eye in voxel coordinates
uniform vec3 u_inv_spacing;      // world direction -> voxel direction
uniform vec3 u_box_lo, u_box_hi; // voxel coordinates, clip box applied
uniform float u_dt;              // world step
uniform float u_step;            // dt in units of the smallest spacing (opacity correction exponent)
uniform float u_min_spacing;
uniform int u_mode;              // 0 composite, 1 mip, 2 iso
uniform float u_iso;
uniform float u_alpha_stop;
uniform int u_jitter;
uniform int u_shading;
uniform int u_skipping;
uniform usampler3D u_mask;       // 1 = brick visible
uniform sampler3D u_minmax;      // brick min, max
uniform ivec3 u_brick_dims;
uniform vec3 u_background;
uniform vec3 u_light_world;      // unit, towards the light
uniform vec4 u_material;         // ambient, diffuse, specular, shininess
uniform int u_gradient_tex;      // 1: normals from u_gradient, 0: central differences here
uniform sampler3D u_gradient;    // unit gradients (volume_gradient.c)

layout(std430, binding = 5) buffer sl_volume_sample_rows {
    uint rows[];                 // per pixel row: samples taken, samples skipped
};

layout(location = 0) out vec4 o_color;

const float BRICK = 8.0;

ivec3 brick_of(vec3 p)
{
    return clamp(ivec3(floor(p / BRICK)), ivec3(0), u_brick_dims - 1);
}

vec3 shade(vec3 base, vec3 p, vec3 view_dir)
{
    vec3 n;
    if (u_gradient_tex != 0) {
        // Precomputed unit gradients, interpolated: too short where they cancel.
        vec3 gn = textureLod(u_gradient, (p + 0.5) / u_dims, 0.0).xyz;
        if (!(dot(gn, gn) > 1e-4))
            return base;
        n = normalize(gn);
    } else {
        vec3 g = sl_volume_gradient(p) * u_inv_spacing;
        float m = max(max(abs(g.x), abs(g.y)), abs(g.z));
        if (!(m > 0.0 && m < 3.0e38)) // zero (constant region), NaN or overflow: unlit
            return base;
        n = normalize(g / m);
    }
    sl_material mat = sl_material(u_material.x, u_material.y, u_material.z, u_material.w);
    return sl_shade(base, n, u_light_world, view_dir, mat);
}

void count(uint taken, uint skipped)
{
    uint y = uint(gl_FragCoord.y);
    if (taken > 0u)
        atomicAdd(rows[2u * y], taken);
    if (skipped > 0u)
        atomicAdd(rows[2u * y + 1u], skipped);
}

void main()
{
    vec3 d = normalize(sl_ray_direction(gl_FragCoord.xy));
    vec3 rd = d * u_inv_spacing;
    vec3 inv_rd = sl_volume_safe_inverse(rd);
    vec2 tb = sl_volume_ray_box(u_eye_v, inv_rd, u_box_lo, u_box_hi);
    float t0 = max(tb.x, 0.0), t1 = tb.y;
    if (!(t1 > t0))
        discard;
    float L = t1 - t0, dt = u_dt;
    float off = 0.5;
    if (u_jitter != 0)
        off = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
    int n = u_jitter != 0 ? max(int(ceil(L / dt - off)), 0) : int(floor(L / dt));
    float rem = u_jitter != 0 ? 0.0 : L - float(n) * dt;

    uint taken = 0u, skipped = 0u;
    vec3 C = vec3(0.0);
    float A = 0.0, depth_t = -1.0;
    float vmax = -1.0 / 0.0;        // mip: running maximum of the finite samples
    bool any = false;
    float prev = sl_volume_value(u_eye_v + t0 * rd), prev_t = t0; // iso: the entry sample
    bool prev_ok = u_mode == 2 && !sl_is_nan(prev);
    if (u_mode == 2)
        taken++;
    float hit_t = -1.0;
    float brick_exit = -1.0;        // samples before this t lie in a brick found visible
    for (int k = 0; k <= n;) {
        float tk, kexp;
        if (k < n) {
            tk = t0 + (float(k) + off) * dt;
            kexp = u_step;
        } else {
            if (!(rem > 0.0))
                break;
            tk = t0 + float(n) * dt + 0.5 * rem;
            kexp = rem / u_min_spacing;
        }
        vec3 p = u_eye_v + tk * rd;
        if (u_skipping != 0 && tk >= brick_exit) {
            // Entering a brick: look it up once; its samples up to brick_exit need no test.
            ivec3 b = brick_of(p);
            vec3 blo = vec3(b) * BRICK;
            float texit = sl_volume_ray_box(u_eye_v, inv_rd, blo, blo + BRICK).y;
            bool skip = texelFetch(u_mask, b, 0).r == 0u;
            if (!skip && u_mode == 1)
                skip = texelFetch(u_minmax, b, 0).g <= vmax;
            if (skip) {
                int k2 = k < n ? clamp(int(ceil((texit - t0) / dt - off)), k + 1, n) : n + 1;
                skipped += uint(k2 - k);
                k = k2;
                continue;
            }
            brick_exit = texit;
        }
        float v = sl_volume_value(p);
        taken++;
        k++;
        if (sl_is_nan(v)) {
            prev_ok = false;
            continue;
        }
        if (u_mode == 0) {
            vec4 c = sl_volume_tf(v);
            if (c.a > 0.0) {
                float a = sl_volume_opacity_correct(c.a, kexp);
                vec3 rgb = u_shading != 0 ? shade(c.rgb, p, -d) : c.rgb;
                C += (1.0 - A) * a * rgb;
                A += (1.0 - A) * a;
                if (A > 0.5 && depth_t < 0.0)
                    depth_t = tk;
                if (A >= u_alpha_stop)
                    break;
            }
        } else if (u_mode == 1) {
            vmax = max(vmax, v);
            any = true;
        } else {
            if (prev_ok && ((prev - u_iso < 0.0) != (v - u_iso < 0.0))) {
                float ta = prev_t, tc = tk, sa = prev - u_iso, sc = v - u_iso;
                for (int it = 0; it < 12; it++) {
                    float tm = 0.5 * (ta + tc);
                    float sm = sl_volume_value(u_eye_v + tm * rd) - u_iso;
                    if (sl_is_nan(sm))
                        break;
                    if ((sa < 0.0) != (sm < 0.0)) {
                        tc = tm;
                        sc = sm;
                    } else {
                        ta = tm;
                        sa = sm;
                    }
                }
                taken += 12u;
                hit_t = sa != sc ? ta + (tc - ta) * sa / (sa - sc) : ta;
                break;
            }
            prev = v;
            prev_t = tk;
            prev_ok = true;
        }
    }
    count(taken, skipped);
    vec3 rgb;
    float depth = 0.0;
    if (u_mode == 0) {
        if (!(A > 0.0))
            discard;
        rgb = C + (1.0 - A) * u_background;
        if (depth_t >= 0.0)
            depth = sl_depth_of(sl_eye.xyz + depth_t * d);
    } else if (u_mode == 1) {
        if (!any)
            discard;
        vec4 c = sl_volume_tf(vmax);
        rgb = c.a * c.rgb + (1.0 - c.a) * u_background;
    } else {
        if (hit_t < 0.0)
            discard;
        vec3 p = u_eye_v + hit_t * rd;
        rgb = shade(sl_volume_tf(u_iso).rgb, p, -d);
        depth = sl_depth_of(sl_eye.xyz + hit_t * d);
    }
    o_color = vec4(rgb, 1.0);
    gl_FragDepth = depth;
}
