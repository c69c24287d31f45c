/* host_frame.c — sl_host_frame.h: host colour + depth into the bound target. */
#include <stdlib.h>

#include "sl_gpu.h"
#include "sl_host_frame.h"

static void delete_textures(sl_host_frame *f)
{
    if (f->color_tex)
        glDeleteTextures(1, &f->color_tex);
    if (f->depth_tex)
        glDeleteTextures(1, &f->depth_tex);
    f->color_tex = f->depth_tex = 0;
}

sl_status sl_host_frame_resize(sl_host_frame *f, int width, int height, sl_err *err)
{
    if (width < 1 || height < 1)
        return sl_err_set(err, SL_ERR_INVALID, "host frame: size %dx%d", width, height);
    if (!f->program) {
        sl_status st = sl_gl_program_create(&(sl_program_desc){.vertex = "gpu/glsl/fullscreen_triangle.vert.glsl",
                                                               .fragment = "gpu/glsl/host_frame.frag.glsl",
                                                               .label = "host_frame"},
                                            &f->program, err);
        if (st != SL_OK)
            return st;
        glCreateVertexArrays(1, &f->vao);
    }
    if (f->width == width && f->height == height && f->rgba)
        return SL_OK;
    size_t n = (size_t)width * (size_t)height;
    uint8_t *rgba = malloc(n * 4);
    float *depth = malloc(n * sizeof(float));
    if (!rgba || !depth) {
        free(rgba);
        free(depth);
        return sl_err_set(err, SL_ERR_NOMEM, "host frame: out of memory for %dx%d", width, height);
    }
    free(f->rgba);
    free(f->depth);
    f->rgba = rgba;
    f->depth = depth;
    delete_textures(f);
    glCreateTextures(GL_TEXTURE_2D, 1, &f->color_tex);
    glTextureStorage2D(f->color_tex, 1, GL_RGBA8, width, height);
    glCreateTextures(GL_TEXTURE_2D, 1, &f->depth_tex);
    glTextureStorage2D(f->depth_tex, 1, GL_R32F, width, height);
    f->width = width;
    f->height = height;
    return sl_gl_check_errors("host frame: textures", err);
}

sl_status sl_host_frame_draw(sl_host_frame *f, sl_err *err)
{
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTextureSubImage2D(f->color_tex, 0, 0, 0, f->width, f->height, GL_RGBA, GL_UNSIGNED_BYTE, f->rgba);
    glTextureSubImage2D(f->depth_tex, 0, 0, 0, f->width, f->height, GL_RED, GL_FLOAT, f->depth);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glUseProgram(f->program);
    glBindTextureUnit(0, f->color_tex);
    glBindTextureUnit(1, f->depth_tex);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    if (f->premultiplied) {
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    } else {
        glDisable(GL_BLEND);
    }
    glDisable(GL_CULL_FACE);
    glBindVertexArray(f->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    glBindTextureUnit(0, 0);
    glBindTextureUnit(1, 0);
    return sl_gl_check_errors("host frame: draw", err);
}

void sl_host_frame_deinit(sl_host_frame *f)
{
    if (!f)
        return;
    delete_textures(f);
    if (f->program)
        glDeleteProgram(f->program);
    if (f->vao)
        glDeleteVertexArrays(1, &f->vao);
    free(f->rgba);
    free(f->depth);
    *f = (sl_host_frame){0};
}

size_t sl_host_frame_gpu_bytes(const sl_host_frame *f)
{
    return f->color_tex ? (size_t)f->width * (size_t)f->height * 8u : 0;
}
