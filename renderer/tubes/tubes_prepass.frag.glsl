// tubes_prepass.frag.glsl — the pixel's ray against one pre-pass sphere (tubes_prepass.vert.glsl):
// the depth of its entry, which lies strictly inside the sweep; misses and entries before the
// near plane write nothing. The sphere is intersected relative to its centre with the lateral
// offset v (no b^2 - c cancellation), so the entry's float error is ~1e-7 of the eye distance.
#include "gpu/glsl/camera.glsl"

flat in vec4 v_sphere;

layout(depth_less) out float gl_FragDepth;

void main()
{
    vec3 d = normalize(sl_ray_direction(gl_FragCoord.xy));
    vec3 o = sl_eye.xyz - v_sphere.xyz;
    float b = dot(o, d);
    vec3 v = o - b * d;
    float disc = v_sphere.w * v_sphere.w - dot(v, v);
    if (!(disc >= 0.0))
        discard;
    float l = -b - sqrt(disc);
    float z = l * dot(d, sl_forward.xyz);
    if (!(z > sl_near.x))
        discard;
    gl_FragDepth = sl_near.x / z;
}
