// particles_splat.vert.glsl — splats (the paper's Fig. 10a, sec. 4.2.1: the
// hidden-surface cones drawn shaded): one cone sprite (particles_cone.glsl)
// per alive particle of the set that passes the visibility test (with
// hidden-surface removal: the id target holds this particle's id at its
// pixel); particles_splat.frag.glsl shades it.
#include "gpu/glsl/camera.glsl"
#include "particles/particles_record.glsl"
#include "particles/particles_cone.glsl"
#include "particles/particles_visible.glsl"

uniform usampler2D u_ids;
uniform int u_hsr;
uniform float u_cone_radius;   // world
uniform float u_max_point;

flat out vec3 v_center;
flat out vec3 v_normal;

void main()
{
    pt_record r = pt_rec[gl_VertexID];
    vec3 p = pt_view_position(r);
    vec4 clip = sl_view_projection * vec4(p, 1.0);
    v_center = p;
    v_normal = r.n_k1.xyz;
    if (!(clip.w > 0.0) || (u_hsr != 0 && !pt_hsr_visible(u_ids, clip, uint(gl_VertexID) + 1u))) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        gl_PointSize = 1.0;
        return;
    }
    gl_Position = clip;
    gl_PointSize = pt_cone_point_size(p, u_cone_radius, u_max_point);
}
