// tubes_nearest_depth.frag.glsl — third pass: a full-screen triangle writes the nearest hit
// depth of tubes_depth.frag.glsl into the depth buffer, 0 (nothing) where no box found a hit:
// the pre-pass depth never stays, also where a root search missed a sphere the pre-pass drew.
layout(r32ui, binding = 0) uniform readonly uimage2D u_nearest;

void main()
{
    gl_FragDepth = uintBitsToFloat(imageLoad(u_nearest, ivec2(gl_FragCoord.xy)).r);
}
