// particles_marks.frag.glsl — a round stipple with analytic coverage (a
// one-pixel ramp at the rim), premultiplied for (ONE, ONE_MINUS_SRC_ALPHA)
// blending; fragments outside the dot are discarded so they write no depth.
flat in float v_diameter;
flat in vec3 v_color;    // the ink, or the curvature colour

layout(location = 0) out vec4 o_color;

void main()
{
    float size = v_diameter + 2.0;
    float r_px = length(gl_PointCoord - 0.5) * size;
    float coverage = clamp(0.5 * v_diameter - r_px + 0.5, 0.0, 1.0);
    if (coverage <= 0.0)
        discard;
    o_color = vec4(v_color * coverage, coverage);
}
