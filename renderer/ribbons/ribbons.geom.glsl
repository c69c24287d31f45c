// ribbons.geom.glsl — geometry-shader extrusion (Neuhauser et al., Sec. 5, the geometry-shader
// baseline): one segment (a GL_LINES primitive of two dataset points) becomes the ring strip
// a_j, b_j, a_j+1, b_j+1, ... (the diagonals a_j+1 - b_j of the index pattern, so the same
// triangles as pulling; the strip's winding is the pattern's reversed, ribbons.c draws this
// pass with glFrontFace(GL_CW)). The output limit (21 components per vertex) is split over
// RB_GS_INVOCATIONS invocations of at most RB_GS_COLUMNS quads each (ribbons_pipelines.c picks
// both from GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS and GL_MAX_GEOMETRY_OUTPUT_VERTICES); the
// cap fans are drawn by the pulling vertex shader. shaders-check compiles I = 1 and 2.
#ifndef RB_GS_COLUMNS
#define RB_GS_COLUMNS 16
#endif
#include "gpu/glsl/camera.glsl"
#include "ribbons/ribbons_vertex.glsl"
#include "ribbons/ribbons_points.glsl"

layout(lines, invocations = RB_GS_INVOCATIONS) in;
layout(triangle_strip, max_vertices = 2 * (RB_GS_COLUMNS + 1)) out;

flat in uint g_point[];

uniform uint u_sides;

void main()
{
#if RB_GS_INVOCATIONS == 1
    uint j0 = 0u, j1 = u_sides;                    // the whole ring in one strip
#else
    uint j0 = uint(gl_InvocationID) * uint(RB_GS_COLUMNS);
    uint j1 = min(j0 + uint(RB_GS_COLUMNS), u_sides);
#endif
    if (j0 >= j1)
        return;
    RibbonPoint a = sl_ribbon_fetch(g_point[0]);
    RibbonPoint b = sl_ribbon_fetch(g_point[1]);
    for (uint j = j0; j <= j1; j++) {
        vec2 cs = u_ring[j % u_sides];
        sl_ribbon_emit(a, cs);
        EmitVertex();
        sl_ribbon_emit(b, cs);
        EmitVertex();
    }
    EndPrimitive();
}
