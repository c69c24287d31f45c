/* particles_focus.c — focus + context of `particles` (particles_focus.h).
 *
 * The depth model: the marks are drawn first with depth GREATER (reversed-Z)
 * and writes on; their depth is copied to `depth` (the marcher must not read
 * the attachment it writes). The marcher's ray interval inside the sphere
 * and the box ends at the mark's eye distance, its premultiplied colour is
 * blended (ONE, ONE_MINUS_SRC_ALPHA) over the target, and it writes
 * max(mark, its own A > 0.5 depth): a mark in front of the sphere keeps its
 * pixel byte for byte, one behind it is covered as much as the volume's
 * opacity says. With MSAA the marcher still shades once per pixel for all
 * its samples, so the copy must pick one mark depth per pixel: a blit would
 * resolve one sample (implementation-defined; Mesa: sample 0), drawing the
 * volume over a mark in front of the sphere wherever that sample missed
 * it. The resolve pass (particles_focus_resolve.frag.glsl) takes the
 * nearest mark among the samples instead: a pixel holding any mark in front
 * of the sphere stays byte-equal to the marks alone, at the price of no
 * volume in the uncovered samples of such a rim pixel.
 */
#include "particles_focus.h"

#include <string.h>

void pt_focus_init(pt_focus *f, const sl_volume *data, const sl_volume_texture *volume,
                   const sl_volume_geometry *geom)
{
    memset(f, 0, sizeof *f);
    f->data = data;
    f->volume = volume;
    f->geom = geom;
}

static void release_copy(pt_focus *f)
{
    if (f->fbo) glDeleteFramebuffers(1, &f->fbo);
    if (f->depth) glDeleteTextures(1, &f->depth);
    f->fbo = f->depth = 0;
    f->width = f->height = f->msaa = 0;
}

void pt_focus_deinit(pt_focus *f)
{
    if (!f)
        return;
    release_copy(f);
    if (f->resolve_program) glDeleteProgram(f->resolve_program);
    if (f->vao) glDeleteVertexArrays(1, &f->vao);
    f->resolve_program = f->vao = 0;
    if (f->ready) {
        sl_volume_marcher_deinit(&f->marcher);
        sl_volume_bricks_destroy(&f->bricks);
    }
    f->ready = 0;
}

size_t pt_focus_bytes(const pt_focus *f)
{
    if (!f->ready)
        return 0;
    return f->bricks.bytes + f->marcher.bytes + (size_t)f->width * f->height * 4;
}

/* The bricks and the marcher, once (the marcher compiles its plain program
 * at init and the focus variant at its first draw). */
static sl_status ensure_ready(pt_focus *f, sl_err *err)
{
    if (f->ready)
        return SL_OK;
    sl_status st = sl_volume_bricks_create(f->data, &f->bricks, err);
    if (st != SL_OK)
        return st;
    if ((st = sl_volume_marcher_init(&f->marcher, f->data, err)) != SL_OK) {
        sl_volume_bricks_destroy(&f->bricks);
        return st;
    }
    f->ready = 1;
    return SL_OK;
}

static sl_status ensure_copy(pt_focus *f, int w, int h, int msaa, sl_err *err)
{
    if (msaa && !f->resolve_program) {
        sl_status st = sl_gl_program_create(&(sl_program_desc){.vertex = "gpu/glsl/fullscreen_triangle.vert.glsl",
                                                               .fragment = "particles/particles_focus_resolve.frag.glsl",
                                                               .label = "particles focus depth resolve"},
                                            &f->resolve_program, err);
        if (st != SL_OK)
            return st;
        glCreateVertexArrays(1, &f->vao);
    }
    if (f->fbo && f->width == w && f->height == h && f->msaa == msaa)
        return SL_OK;
    release_copy(f);
    glCreateTextures(GL_TEXTURE_2D, 1, &f->depth);
    glTextureStorage2D(f->depth, 1, msaa ? GL_R32F : GL_DEPTH_COMPONENT32F, w, h);
    glTextureParameteri(f->depth, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(f->depth, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glCreateFramebuffers(1, &f->fbo);
    if (msaa) {
        glNamedFramebufferTexture(f->fbo, GL_COLOR_ATTACHMENT0, f->depth, 0);
        glNamedFramebufferDrawBuffer(f->fbo, GL_COLOR_ATTACHMENT0);
    } else {
        glNamedFramebufferTexture(f->fbo, GL_DEPTH_ATTACHMENT, f->depth, 0);
        glNamedFramebufferDrawBuffer(f->fbo, GL_NONE);
    }
    glNamedFramebufferReadBuffer(f->fbo, GL_NONE);
    if (glCheckNamedFramebufferStatus(f->fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        release_copy(f);
        return sl_err_set(err, SL_ERR_GPU, "particles: the focus depth copy (%dx%d) is incomplete", w, h);
    }
    f->width = w;
    f->height = h;
    f->msaa = msaa;
    return sl_gl_check_errors("particles: the focus depth copy", err);
}

sl_status pt_focus_draw(pt_focus *f, const sl_view *view, const sl_params *params, const sl_target *target,
                        sl_render_stats *stats, sl_err *err)
{
    double radius = sl_params_float(params, "focus_radius");
    if (!(radius > 0.0))
        return SL_OK;
    sl_status st = ensure_ready(f, err);
    int msaa = target->samples > 1;
    if (st == SL_OK)
        st = ensure_copy(f, target->width, target->height, msaa, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "particles: focus");
        return st;
    }
    if (msaa) {
        /* The target's depth texture is read, not attached: no feedback. */
        glBindFramebuffer(GL_FRAMEBUFFER, f->fbo);
        glViewport(0, 0, target->width, target->height);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_BLEND);
        glUseProgram(f->resolve_program);
        glUniform1i(glGetUniformLocation(f->resolve_program, "u_depth"), 0);
        glUniform1i(glGetUniformLocation(f->resolve_program, "u_samples"), target->samples);
        glBindTextureUnit(0, target->depth);
        glBindVertexArray(f->vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glBindVertexArray(0);
        glBindTextureUnit(0, 0);
    } else {
        glBlitNamedFramebuffer(target->fbo, f->fbo, 0, 0, target->width, target->height, 0, 0, target->width,
                               target->height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, target->fbo);
    glViewport(0, 0, view->width, view->height);
    float centre[3], light[3];
    sl_params_vec3(params, "focus_center", centre);
    sl_params_vec3(params, "light_direction", light);
    /* volume_dvr's defaults for what the focus has no parameter of. */
    sl_volume_march_desc d = {
        .mode = SL_VOLUME_MARCH_COMPOSITE,
        .tf = sl_params_transfer(params, "focus_transfer_function"),
        .step = sl_params_float(params, "focus_step"),
        .jitter = 1,
        .clip = 0,
        .light_dir = {light[0], light[1], light[2]},
        .focus = {.centre = {centre[0], centre[1], centre[2]}, .radius = radius, .opaque_depth_tex = f->depth},
    };
    sl_render_stats ms = {0};
    if ((st = sl_volume_marcher_draw(&f->marcher, f->volume, &f->bricks, f->geom, view, &d, &ms, err)) != SL_OK) {
        sl_err_prefix(err, "particles: focus");
        return st;
    }
    glBindTextureUnit(6, 0);
    stats->samples += ms.samples;
    stats->samples_skipped += ms.samples_skipped;
    return SL_OK;
}
