// particles_marks.vert.glsl — stipples (the paper's sec. 4.2.2): one point per
// alive particle of the set that passes the visibility test (with hidden-
// surface removal: the id target holds this particle's id at its pixel),
// sized by the tone it stands for: ink area grows with the ink wanted, so
// the diameter is u_stipple_size mean spacings times sqrt(tone), projected
// (a zoom does not change the tone). Tone from the diffuse term d = max(0,
// n.l) with n facing the viewer: dark ink on a light background wants
// 1 - d, light ink on a dark background wants d; contrast stretches it about
// 1/2, brightness shifts it towards less ink on a brighter picture. The
// dot's colour: the ink, or with curvature colouring the set's 2D transfer
// function at the particle's (k1, k2) (particles_tf2d.glsl). Particles
// inside the focus sphere draw nothing.
#include "gpu/glsl/camera.glsl"
#include "particles/particles_record.glsl"
#include "particles/particles_tf2d.glsl"

uniform usampler2D u_ids;
uniform int u_hsr;
uniform vec3 u_light_world;    // unit, towards the light
uniform float u_mean_spacing;  // world
uniform float u_stipple_size;  // in mean spacings
uniform float u_brightness, u_contrast;
uniform int u_ink_dark;
uniform float u_max_point;
uniform vec3 u_ink;

flat out float v_diameter;
flat out vec3 v_color;

void cull()
{
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    gl_PointSize = 1.0;
    v_diameter = 0.0;
    v_color = vec3(0.0);
}

void main()
{
    pt_record r = pt_rec[gl_VertexID];
    vec3 p = pt_view_position(r);
    vec4 clip = sl_view_projection * vec4(p, 1.0);
    if (!(clip.w > 0.0) || pt_in_focus(r.x.xyz)) {
        cull();
        return;
    }
    if (u_hsr != 0) {
        vec2 win = (clip.xy / clip.w * 0.5 + 0.5) * sl_viewport.xy;
        ivec2 px = ivec2(floor(win));
        if (any(lessThan(px, ivec2(0))) || any(greaterThanEqual(px, ivec2(sl_viewport.xy))) ||
            texelFetch(u_ids, px, 0).r != uint(gl_VertexID) + 1u) {
            cull();
            return;
        }
    }
    vec3 n = r.n_k1.xyz;
    if (dot(n, sl_eye.xyz - p) < 0.0)
        n = -n;
    float d = max(dot(n, u_light_world), 0.0);
    float ink = u_ink_dark != 0 ? 1.0 - d : d;
    float tone = clamp((ink - 0.5) * u_contrast + 0.5 + (u_ink_dark != 0 ? -u_brightness : u_brightness), 0.0, 1.0);
    float diameter = u_stipple_size * u_mean_spacing * u_px_per_world / pt_eye_distance(p) * sqrt(tone);
    if (diameter < 0.5) {
        cull();
        return;
    }
    gl_Position = clip;
    v_diameter = min(diameter, u_max_point - 2.0);
    gl_PointSize = v_diameter + 2.0;
    v_color = pt_curvature_color(u_ink, r.n_k1.w, r.e1_k2.w);
}
