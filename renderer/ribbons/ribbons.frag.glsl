// ribbons.frag.glsl — shading of an elliptic ribbon fragment (Neuhauser et al., Secs. 3.2, 4, 5):
// the fragment's local point p in the normal plane (units of r) gives the ellipse normal and
// the eccentric anomaly phi (no ring seam, no interpolated normals); Blinn-Phong through the
// shared line style; twist lines (Sec. 4, ribbons_twist.glsl), silhouette-point halos (Sec.
// 3.2, ribbons_halo.glsl) and the depth cue (Sec. 5) each behind a uniform (uniform control
// flow, derivatives taken outside branches). Caps (u_cap = 1) are flat: normal t, no twist or
// halo. `flat` quads (u_flat = 1, two-sided): normal n turned to the viewer, no twist lines,
// halo lambda = |p_y| (the fraction of the half-width, 1 at both edges). Shared by every
// pipeline. No discard, no gl_FragDepth (early depth stays on). Opaque output.
#include "gpu/glsl/camera.glsl"
#include "gpu/glsl/lighting.glsl"
#include "gpu/glsl/colormap.glsl"
#include "gpu/glsl/line_style.glsl"
#include "ribbons/ribbons_halo.glsl"
#include "ribbons/ribbons_twist.glsl"

in vec3 v_position;
in vec3 v_centre;
in vec3 v_n;
in vec3 v_t;
in float v_r;
in float v_w;
in float v_twist;
in float v_slope;
in float v_scalar;

uniform int u_cap;               // 1: the cap pass
uniform int u_flat;              // 1: pipeline flat (two-sided quads x -/+ r b)
uniform int u_rotate;            // 1: helicity frame (stripes fixed in it)
uniform float u_twist_scale;     // f
uniform int u_twist_lines;       // k, 0 = off
uniform float u_twist_width;     // w_r, units of r
uniform int u_halo;              // 0 = off
uniform int u_halo_screen;       // 1: halo_width in pixels
uniform float u_halo_width;
uniform vec3 u_halo_color;
uniform float u_halo_min;        // 1 - cos(pi / N): the band always reaches the N-gon's silhouette; flat: 0
uniform float u_depth_cue;       // 0 = off
uniform vec2 u_depth_range;      // eye distances of the data's bounding sphere, near and far

layout(location = 0) out vec4 o_color;

vec3 safe_normalize(vec3 v, vec3 fallback)
{
    float l = length(v);
    return l > 1e-20 ? v / l : fallback;
}

void main()
{
    vec3 t = safe_normalize(v_t, vec3(0.0, 0.0, 1.0));
    vec3 n = safe_normalize(v_n - t * dot(v_n, t), vec3(1.0, 0.0, 0.0));
    vec3 b = cross(t, n);
    float r = max(v_r, 1e-30);
    float w = max(v_w, 1e-3);          // SL_RIBBONS_MIN_W of ribbons_ring.glsl
    vec3 d = v_position - v_centre;
    vec2 p = vec2(dot(d, n), dot(d, b)) / r;
    vec3 v = normalize(sl_eye.xyz - v_position);
    vec3 normal = u_cap != 0 ? t : safe_normalize(p.x / (w * w) * n + p.y * b, n);
    if (u_flat != 0)
        normal = dot(n, v) < 0.0 ? -n : n;

    vec3 base = u_use_colormap != 0 ? sl_colormap(u_colormap, v_scalar, u_scalar_range) : u_color;
    vec3 l = normalize(u_light_eye.x * sl_right.xyz + u_light_eye.y * sl_up.xyz - u_light_eye.z * sl_forward.xyz);
    sl_material m = sl_material(u_material.x, u_material.y, u_material.z, u_material.w);
    vec3 color = sl_shade(base, normal, l, v, m);

    // Twist lines: a = phi - theta in the unrotated frame (stripes fixed in the helicity frame).
    float phi = atan(p.y, p.x / w);
    float a = phi - (u_rotate != 0 ? 0.0 : u_twist_scale * v_twist);
    float fw_a = min(fwidth(a), fwidth(mod(a + 3.14159265, SL_RIBBON_TWO_PI)));
    if (u_twist_lines > 0 && u_cap == 0 && u_flat == 0) {
        float w_u = sl_ribbon_twist_width(u_twist_width, r * u_twist_scale * v_slope);
        color *= 1.0 - sl_ribbon_twist_cover(a, fw_a, u_twist_lines, w_u);
    }

    // Halo: camera in the normal plane, homogeneous, rescaled so no entry exceeds 1.
    vec3 e = sl_eye.xyz - v_centre;
    vec2 c2 = vec2(dot(e, n), dot(e, b)) / r;
    float s = 1.0 / max(1.0, max(abs(c2.x), abs(c2.y)));
    vec3 c = vec3(s * c2, s);
    vec2 pmax, pmax2;
    bool seen = sl_ribbon_silhouette(c, w, pmax, pmax2);
    float lambda = seen ? sl_ribbon_halo_lambda(p, c, w, pmax, pmax2) : 0.0;
    // flat: the quad's half-width as seen (r |b x v|) is the chord's half.
    float half_chord = 0.5 * r * length(pmax2 - pmax);
    if (u_flat != 0) {
        seen = true;
        lambda = min(abs(p.y), 1.0);
        half_chord = r * length(cross(b, v));
    }
    float fw_l = fwidth(lambda);
    if (u_halo != 0 && u_cap == 0 && seen) {
        float eps = u_halo_width;
        if (u_halo_screen != 0) {
            float z = max(dot(v_position - sl_eye.xyz, sl_forward.xyz), sl_near.x);
            float px = 2.0 * z * sl_viewport.z / sl_viewport.y;
            eps = u_halo_width * px / max(half_chord, 1e-30);
        }
        eps = clamp(max(eps, u_halo_min), 0.0, 1.0);
        color = mix(color, u_halo_color, smoothstep(1.0 - eps - fw_l, 1.0 - eps + fw_l, lambda));
    }

    if (u_depth_cue > 0.0) {
        float dist = length(v_position - sl_eye.xyz);
        float k = clamp((dist - u_depth_range.x) / max(u_depth_range.y - u_depth_range.x, 1e-30), 0.0, 1.0);
        color = mix(color, vec3(dot(color, vec3(0.299, 0.587, 0.114))), u_depth_cue * k);
    }
    o_color = vec4(color, 1.0);
}
