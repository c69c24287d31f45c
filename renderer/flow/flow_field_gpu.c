/* flow_field_gpu.c — a regular vector field as the GPU reads it
 * (flow_gpu.h; flow_field_regular.glsl): its voxels in an RGBA32F 3D
 * texture (exact floats, nearest filter: the shader interpolates by
 * texelFetch in the CPU's order) and the uniforms that place it. Shared by
 * the streamline driver (flow_gpu.c) and sightline-probe --gpu
 * (probe/probe_gpu.c). Render thread only; the field's volume is read during
 * the upload only.
 */
#include <stdlib.h>

#include "../gpu/sl_gpu.h"
#include "flow_gpu.h"

sl_status sl_flow_field_texture_create(const sl_flow_field *f, GLuint *texture, sl_err *err)
{
    *texture = 0;
    if (f->kind != SL_FLOW_FIELD_REGULAR || !f->volume)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "only a regular vector field has a field texture");
    size_t n = (size_t)f->dims[0] * (size_t)f->dims[1] * (size_t)f->dims[2];
    float *rgba = malloc(4 * n * sizeof *rgba);
    if (!rgba)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the field texture");
    const float *src = f->volume->data;
    for (size_t i = 0; i < n; i++) {
        rgba[4 * i] = src[3 * i];
        rgba[4 * i + 1] = src[3 * i + 1];
        rgba[4 * i + 2] = src[3 * i + 2];
        rgba[4 * i + 3] = 0.0f;
    }
    sl_err stale = {0};
    sl_gl_check_errors("before the flow field upload", &stale); /* clears errors not ours */
    glGenTextures(1, texture);
    glBindTexture(GL_TEXTURE_3D, *texture);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_RGBA32F, f->dims[0], f->dims[1], f->dims[2], 0, GL_RGBA, GL_FLOAT, rgba);
    glBindTexture(GL_TEXTURE_3D, 0);
    free(rgba);
    sl_status st = sl_gl_check_errors("uploading the flow field texture", err);
    if (st != SL_OK) {
        glDeleteTextures(1, texture);
        *texture = 0;
    }
    return st;
}

void sl_flow_field_texture_bind(GLuint program, const sl_flow_field *f, GLuint texture, int doubles)
{
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_3D, texture);
    glUniform1i(glGetUniformLocation(program, "u_field"), 0);
    glUniform3i(glGetUniformLocation(program, "u_dims"), f->dims[0], f->dims[1], f->dims[2]);
    glUniform3f(glGetUniformLocation(program, "u_origin_f"), (float)f->origin[0], (float)f->origin[1],
                (float)f->origin[2]);
    glUniform3f(glGetUniformLocation(program, "u_spacing_f"), (float)f->spacing[0], (float)f->spacing[1],
                (float)f->spacing[2]);
    if (doubles) {
        glUniform3d(glGetUniformLocation(program, "u_origin_d"), f->origin[0], f->origin[1], f->origin[2]);
        glUniform3d(glGetUniformLocation(program, "u_spacing_d"), f->spacing[0], f->spacing[1], f->spacing[2]);
    }
}
