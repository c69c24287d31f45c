// tubes_nearest_depth.frag.glsl — third pass: a full-screen triangle writes the nearest hit
// depth of tubes_depth.frag.glsl into the depth buffer (pixels without a hit keep theirs).
layout(r32ui, binding = 0) uniform readonly uimage2D u_nearest;

void main()
{
    uint bits = imageLoad(u_nearest, ivec2(gl_FragCoord.xy)).r;
    if (bits == 0u)
        discard;
    gl_FragDepth = uintBitsToFloat(bits);
}
