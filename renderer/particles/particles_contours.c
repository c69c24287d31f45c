/* particles_contours.c — contours of `particles` (particles_contours.h). */
#include "particles_contours.h"

#include <string.h>

#include "../gpu/sl_gpu.h"

#define PT_SEGMENT_BYTES 32 /* pt_segment of particles_contours.glsl */

sl_status pt_contours_init(pt_contours *c, sl_err *err)
{
    memset(c, 0, sizeof *c);
    sl_status st = sl_gl_program_create(&(sl_program_desc){.compute = "particles/particles_contours.comp.glsl",
                                                           .label = "particles contour selection"},
                                        &c->select, err);
    if (st == SL_OK)
        st = sl_gl_program_create(&(sl_program_desc){.vertex = "particles/particles_contours.vert.glsl",
                                                     .fragment = "particles/particles_contours.frag.glsl",
                                                     .label = "particles contours"},
                                  &c->draw, err);
    if (st != SL_OK)
        pt_contours_deinit(c);
    return st;
}

void pt_contours_deinit(pt_contours *c)
{
    if (c->select) glDeleteProgram(c->select);
    if (c->draw) glDeleteProgram(c->draw);
    if (c->segments) glDeleteBuffers(1, &c->segments);
    if (c->command) glDeleteBuffers(1, &c->command);
    memset(c, 0, sizeof *c);
}

size_t pt_contours_bytes(const pt_contours *c)
{
    return (size_t)c->capacity * PT_SEGMENT_BYTES + (c->command ? 16 : 0);
}

static sl_status ensure_capacity(pt_contours *c, uint32_t n, sl_err *err)
{
    if (!c->command) {
        glCreateBuffers(1, &c->command);
        glNamedBufferStorage(c->command, 16, NULL, GL_DYNAMIC_STORAGE_BIT);
    }
    if (c->segments && c->capacity >= n)
        return SL_OK;
    if (c->segments)
        glDeleteBuffers(1, &c->segments);
    c->capacity = 0;
    glCreateBuffers(1, &c->segments);
    glNamedBufferStorage(c->segments, (GLsizeiptr)n * PT_SEGMENT_BYTES, NULL, 0);
    sl_status st = sl_gl_check_errors("particles: the contour segment buffer", err);
    if (st != SL_OK) {
        glDeleteBuffers(1, &c->segments);
        c->segments = 0;
        return st;
    }
    c->capacity = n;
    return SL_OK;
}

sl_status pt_contours_draw(pt_contours *c, const pt_frame *f, const pt_set_view *sv, const sl_params *params,
                           double sigma, sl_err *err)
{
    uint32_t n = sv->set->stats.alive;
    if (n == 0)
        return SL_OK;
    sl_status st = ensure_capacity(c, n, err);
    if (st != SL_OK)
        return st;
    double nn = sv->set->stats.mean_nn;
    double band = sl_params_float(params, "contour_distance") * nn;
    double flat = sigma > 0.0 && band / sigma < 1.0 ? band / sigma : 1.0;
    const GLuint command[4] = {6, 0, 0, 0}; /* count, instanceCount, first, baseInstance */
    glNamedBufferSubData(c->command, 0, sizeof command, command);

    GLuint p = c->select;
    glUseProgram(p);
    pt_frame_uniforms(p, f);
    glUniform1i(glGetUniformLocation(p, "u_ids"), 0);
    glBindTextureUnit(0, sv->hsr ? sv->id_tex : 0);
    glUniform1i(glGetUniformLocation(p, "u_hsr"), sv->hsr);
    glUniform1ui(glGetUniformLocation(p, "u_count"), n);
    glUniform1f(glGetUniformLocation(p, "u_band"), (float)band);
    glUniform1f(glGetUniformLocation(p, "u_length"), (float)(sl_params_float(params, "contour_length") * nn));
    glUniform1f(glGetUniformLocation(p, "u_flat_limit"), (float)flat);
    glUniform1f(glGetUniformLocation(p, "u_mean_spacing"), (float)nn);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, c->segments);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, c->command);
    glDispatchCompute((n + 255) / 256, 1, 1); /* n <= 4e6 (max_particles): < 65535 groups */
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);

    p = c->draw;
    glUseProgram(p);
    glUniform1f(glGetUniformLocation(p, "u_width"), (float)sl_params_float(params, "contour_width"));
    glUniform1f(glGetUniformLocation(p, "u_depth_bias"), (float)(band + sl_params_float(params, "contour_length") * nn));
    glUniform3fv(glGetUniformLocation(p, "u_ink"), 1, sv->ink);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, c->command);
    glDrawArraysIndirect(GL_TRIANGLES, NULL);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    return SL_OK;
}
