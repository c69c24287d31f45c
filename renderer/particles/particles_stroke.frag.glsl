// particles_stroke.frag.glsl — one hatch segment: coverage of the capsule of
// radius u_half_width px around the projected segment, with a one-pixel ramp
// at its rim (anti-aliasing across the width), premultiplied for (ONE,
// ONE_MINUS_SRC_ALPHA) blending; fragments outside are discarded so they
// write no depth.
uniform float u_half_width;

noperspective in vec2 v_px;
flat in float v_length;
flat in vec3 v_color;

layout(location = 0) out vec4 o_color;

void main()
{
    float t = clamp(v_px.x, 0.0, v_length);
    float dist = length(vec2(v_px.x - t, v_px.y));
    float coverage = clamp(u_half_width - dist + 0.5, 0.0, 1.0);
    if (coverage <= 0.0)
        discard;
    o_color = vec4(v_color * coverage, coverage);
}
