// tubes_prepass.vert.glsl — occluder pre-pass of `tubes` (beyond the paper): three spheres of
// each Hermite segment's sweep (its two nodes and the joint of its two quadratic halves), each
// drawn as a point sprite around its projection; tubes_prepass.frag.glsl writes the depth of the
// ray's entry into the sphere shrunk by SHRINK, so every pre-pass depth lies strictly behind the
// sweep's nearest entry and box fronts behind it can be rejected by early depth tests
// (tubes_depth.frag.glsl) before any root search. Programmable pulling: gl_VertexID =
// 3 * segment + which; nodes and segment index pairs come from shader storage (no vertex
// arrays). Segments whose bounding sphere reaches the near plane are skipped (there rays may
// start inside a sweep and see no entry).
#include "gpu/glsl/camera.glsl"

layout(std430, binding = 1) readonly buffer tubes_nodes_block { vec4 nodes[]; };     // p,r then t,dr
layout(std430, binding = 2) readonly buffer tubes_segments_block { uint segments[]; }; // node pairs

uniform float u_radius;
uniform float u_radius_scale;
uniform int u_data_radii;

const float SHRINK = 0.999; // radius kept: entries lie >= 1e-3 r behind the sweep's, far above float error

flat out vec4 v_sphere; // centre (relative to origin), shrunk radius

void drop()
{
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // outside the frustum: clipped
    gl_PointSize = 1.0;
}

void main()
{
    int segment = gl_VertexID / 3, which = gl_VertexID - 3 * segment;
    uint i = segments[2 * segment], j = segments[2 * segment + 1];
    vec4 n0 = nodes[2 * i], n1 = nodes[2 * j];
    vec4 d0 = nodes[2 * i + 1], d1 = nodes[2 * j + 1];
    float r0 = u_data_radii != 0 ? n0.w * u_radius_scale : u_radius;
    float r1 = u_data_radii != 0 ? n1.w * u_radius_scale : u_radius;
    float dr0 = u_data_radii != 0 ? d0.w * u_radius_scale : 0.0;
    float dr1 = u_data_radii != 0 ? d1.w * u_radius_scale : 0.0;
    // Bezier controls of the cubic (as tubes.geom.glsl) and the joint of its quadratic halves.
    vec3 a2 = n0.xyz + d0.xyz / 3.0, b2 = n1.xyz - d1.xyz / 3.0, m = 0.5 * (a2 + b2);
    float ra2 = r0 + dr0 / 3.0, rb2 = r1 - dr1 / 3.0, rm = 0.5 * (ra2 + rb2);
    vec3 centre = 0.5 * (n0.xyz + n1.xyz);
    float reach = max(max(length(n0.xyz - centre), length(n1.xyz - centre)),
                      max(length(a2 - centre), length(b2 - centre))) +
                  max(max(abs(r0), abs(r1)), max(abs(ra2), abs(rb2)));
    if (dot(centre - sl_eye.xyz, sl_forward.xyz) - reach <= 1.01 * sl_near.x) {
        drop();
        return;
    }
    vec3 p = which == 0 ? n0.xyz : (which == 1 ? m : n1.xyz);
    float r = abs(which == 0 ? r0 : (which == 1 ? rm : r1));
    float z = dot(p - sl_eye.xyz, sl_forward.xyz);
    // World size of one pixel in the plane through p perpendicular to F; the sprite bounds the
    // sphere's projection with room for perspective stretch (a smaller one only culls less).
    float pixel = 2.0 * sl_viewport.z * z / sl_viewport.y;
    v_sphere = vec4(p, SHRINK * r);
    gl_Position = sl_view_projection * vec4(p, 1.0);
    gl_PointSize = 2.6 * r / pixel * z / max(z - r, 1e-30) + 2.0;
}
