// particles_cone.frag.glsl — the cone of one particle (Algorithm 3): the
// pixel's ray meets the particle's tangent plane at x; fragments farther than
// the cone radius from the particle are cut, the rest get the depth of the
// cone surface, rising from the apex at the particle to u_cone_radius behind
// it at the rim, along the ray. Nearly edge-on tangent planes use a disk
// facing the viewer instead, so silhouette particles still cover their pixel.
// The footprint is at least 1.5 px in radius (the apex pixel is covered).
#include "gpu/glsl/camera.glsl"
#include "particles/particles_record.glsl"

uniform float u_cone_radius;

flat in uint v_id;
flat in vec3 v_center;
flat in vec3 v_normal;

layout(location = 0) out uint o_id;

void main()
{
    vec3 rd = normalize(sl_ray_direction(gl_FragCoord.xy));
    vec3 n = v_normal;
    if (abs(dot(n, rd)) < 0.1)
        n = -rd;
    float t = dot(v_center - sl_eye.xyz, n) / dot(rd, n);
    vec3 x = sl_eye.xyz + t * rd;
    float z = pt_eye_distance(v_center);
    float radius = max(u_cone_radius, 1.5 * z / u_px_per_world);
    float rho = length(x - v_center);
    if (rho > radius || !(t > 0.0))
        discard;
    o_id = v_id;
    gl_FragDepth = sl_depth_of(x + (u_cone_radius * rho / radius) * rd);
}
