/* particles_hsr.c — the id pass of hidden-surface removal (particles_hsr.h). */
#include "particles_hsr.h"

#include <string.h>

#include "../gpu/sl_gpu.h"

sl_status pt_hsr_init(pt_hsr *h, sl_err *err)
{
    memset(h, 0, sizeof *h);
    return sl_gl_program_create(&(sl_program_desc){.vertex = "particles/particles_cone.vert.glsl",
                                                   .fragment = "particles/particles_cone.frag.glsl",
                                                   .label = "particles cones"},
                                &h->program, err);
}

static void release_target(pt_hsr *h)
{
    if (h->fbo) glDeleteFramebuffers(1, &h->fbo);
    if (h->ids) glDeleteTextures(1, &h->ids);
    if (h->depth) glDeleteTextures(1, &h->depth);
    h->fbo = h->ids = h->depth = 0;
    h->width = h->height = 0;
}

void pt_hsr_deinit(pt_hsr *h)
{
    release_target(h);
    if (h->program)
        glDeleteProgram(h->program);
    h->program = 0;
}

size_t pt_hsr_bytes(const pt_hsr *h)
{
    return (size_t)h->width * h->height * 8;
}

static sl_status ensure_target(pt_hsr *h, int w, int hgt, sl_err *err)
{
    if (h->fbo && h->width == w && h->height == hgt)
        return SL_OK;
    release_target(h);
    glCreateTextures(GL_TEXTURE_2D, 1, &h->ids);
    glTextureStorage2D(h->ids, 1, GL_R32UI, w, hgt);
    /* An integer texture is complete only with NEAREST filters. */
    glTextureParameteri(h->ids, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(h->ids, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glCreateTextures(GL_TEXTURE_2D, 1, &h->depth);
    glTextureStorage2D(h->depth, 1, GL_DEPTH_COMPONENT32F, w, hgt);
    glCreateFramebuffers(1, &h->fbo);
    glNamedFramebufferTexture(h->fbo, GL_COLOR_ATTACHMENT0, h->ids, 0);
    glNamedFramebufferTexture(h->fbo, GL_DEPTH_ATTACHMENT, h->depth, 0);
    if (glCheckNamedFramebufferStatus(h->fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        release_target(h);
        return sl_err_set(err, SL_ERR_GPU, "particles: the hidden-surface target (%dx%d) is incomplete", w, hgt);
    }
    h->width = w;
    h->height = hgt;
    return sl_gl_check_errors("particles: the hidden-surface target", err);
}

sl_status pt_hsr_draw(pt_hsr *h, const pt_frame *f, GLsizei count, double cone_radius, sl_err *err)
{
    sl_status st = ensure_target(h, f->view->width, f->view->height, err);
    if (st != SL_OK)
        return st;
    glBindFramebuffer(GL_FRAMEBUFFER, h->fbo);
    glViewport(0, 0, h->width, h->height);
    const GLuint zero[4] = {0, 0, 0, 0};
    const GLfloat far_depth = 0.0f;
    glClearNamedFramebufferuiv(h->fbo, GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(h->fbo, GL_DEPTH, 0, &far_depth);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glUseProgram(h->program);
    pt_frame_uniforms(h->program, f);
    glUniform1f(glGetUniformLocation(h->program, "u_cone_radius"), (float)cone_radius);
    glDrawArrays(GL_POINTS, 0, count);
    return SL_OK;
}
