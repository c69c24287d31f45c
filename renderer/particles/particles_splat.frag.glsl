// particles_splat.frag.glsl — one splat: the particle's cone
// (particles_cone.glsl: its tangent disk, the cone's depth), opaque, in the
// set's ink shaded by Lambert's law with the normal turned to the viewer:
// ink (a + (1 - a) max(0, n.l)), a = PT_SPLAT_AMBIENT so the unlit side
// keeps its shape against the background.
#include "gpu/glsl/camera.glsl"
#include "particles/particles_record.glsl"
#include "particles/particles_cone.glsl"

const float PT_SPLAT_AMBIENT = 0.1;

uniform float u_cone_radius;
uniform vec3 u_ink;
uniform vec3 u_light_world;    // unit, towards the light

flat in vec3 v_center;
flat in vec3 v_normal;

layout(location = 0) out vec4 o_color;

void main()
{
    float depth;
    if (!pt_cone_fragment(gl_FragCoord.xy, v_center, v_normal, u_cone_radius, false, depth))
        discard;
    vec3 n = v_normal;
    if (dot(n, sl_eye.xyz - v_center) < 0.0)
        n = -n;
    float d = max(dot(n, u_light_world), 0.0);
    o_color = vec4(u_ink * (PT_SPLAT_AMBIENT + (1.0 - PT_SPLAT_AMBIENT) * d), 1.0);
    gl_FragDepth = depth;
}
