// tubes_depth.frag.glsl — second pass after the occluder pre-pass: early depth tests against the
// pre-pass depth (a box front behind it cannot win, tubes_prepass.vert.glsl) keep llvmpipe and
// GPUs from running the root search for hidden boxes at all; surviving fragments fold their hit
// depth into the per-pixel nearest (reversed-Z: larger is nearer; positive floats order as
// their bits) with an atomic max. Writes neither colour nor depth.
#include "tubes/tubes_hit.glsl"

layout(early_fragment_tests) in;
layout(r32ui, binding = 0) uniform coherent uimage2D u_nearest;

void main()
{
    tubes_hit h;
    if (tubes_pixel_hit(h))
        imageAtomicMax(u_nearest, ivec2(gl_FragCoord.xy), floatBitsToUint(h.depth));
}
