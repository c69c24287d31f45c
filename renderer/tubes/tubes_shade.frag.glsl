// tubes_shade.frag.glsl — last pass: early depth tests (GL_GEQUAL) against the nearest hit depth
// leave only boxes whose front is not behind it; each repeats its root search and shades the
// pixel when its hit is the nearest. "The nearest" allows a few ulps: this program and
// tubes_depth.frag.glsl run the same code but are compiled apart, and two sub-segments meeting
// at a joint may hit within rounding of each other (they then shade the same surface point).
#include "tubes/tubes_hit.glsl"

layout(early_fragment_tests) in;
layout(r32ui, binding = 0) uniform readonly uimage2D u_nearest;
layout(location = 0) out vec4 o_color;

const int TUBES_NEAREST_ULPS = 8;

void main()
{
    tubes_hit h;
    if (!tubes_pixel_hit(h))
        discard;
    int nearest = int(imageLoad(u_nearest, ivec2(gl_FragCoord.xy)).r);
    if (abs(int(floatBitsToUint(h.depth)) - nearest) > TUBES_NEAREST_ULPS)
        discard;
    o_color = tubes_shade_hit(h);
}
