// volume_march.glsl — the ray marcher of the volume techniques (README.md of volume_dvr: the model).
// sl_volume_march samples one ray over [t0, t1] at the midpoints of segments dt long (the
// last one shorter, with its own opacity correction) or, with jitter, at a per-pixel offset
// in [0, 1) of each segment. composite: front-to-back emission–absorption until alpha
// reaches u_alpha_stop; mip: the largest value, then the transfer function; iso: the first
// sign change of value - iso between samples (the first at t0), refined by bisection and a
// final secant step, shaded. Empty-space skipping: the outer loop looks up the brick of the
// next sample and its run d (the cube of bricks within d - 1 of it is of its kind); in an
// invisible brick (composite: zero opacity for every value in it; iso: iso outside its
// range) it jumps to the first sample past that cube (mip: visible bricks are looked up one
// by one, and one whose maximum cannot raise the running maximum is skipped); in a visible
// one the inner loop takes every sample up to the cube's exit without further lookups. The
// same samples are kept, so the image is unchanged. NaN samples are transparent (iso: no
// crossing next to them). Samples taken and skipped are added to the row counters.
// Compile-time variants (volume_march.c compiles each on first use; no defaults): SL_MODE 0
// composite, 1 mip, 2 iso; SL_SHADING 1 shades (composite with shading, iso; an iso without
// it, never drawn, takes the TF colour); SL_GRADIENT_TEX 1 takes normals from u_gradient. On
// llvmpipe a loop that merely contains the unused shading or iso code runs 3-6x slower than
// one without it. Coordinates: eye_v + t rd in voxels, rd = d / spacing, so t is the world
// distance along the unit world direction d. Uniforms: set by sl_volume_marcher_draw.
#include "gpu/glsl/lighting.glsl"
#include "volume/volume_ray.glsl"
#include "volume/volume_sample.glsl"
#include "volume/volume_tf.glsl"

uniform vec3 u_inv_spacing;      // world direction -> voxel direction
uniform float u_dt;              // world step
uniform float u_step;            // dt in units of the smallest spacing (opacity correction exponent)
uniform float u_min_spacing;
uniform float u_iso;
uniform float u_alpha_stop;
uniform int u_jitter;
uniform int u_skipping;
uniform usampler3D u_runs;       // per brick: sl_volume_brick_runs (volume/sl_volume.h)
uniform sampler3D u_minmax;      // brick min, max
uniform ivec3 u_brick_dims;
uniform vec3 u_light_world;      // unit, towards the light
uniform vec4 u_material;         // ambient, diffuse, specular, shininess
uniform sampler3D u_gradient;    // SL_GRADIENT_TEX: unit gradients (volume_gradient.c)

layout(std430, binding = 5) buffer sl_volume_sample_rows {
    uint rows[];                 // per pixel row: samples taken, samples skipped
};

const float SL_MARCH_BRICK = 8.0;   // SL_VOLUME_BRICK
const uint SL_MARCH_RUN_VISIBLE = 128u;   // SL_VOLUME_RUN_VISIBLE

ivec3 sl_march_brick_of(vec3 p)
{
    return clamp(ivec3(floor(p / SL_MARCH_BRICK)), ivec3(0), u_brick_dims - 1);
}

#if SL_SHADING
vec3 sl_march_shade(vec3 base, vec3 p, vec3 view_dir)
{
    vec3 n;
#if SL_GRADIENT_TEX
    vec3 gn = textureLod(u_gradient, (p + 0.5) / u_dims, 0.0).xyz;
    if (!(dot(gn, gn) > 1e-4))
        return base;
    n = normalize(gn);
#else
    vec3 g = sl_volume_gradient(p) * u_inv_spacing;
    float m = max(max(abs(g.x), abs(g.y)), abs(g.z));
    if (!(m > 0.0 && m < 3.0e38)) // zero (constant region), NaN or overflow: unlit
        return base;
    n = normalize(g / m);
#endif
    sl_material mat = sl_material(u_material.x, u_material.y, u_material.z, u_material.w);
    return sl_shade(base, n, u_light_world, view_dir, mat);
}
#endif

void sl_march_count(uint taken, uint skipped)
{
    uint y = uint(gl_FragCoord.y);
    if (taken > 0u)
        atomicAdd(rows[2u * y], taken);
    if (skipped > 0u)
        atomicAdd(rows[2u * y + 1u], skipped);
}

// The composite of one ray: C premultiplied, A its opacity; covered false when nothing
// shows (composite: A = 0; mip: no finite sample; iso: no crossing); depth_t the ray
// parameter of the depth (composite: where A first exceeds 0.5; iso: the hit), else -1.
struct sl_march_result {
    vec3 C;
    float A;
    float depth_t;
    bool covered;
};

