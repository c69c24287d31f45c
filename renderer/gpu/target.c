/* target.c — offscreen render targets and readback (see sl_gpu.h).
 *
 * Colour RGBA8 + depth 32F. Depth is reversed-Z (sl_camera.h): cleared to 0,
 * tested with GL_GREATER, clip control GL_ZERO_TO_ONE. With MSAA the frame is
 * rendered into multisample textures and resolved by a blit (depth: the
 * first sample, as NEAREST requires). Render thread only.
 */
#include "sl_gpu.h"

#include <stdlib.h>
#include <string.h>

static GLuint make_texture(GLenum format, int w, int h, int samples)
{
    GLuint tex;
    if (samples > 1) {
        glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &tex);
        glTextureStorage2DMultisample(tex, samples, format, w, h, GL_TRUE);
    } else {
        glCreateTextures(GL_TEXTURE_2D, 1, &tex);
        glTextureStorage2D(tex, 1, format, w, h);
        glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    return tex;
}

static sl_status make_fbo(GLuint color, GLuint depth, GLuint *fbo, sl_err *err)
{
    glCreateFramebuffers(1, fbo);
    glNamedFramebufferTexture(*fbo, GL_COLOR_ATTACHMENT0, color, 0);
    glNamedFramebufferTexture(*fbo, GL_DEPTH_ATTACHMENT, depth, 0);
    GLenum status = glCheckNamedFramebufferStatus(*fbo, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        return sl_err_set(err, SL_ERR_GPU, "framebuffer incomplete (0x%x)", status);
    return SL_OK;
}

static GLint min_limit(const GLenum *names, int n)
{
    GLint best = 0;
    for (int i = 0; i < n; i++) {
        GLint v = 0;
        glGetIntegerv(names[i], &v);
        if (i == 0 || v < best)
            best = v;
    }
    return best;
}

sl_status sl_target_check(int width, int height, int samples, sl_err *err)
{
    /* Colour and depth are textures (multisampled ones with MSAA) attached
     * to one framebuffer: every one of these limits applies. */
    static const GLenum size_limits[] = {GL_MAX_TEXTURE_SIZE, GL_MAX_RENDERBUFFER_SIZE, GL_MAX_FRAMEBUFFER_WIDTH,
                                         GL_MAX_FRAMEBUFFER_HEIGHT};
    static const GLenum sample_limits[] = {GL_MAX_SAMPLES, GL_MAX_COLOR_TEXTURE_SAMPLES, GL_MAX_DEPTH_TEXTURE_SAMPLES};
    GLint max_size = min_limit(size_limits, 4);
    GLint max_samples = min_limit(sample_limits, 3);
    if (width < 1 || height < 1 || width > max_size || height > max_size)
        return sl_err_set(err, width < 1 || height < 1 ? SL_ERR_INVALID : SL_ERR_UNSUPPORTED,
                          "target size %dx%d is outside 1..%d on this GPU", width, height, (int)max_size);
    if (samples > 1 && samples > max_samples)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "%d MSAA samples requested, this GPU offers at most %d", samples,
                          (int)max_samples);
    return SL_OK;
}

sl_status sl_target_init(sl_target *t, int width, int height, int samples, sl_err *err)
{
    memset(t, 0, sizeof *t);
    sl_status check = sl_target_check(width, height, samples, err);
    if (check != SL_OK)
        return check;
    t->width = width;
    t->height = height;
    t->samples = samples > 1 ? samples : 1;
    t->color = make_texture(GL_RGBA8, width, height, t->samples);
    t->depth = make_texture(GL_DEPTH_COMPONENT32F, width, height, t->samples);
    sl_status st = make_fbo(t->color, t->depth, &t->fbo, err);
    if (st == SL_OK && t->samples > 1) {
        t->resolve_color = make_texture(GL_RGBA8, width, height, 1);
        t->resolve_depth = make_texture(GL_DEPTH_COMPONENT32F, width, height, 1);
        st = make_fbo(t->resolve_color, t->resolve_depth, &t->resolve_fbo, err);
    } else {
        t->resolve_fbo = t->fbo;
        t->resolve_color = t->color;
        t->resolve_depth = t->depth;
    }
    if (st != SL_OK)
        sl_target_deinit(t);
    return st;
}

void sl_target_deinit(sl_target *t)
{
    if (t->resolve_fbo && t->resolve_fbo != t->fbo) {
        glDeleteFramebuffers(1, &t->resolve_fbo);
        glDeleteTextures(1, &t->resolve_color);
        glDeleteTextures(1, &t->resolve_depth);
    }
    if (t->fbo) glDeleteFramebuffers(1, &t->fbo);
    if (t->color) glDeleteTextures(1, &t->color);
    if (t->depth) glDeleteTextures(1, &t->depth);
    memset(t, 0, sizeof *t);
}

void sl_target_begin(sl_target *t, const float background[4])
{
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glViewport(0, 0, t->width, t->height);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glDisable(GL_SCISSOR_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glClearDepthf(0.0f);
    glClearColor(background[0], background[1], background[2], background[3]);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    if (t->samples > 1)
        glEnable(GL_MULTISAMPLE);
}

void sl_target_resolve(sl_target *t)
{
    if (t->resolve_fbo == t->fbo)
        return;
    glBlitNamedFramebuffer(t->fbo, t->resolve_fbo, 0, 0, t->width, t->height,
                           0, 0, t->width, t->height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBlitNamedFramebuffer(t->fbo, t->resolve_fbo, 0, 0, t->width, t->height,
                           0, 0, t->width, t->height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

static void flip_rows(uint8_t *data, size_t row_bytes, int rows)
{
    uint8_t *tmp = malloc(row_bytes);
    if (!tmp)
        return;
    for (int y = 0; y < rows / 2; y++) {
        uint8_t *a = data + (size_t)y * row_bytes, *b = data + (size_t)(rows - 1 - y) * row_bytes;
        memcpy(tmp, a, row_bytes);
        memcpy(a, b, row_bytes);
        memcpy(b, tmp, row_bytes);
    }
    free(tmp);
}

void sl_target_read_rgba(sl_target *t, uint8_t *rgba, int top_down)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t->resolve_fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, t->width, t->height, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    if (top_down)
        flip_rows(rgba, (size_t)t->width * 4, t->height);
}

void sl_target_read_depth(sl_target *t, float *depth)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t->resolve_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, t->width, t->height, GL_DEPTH_COMPONENT, GL_FLOAT, depth);
    flip_rows((uint8_t *)depth, (size_t)t->width * sizeof(float), t->height);
}

void sl_gpu_timer_init(sl_gpu_timer *t)
{
    glGenQueries(1, &t->query);
    t->running = 0;
}

void sl_gpu_timer_deinit(sl_gpu_timer *t)
{
    if (t->query)
        glDeleteQueries(1, &t->query);
    t->query = 0;
}

void sl_gpu_timer_begin(sl_gpu_timer *t)
{
    glBeginQuery(GL_TIME_ELAPSED, t->query);
    t->running = 1;
}

double sl_gpu_timer_end_ms(sl_gpu_timer *t)
{
    if (!t->running)
        return 0.0;
    glEndQuery(GL_TIME_ELAPSED);
    t->running = 0;
    GLuint64 ns = 0;
    glGetQueryObjectui64v(t->query, GL_QUERY_RESULT, &ns);
    return (double)ns * 1e-6;
}
