/* gl_errors.c — the GL errors a prepare's allocations raised, as an sl_status.
 *
 * glNamedBufferStorage and glTexStorage* report an out-of-memory only through
 * glGetError; a technique that never asks draws from buffers that do not
 * exist. sl_gl_check_errors drains every pending error and names the first.
 * sl_gl_inject_error lets a test make the next check fail as a real
 * GL_OUT_OF_MEMORY would (the fault cannot be provoked on demand). Render
 * thread only (the GL context's thread, like every GL call).
 */
#include "sl_gpu.h"

static GLenum injected = GL_NO_ERROR; /* render thread only */

static const char *gl_error_name(GLenum e)
{
    switch (e) {
    case GL_OUT_OF_MEMORY: return "out of GPU memory (GL_OUT_OF_MEMORY)";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE (a size above the GPU's limit?)";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    default: return "GL error";
    }
}

sl_status sl_gl_check_errors(const char *what, sl_err *err)
{
    GLenum first = injected;
    injected = GL_NO_ERROR;
    for (GLenum e; (e = glGetError()) != GL_NO_ERROR;)
        if (first == GL_NO_ERROR)
            first = e;
    if (first == GL_NO_ERROR)
        return SL_OK;
    return sl_err_set(err, SL_ERR_GPU, "%s: %s (0x%x)", what, gl_error_name(first), (unsigned)first);
}

void sl_gl_inject_error(GLenum error)
{
    injected = error;
}