sl_march_result sl_volume_march(vec3 eye_v, vec3 d, float t0, float t1)
{
    vec3 rd = d * u_inv_spacing;
    vec3 inv_rd = sl_volume_safe_inverse(rd);
    float L = t1 - t0, dt = u_dt;
    float off = 0.5;
    if (u_jitter != 0)
        off = sl_volume_jitter(gl_FragCoord.xy);
    // Samples k < n on the lattice t0 + (k + off) dt (exponent u_step); sample n,
    // when rem > 0, at the middle of the remainder (its own exponent).
    int n = u_jitter != 0 ? max(int(ceil(L / dt - off)), 0) : int(floor(L / dt));
    float rem = u_jitter != 0 ? 0.0 : L - float(n) * dt;
    int last = rem > 0.0 ? n : n - 1; // the last sample's index
    float t_rem = t0 + float(n) * dt + 0.5 * rem, exp_rem = rem / u_min_spacing;

    uint taken = 0u, skipped = 0u;
#if SL_MODE == 0
    vec3 C = vec3(0.0);
    float A = 0.0, depth_t = -1.0;
#elif SL_MODE == 1
    float vmax = -1.0 / 0.0;        // running maximum of the finite samples
    bool any = false;
#elif SL_MODE == 2
    float prev = sl_volume_value(eye_v + t0 * rd), prev_t = t0; // the entry sample
    bool prev_ok = !sl_is_nan(prev);
    taken++;
    float hit_t = -1.0;
#endif
    bool done = false;
    int k = 0;
    while (k <= last && !done) {
        // The run of samples [k, k_end) this brick lookup covers.
        int k_end = last + 1;
        if (u_skipping != 0) {
            float tk = k < n ? t0 + (float(k) + off) * dt : t_rem;
            ivec3 b = sl_march_brick_of(eye_v + tk * rd);
            uint code = texelFetch(u_runs, b, 0).r;
            bool skip = code < SL_MARCH_RUN_VISIBLE;
            uint run = skip ? code : code - SL_MARCH_RUN_VISIBLE;
#if SL_MODE == 1
            // Visible bricks one at a time, each skipped when its maximum
            // cannot raise the running one (head phantom at 1280x720: 362 ms,
            // 90 % skipped; as runs without the test, 843 ms).
            if (!skip) {
                skip = texelFetch(u_minmax, b, 0).g <= vmax;
                run = 1u;
            }
#endif
            float r = float(max(run, 1u));
            vec3 blo = (vec3(b) - (r - 1.0)) * SL_MARCH_BRICK, bhi = (vec3(b) + r) * SL_MARCH_BRICK;
            float texit = sl_volume_ray_box(eye_v, inv_rd, blo, bhi).y;
            int kx = k < n ? clamp(int(ceil((texit - t0) / dt - off)), k + 1, n) : n + 1;
            // The remainder sample lies past the lattice: inside this run only
            // when the run reaches the end of the lattice and t_rem < texit.
            if (kx == n && rem > 0.0 && t_rem < texit)
                kx = n + 1;
            kx = min(kx, last + 1);
            if (skip) {
                skipped += uint(kx - k);
                k = kx;
                continue;
            }
            k_end = kx;
        }
        for (; k < k_end; k++) {
            float tk = k < n ? t0 + (float(k) + off) * dt : t_rem;
            vec3 p = eye_v + tk * rd;
            float v = sl_volume_value(p);
            taken++;
            if (sl_is_nan(v)) {
#if SL_MODE == 2
                prev_ok = false;
#endif
                continue;
            }
#if SL_MODE == 0
            vec4 c = sl_volume_tf(v);
            if (c.a > 0.0) {
                float a = sl_volume_opacity_correct(c.a, k < n ? u_step : exp_rem);
#if SL_SHADING
                vec3 rgb = sl_march_shade(c.rgb, p, -d);
#else
                vec3 rgb = c.rgb;
#endif
                C += (1.0 - A) * a * rgb;
                A += (1.0 - A) * a;
                if (A > 0.5 && depth_t < 0.0)
                    depth_t = tk;
                if (A >= u_alpha_stop) {
                    done = true;
                    break;
                }
            }
#elif SL_MODE == 1
            vmax = max(vmax, v);
            any = true;
#elif SL_MODE == 2
            if (prev_ok && ((prev - u_iso < 0.0) != (v - u_iso < 0.0))) {
                float ta = prev_t, tc = tk, sa = prev - u_iso, sc = v - u_iso;
                for (int it = 0; it < 12; it++) {
                    float tm = 0.5 * (ta + tc);
                    float sm = sl_volume_value(eye_v + tm * rd) - u_iso;
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
                done = true;
                break;
            }
            prev = v;
            prev_t = tk;
            prev_ok = true;
#endif
        }
    }
    sl_march_count(taken, skipped);
    sl_march_result r;
#if SL_MODE == 0
    r = sl_march_result(C, A, depth_t, A > 0.0);
#elif SL_MODE == 1
    vec4 c = sl_volume_tf(vmax);
    r = sl_march_result(c.a * c.rgb, c.a, -1.0, any);
#elif SL_MODE == 2
    vec3 base = sl_volume_tf(u_iso).rgb;
#if SL_SHADING
    if (hit_t >= 0.0)
        base = sl_march_shade(base, eye_v + hit_t * rd, -d);
#endif
    r = sl_march_result(base, 1.0, hit_t, hit_t >= 0.0);
#endif
    return r;
}
