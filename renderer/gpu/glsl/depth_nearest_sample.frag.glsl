// depth_nearest_sample.frag.glsl — the depth of a multisampled target as one value per
// pixel (sl_depth_copy.c): the nearest surface among the pixel's samples (reversed-Z:
// the largest depth; 0 = nothing in any sample). A ray marched after opaque geometry
// then ends at the nearest surface its pixel holds, so a pixel with any surface in
// front of the volume keeps that surface's colour exactly.
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
