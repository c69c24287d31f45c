// broken_variant.comp.glsl — compiles with MODE == 1 but not in its #else
// branch, for render.shaders.detects_variant_error: shaders-check must try
// MODE=2 (the technique would pass it as a define) and fail there.
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer data_block { uint data[]; };

void main()
{
#if MODE == 1
    data[gl_GlobalInvocationID.x] = 1u;
#else
    data[gl_GlobalInvocationID.x] = undeclared_value;
#endif
}
