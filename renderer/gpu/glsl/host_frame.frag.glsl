// host_frame.frag.glsl — a CPU-drawn frame into the target (gpu/sl_host_frame.h): colour and
// reversed-Z depth per pixel; pixels with depth 0 (nothing hit) keep what the target holds.
layout(binding = 0) uniform sampler2D u_color;
layout(binding = 1) uniform sampler2D u_depth;
layout(location = 0) out vec4 o_color;

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    float depth = texelFetch(u_depth, p, 0).r;
    if (!(depth > 0.0))
        discard;
    o_color = texelFetch(u_color, p, 0);
    gl_FragDepth = depth;
}
