// particles_cone.vert.glsl — hidden-surface removal, pass 1 (the paper's
// Algorithm 3): every alive particle of the set as a cone sprite, a point
// large enough for its tangent disk of radius u_cone_radius (world) on
// screen (particles_cone.glsl); particles_cone.frag.glsl cuts the disk and
// writes the cone's depth and the particle's id + 1 into the id target.
// Particles inside the focus sphere cast no cone.
#include "gpu/glsl/camera.glsl"
#include "particles/particles_record.glsl"
#include "particles/particles_cone.glsl"

uniform float u_cone_radius;
uniform float u_max_point;

flat out uint v_id;
flat out vec3 v_center;
flat out vec3 v_normal;

void main()
{
    pt_record r = pt_rec[gl_VertexID];
    vec3 p = pt_view_position(r);
    v_id = uint(gl_VertexID) + 1u;
    v_center = p;
    v_normal = r.n_k1.xyz;
    if (pt_in_focus(r.x.xyz)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        gl_PointSize = 1.0;
        return;
    }
    gl_Position = sl_view_projection * vec4(p, 1.0);
    gl_PointSize = pt_cone_point_size(p, u_cone_radius, u_max_point);
}
