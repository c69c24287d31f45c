/* unbind.c — makes the driver let go of the buffers a released technique state last drew.
 *
 * Mesa's state tracker (and llvmpipe's draw module under it) keep a
 * reference to the vertex and index buffers of the last draw until the next
 * draw validates other state, so glDeleteBuffers alone leaves the buffers of
 * the most recently drawn scene allocated (102 MB for tornado with
 * tubes_mesh, measured in the server's resident memory). One indexed draw
 * of one point, with a one-vertex buffer and a trivial program, into a 1x1
 * target replaces those bindings (a draw without attributes or with
 * rasterizer discard did not: measured, the memory stayed); every GL name
 * it makes is deleted before it returns and the bindings it touched are
 * back to 0. Costs a shader compile (milliseconds): for occasional use after
 * a release, not per frame. Render thread (the context must be current).
 */
#include "sl_gpu.h"

#include <epoxy/gl.h>

static const char *const vertex_src = "#version 450 core\nvoid main() { gl_Position = vec4(0.0, 0.0, 0.0, 1.0); }\n";
static const char *const fragment_src = "#version 450 core\nout vec4 color;\nvoid main() { color = vec4(0.0); }\n";

void sl_gpu_drop_references(void)
{
    GLuint vs = glCreateShader(GL_VERTEX_SHADER), fs = glCreateShader(GL_FRAGMENT_SHADER);
    glShaderSource(vs, 1, &vertex_src, NULL);
    glShaderSource(fs, 1, &fragment_src, NULL);
    glCompileShader(vs);
    glCompileShader(fs);
    GLuint program = glCreateProgram();
    glAttachShader(program, vs);
    glAttachShader(program, fs);
    glLinkProgram(program);
    GLint linked = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &linked);
    GLuint vao = 0, buffers[2] = {0, 0};
    glCreateVertexArrays(1, &vao);
    glCreateBuffers(2, buffers);
    const float vertex[4] = {0, 0, 0, 1};
    const GLuint index = 0;
    glNamedBufferData(buffers[0], sizeof vertex, vertex, GL_STATIC_DRAW);
    glNamedBufferData(buffers[1], sizeof index, &index, GL_STATIC_DRAW);
    glVertexArrayVertexBuffer(vao, 0, buffers[0], 0, sizeof vertex);
    glVertexArrayAttribFormat(vao, 0, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 0, 0);
    glEnableVertexArrayAttrib(vao, 0);
    glVertexArrayElementBuffer(vao, buffers[1]);
    sl_target t = {0};
    sl_err err = {0};
    if (linked && sl_target_init(&t, 1, 1, 1, &err) == SL_OK) {
        const float clear[4] = {0, 0, 0, 0};
        sl_target_begin(&t, clear);
        glUseProgram(program);
        glBindVertexArray(vao);
        glDrawElements(GL_POINTS, 1, GL_UNSIGNED_INT, NULL);
        glBindVertexArray(0);
        glUseProgram(0);
    }
    glFinish();
    sl_target_deinit(&t);
    glDeleteBuffers(2, buffers);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(program);
    glDeleteShader(vs);
    glDeleteShader(fs);
}
