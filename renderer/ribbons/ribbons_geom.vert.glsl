// ribbons_geom.vert.glsl — vertex stage of `pipeline = geometry`: GL_LINES over the u32
// segment-pair index buffer; each vertex only hands its dataset point (gl_VertexID) to
// ribbons.geom.glsl, which fetches and extrudes.
flat out uint g_point;

void main()
{
    g_point = uint(gl_VertexID);
    gl_Position = vec4(0.0);
}
