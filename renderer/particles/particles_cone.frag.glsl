// particles_cone.frag.glsl — the cone of one particle (Algorithm 3,
// particles_cone.glsl): fragments off its disk are cut, the rest write the
// cone's depth and the particle's id + 1.
#include "gpu/glsl/camera.glsl"
#include "particles/particles_record.glsl"
#include "particles/particles_cone.glsl"

uniform float u_cone_radius;

flat in uint v_id;
flat in vec3 v_center;
flat in vec3 v_normal;

layout(location = 0) out uint o_id;

void main()
{
    float depth;
    if (!pt_cone_fragment(gl_FragCoord.xy, v_center, v_normal, u_cone_radius, true, depth))
        discard;
    o_id = v_id;
    gl_FragDepth = depth;
}
