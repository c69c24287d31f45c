// missing_include.vert.glsl — includes a file that is not embedded, for
// render.shaders.detects_missing_include: shaders-check must name it.
#include "gpu/glsl/no_such_file.glsl"

void main()
{
    gl_Position = vec4(0.0);
}
