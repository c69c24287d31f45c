// ribbons_ring.glsl — placing a ring vertex of an elliptic ribbon (Neuhauser et al., Sec. 3.1,
// Eq. 1: p = x + r F (w cos phi, sin phi, 0)^T with F = (n, b, t), n x b = t; n is the face
// normal, the thin axis of semi-axis r w', b the width axis of semi-axis r).
// w' = clamp(max(width_ratio, min_thickness, w_px), 1e-3, 1), where w_px keeps the full
// on-screen thickness 2 r w' at or above min_pixels (Sec. 7.2's suggestion; / cos(pi/N) for
// the inscribed N-gon). The helicity frame rotates n about t by theta = f R (Rees et al.).
// Needs camera.glsl. Pure functions of their arguments and the uniforms below.
uniform float u_width_ratio;
uniform float u_min_thickness;
uniform float u_min_pixels;   // 0: off
uniform float u_cos_pi_n;     // cos(pi / sides)

const float SL_RIBBONS_MIN_W = 1e-3;

// w' of a ring at centre x (relative to the origin) with semi-major axis r.
float sl_ribbon_w(vec3 x, float r)
{
    float w = max(u_width_ratio, u_min_thickness);
    if (u_min_pixels > 0.0 && r > 0.0) {
        float z = max(dot(x - sl_eye.xyz, sl_forward.xyz), sl_near.x);
        float px = 2.0 * z * sl_viewport.z / sl_viewport.y;     // world size of a pixel at z
        w = max(w, u_min_pixels * px / (2.0 * r * u_cos_pi_n));
    }
    return clamp(w, SL_RIBBONS_MIN_W, 1.0);
}

// n rotated about t by theta (towards b = t x n).
vec3 sl_ribbon_rotate(vec3 n, vec3 t, float theta)
{
    return cos(theta) * n + sin(theta) * cross(t, n);
}

vec3 sl_ribbon_place(vec3 x, vec3 n, vec3 b, vec2 cs, float r, float w)
{
    return x + r * (w * cs.x * n + cs.y * b);
}
