// tubes.frag.glsl — one-pass ray casting (the paper's, Russig et al. 3.2): casts the pixel's ray
// at one quadratic sub-segment's sphere sweep, keeps the nearest entry beyond the near plane,
// writes its depth and shades it (tubes_hit.glsl). Used with occlusion_prepass off; with it on,
// tubes_depth.frag.glsl and tubes_shade.frag.glsl split the same work around early depth tests.
#include "tubes/tubes_hit.glsl"

layout(depth_less) out float gl_FragDepth;
layout(location = 0) out vec4 o_color;

void main()
{
    tubes_hit h;
    if (!tubes_pixel_hit(h))
        discard;
    o_color = tubes_shade_hit(h);
    gl_FragDepth = h.depth;
}
