// broken.frag.glsl — a fragment shader with a type error on line 11, for
// render.shaders.detects_compile_error: shaders-check must fail, naming this
// file and line 11 (after the pasted include, so the #line mapping is tested).
#include "gpu/glsl/lighting.glsl"

layout(location = 0) out vec4 o_color;

void main()
{
    vec3 c = vec3(1.0);
    float wrong = c;
    o_color = vec4(c * wrong, 1.0);
}
