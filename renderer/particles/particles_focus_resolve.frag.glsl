// particles_focus_resolve.frag.glsl — the marks' depth of a multisampled
// target as one value per pixel for the focus marcher (particles_focus.c):
// the nearest mark among the pixel's samples (reversed-Z: the largest
// depth; 0 = no mark in any sample). A ray then ends at the nearest mark
// its pixel holds, so a pixel with any mark in front of the focus sphere is
// left exactly as the marks drew it.
uniform sampler2DMS u_depth;
uniform int u_samples;

layout(location = 0) out float o_depth;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    float d = 0.0;
    for (int s = 0; s < u_samples; s++)
        d = max(d, texelFetch(u_depth, px, s).r);
    o_depth = d;
}
