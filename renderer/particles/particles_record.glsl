// particles_record.glsl — the final particle records the drawing passes read
// (particles_final.comp.glsl writes them; particles_system.h pt_record):
// x.xyz local world (world - volume origin), x.w 1 alive; n (B-spline, unit,
// -grad f: outward for objects brighter than their surroundings) + k1;
// e1 (direction of k1) + k2. Alive records come first.
struct pt_record {
    vec4 x;
    vec4 n_k1;
    vec4 e1_k2;
};

layout(std430, binding = 1) readonly buffer pt_records { pt_record pt_rec[]; };

uniform vec3 u_volume_offset;   // volume origin - view origin (positions relative to the view origin)
uniform float u_px_per_world;   // window height / (2 tan(fov_y / 2)): pixels per world unit at eye distance 1
uniform vec4 u_focus;           // focus sphere: xyz centre in local world, w radius (0 = no focus)

vec3 pt_view_position(pt_record r)
{
    return u_volume_offset + r.x.xyz;
}

// Eye distance along the view direction (camera.glsl's depth model).
float pt_eye_distance(vec3 p)
{
    return max(dot(p - sl_eye.xyz, sl_forward.xyz), 1e-30);
}

// Inside the focus sphere (focus + context): such a particle casts no cone
// and draws no mark, the volume is drawn there instead (particles_focus.h).
bool pt_in_focus(vec3 local)
{
    vec3 v = local - u_focus.xyz;
    return u_focus.w > 0.0 && dot(v, v) < u_focus.w * u_focus.w;
}
