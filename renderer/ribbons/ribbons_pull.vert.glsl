// ribbons_pull.vert.glsl — programmable pulling (Neuhauser et al., Sec. 5, Fig. 7 top): no
// vertex attributes; vertex gl_VertexID (basevertex included, GL 4.5 11.1.3.9) is ring slot
// j = id % N of dataset point id / N, fetched from the std430 buffers ribbons_prep.c packs.
// Used by the pulling mantle and caps, the geometry pipeline's caps, and `flat` (N = 2 with
// the ring table (0, -1), (0, 1): the quad x -/+ r b).
#include "gpu/glsl/camera.glsl"
#include "ribbons/ribbons_vertex.glsl"
#include "ribbons/ribbons_points.glsl"

uniform uint u_sides;

void main()
{
    uint point = uint(gl_VertexID) / u_sides;
    uint j = uint(gl_VertexID) % u_sides;
    sl_ribbon_emit(sl_ribbon_fetch(point), u_ring[j]);
}
