/* depth_copy.c — a target's depth copied into a texture (sl_depth_copy.h).
 * The copy is remade only when the target's size or sample count changes.
 */
#include "sl_depth_copy.h"

#include <string.h>

static void release_texture(sl_depth_copy *dc)
{
    if (dc->fbo) glDeleteFramebuffers(1, &dc->fbo);
    if (dc->texture) glDeleteTextures(1, &dc->texture);
    dc->fbo = dc->texture = 0;
    dc->width = dc->height = dc->msaa = 0;
}

void sl_depth_copy_deinit(sl_depth_copy *dc)
{
    if (!dc)
        return;
    release_texture(dc);
    if (dc->resolve_program) glDeleteProgram(dc->resolve_program);
    if (dc->vao) glDeleteVertexArrays(1, &dc->vao);
    memset(dc, 0, sizeof *dc);
}

size_t sl_depth_copy_bytes(const sl_depth_copy *dc)
{
    return (size_t)dc->width * (size_t)dc->height * 4;
}

static sl_status ensure_texture(sl_depth_copy *dc, int w, int h, int msaa, sl_err *err)
{
    if (msaa && !dc->resolve_program) {
        sl_status st = sl_gl_program_create(&(sl_program_desc){.vertex = "gpu/glsl/fullscreen_triangle.vert.glsl",
                                                               .fragment = "gpu/glsl/depth_nearest_sample.frag.glsl",
                                                               .label = "depth copy: nearest sample"},
                                            &dc->resolve_program, err);
        if (st != SL_OK)
            return st;
        glCreateVertexArrays(1, &dc->vao);
    }
    if (dc->fbo && dc->width == w && dc->height == h && dc->msaa == msaa)
        return SL_OK;
    release_texture(dc);
    glCreateTextures(GL_TEXTURE_2D, 1, &dc->texture);
    glTextureStorage2D(dc->texture, 1, msaa ? GL_R32F : GL_DEPTH_COMPONENT32F, w, h);
    glTextureParameteri(dc->texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(dc->texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glCreateFramebuffers(1, &dc->fbo);
    if (msaa) {
        glNamedFramebufferTexture(dc->fbo, GL_COLOR_ATTACHMENT0, dc->texture, 0);
        glNamedFramebufferDrawBuffer(dc->fbo, GL_COLOR_ATTACHMENT0);
    } else {
        glNamedFramebufferTexture(dc->fbo, GL_DEPTH_ATTACHMENT, dc->texture, 0);
        glNamedFramebufferDrawBuffer(dc->fbo, GL_NONE);
    }
    glNamedFramebufferReadBuffer(dc->fbo, GL_NONE);
    if (glCheckNamedFramebufferStatus(dc->fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        release_texture(dc);
        return sl_err_set(err, SL_ERR_GPU, "depth copy: the %dx%d copy is incomplete", w, h);
    }
    dc->width = w;
    dc->height = h;
    dc->msaa = msaa;
    return sl_gl_check_errors("depth copy: creating the texture", err);
}

sl_status sl_depth_copy_update(sl_depth_copy *dc, const sl_target *target, sl_err *err)
{
    int msaa = target->samples > 1;
    sl_status st = ensure_texture(dc, target->width, target->height, msaa, err);
    if (st != SL_OK)
        return st;
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    if (msaa) {
        /* The target's depth texture is read, not attached: no feedback. */
        glBindFramebuffer(GL_FRAMEBUFFER, dc->fbo);
        glViewport(0, 0, target->width, target->height);
        glUseProgram(dc->resolve_program);
        glUniform1i(glGetUniformLocation(dc->resolve_program, "u_depth"), 0);
        glUniform1i(glGetUniformLocation(dc->resolve_program, "u_samples"), target->samples);
        glBindTextureUnit(0, target->depth);
        glBindVertexArray(dc->vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glBindVertexArray(0);
        glBindTextureUnit(0, 0);
    } else {
        glBlitNamedFramebuffer(target->fbo, dc->fbo, 0, 0, target->width, target->height, 0, 0, target->width,
                               target->height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, target->fbo);
    glViewport(0, 0, target->width, target->height);
    return SL_OK;
}
