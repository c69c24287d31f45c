// tubes_prepass.frag.glsl — the pixel's ray against one pre-pass sphere (tubes_prepass.vert.glsl):
// the depth of its entry, which lies strictly inside the sweep; misses and entries before the
// near plane write nothing. The sphere is intersected relative to its centre with the lateral
// offset v (no b^2 - c cancellation); the depth written is moved FAR_BIAS of the eye distance
// farther, so that for tubes of a pixel or less, where the radius shrink leaves only ~1e-6 of
// the distance, float error (~1e-7 of it, more near the sphere's rim) stays on the safe side.
#include "gpu/glsl/camera.glsl"

flat in vec4 v_sphere;

const float FAR_BIAS = 4e-6;

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
    gl_FragDepth = sl_near.x / (z * (1.0 + FAR_BIAS));
}
