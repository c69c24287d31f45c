/* particles_splat.c — splats of `particles` (particles_splat.h). */
#include "particles_splat.h"

#include "../gpu/sl_gpu.h"

sl_status pt_splat_init(pt_splat *s, sl_err *err)
{
    s->program = 0;
    return sl_gl_program_create(&(sl_program_desc){.vertex = "particles/particles_splat.vert.glsl",
                                                   .fragment = "particles/particles_splat.frag.glsl",
                                                   .label = "particles splats"},
                                &s->program, err);
}

void pt_splat_deinit(pt_splat *s)
{
    if (s->program)
        glDeleteProgram(s->program);
    s->program = 0;
}

double pt_splat_draw(pt_splat *s, const pt_frame *f, const pt_set_view *sv, double cone_radius)
{
    GLuint p = s->program;
    GLsizei n = (GLsizei)sv->set->stats.alive;
    glUseProgram(p);
    pt_frame_uniforms(p, f);
    glUniform1i(glGetUniformLocation(p, "u_ids"), 0);
    glBindTextureUnit(0, sv->hsr ? sv->id_tex : 0);
    glUniform1i(glGetUniformLocation(p, "u_hsr"), sv->hsr);
    glUniform1f(glGetUniformLocation(p, "u_cone_radius"), (float)cone_radius);
    glUniform3fv(glGetUniformLocation(p, "u_light_world"), 1, f->light_world);
    glUniform3fv(glGetUniformLocation(p, "u_ink"), 1, sv->ink);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDrawArrays(GL_POINTS, 0, n);
    return n;
}
