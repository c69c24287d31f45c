/* particles_stipple.c — stipples of `particles` (particles_stipple.h). */
#include "particles_stipple.h"

#include "../gpu/sl_gpu.h"

sl_status pt_stipple_init(pt_stipple *s, sl_err *err)
{
    s->program = 0;
    return sl_gl_program_create(&(sl_program_desc){.vertex = "particles/particles_marks.vert.glsl",
                                                   .fragment = "particles/particles_marks.frag.glsl",
                                                   .label = "particles stipples"},
                                &s->program, err);
}

void pt_stipple_deinit(pt_stipple *s)
{
    if (s->program)
        glDeleteProgram(s->program);
    s->program = 0;
}

double pt_stipple_draw(pt_stipple *s, const pt_frame *f, const pt_set_view *sv, const sl_params *params)
{
    GLuint p = s->program;
    GLsizei n = (GLsizei)sv->set->stats.alive;
    glUseProgram(p);
    pt_frame_uniforms(p, f);
    glUniform1i(glGetUniformLocation(p, "u_ids"), 0);
    glBindTextureUnit(0, sv->hsr ? sv->id_tex : 0);
    glUniform1i(glGetUniformLocation(p, "u_hsr"), sv->hsr);
    glUniform3fv(glGetUniformLocation(p, "u_light_world"), 1, f->light_world);
    glUniform1f(glGetUniformLocation(p, "u_mean_spacing"), (float)sv->set->stats.mean_nn);
    glUniform1f(glGetUniformLocation(p, "u_stipple_size"), (float)sl_params_float(params, "stipple_size"));
    glUniform1f(glGetUniformLocation(p, "u_brightness"), (float)sl_params_float(params, "stipple_brightness"));
    glUniform1f(glGetUniformLocation(p, "u_contrast"), (float)sl_params_float(params, "stipple_contrast"));
    glUniform1i(glGetUniformLocation(p, "u_ink_dark"), sv->ink_dark);
    glUniform3fv(glGetUniformLocation(p, "u_ink"), 1, sv->ink);
    pt_tf2d_uniforms(p, &sv->curvature, 1);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glDrawArrays(GL_POINTS, 0, n);
    glDisable(GL_BLEND);
    glBindTextureUnit(1, 0);
    return n;
}
