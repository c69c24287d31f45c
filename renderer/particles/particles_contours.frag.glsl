// particles_contours.frag.glsl — a contour segment of constant pixel width
// with round caps: coverage = the width's half minus the distance to the
// projected segment, ramped over one pixel, premultiplied in the set's ink
// for (ONE, ONE_MINUS_SRC_ALPHA) blending; uncovered fragments are
// discarded.
uniform vec3 u_ink;
uniform float u_width;           // px

noperspective in vec2 v_local;
flat in float v_length;

layout(location = 0) out vec4 o_color;

void main()
{
    float beyond = max(max(-v_local.x, v_local.x - v_length), 0.0);
    float dist = length(vec2(beyond, v_local.y));
    float coverage = clamp(0.5 * u_width - dist + 0.5, 0.0, 1.0);
    if (coverage <= 0.0)
        discard;
    o_color = vec4(u_ink * coverage, coverage);
}
