/* lr_bezier_gpu.c — the GPU side of the Bézier blocks (sl_lr_bezier.h): the
 * shader storage buffers (float always, double on request), their bindings,
 * the uniforms and #defines of lr_bezier.glsl, and the element look-up's
 * buffers (made, bound and freed with the blocks; lr_find.glsl pastes its
 * GLSL). Render thread (needs the GL context). */
#include "sl_lr_bezier.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../gpu/sl_gpu.h"

/* The element look-up travels with the blocks: its buffers are made and
 * bound here, its kind is compiled in by sl_lr_bezier_defines. */
static sl_status lookup_upload(const sl_lr_bezier *bz, sl_lr_bezier_gpu *gpu, sl_err *err)
{
    sl_status st = sl_lr_lookup_gpu_init(&gpu->lookup, bz->lookup, 0, err);
    if (st == SL_OK)
        gpu->bytes += gpu->lookup.bytes;
    return st;
}

static sl_status make_buffer(GLuint *buf, const void *data, size_t bytes, const char *what, sl_err *err)
{
    glCreateBuffers(1, buf);
    glNamedBufferStorage(*buf, (GLsizeiptr)bytes, data, 0);
    return sl_gl_check_errors(what, err);
}

sl_status sl_lr_bezier_upload(const sl_lr_bezier *bz, int want_double, sl_lr_bezier_gpu *gpu, sl_err *err)
{
    memset(gpu, 0, sizeof *gpu);
    size_t ne = bz->element_count, nc = ne * bz->stride;
    float *box = malloc(sizeof(float) * 8 * ne);
    float *coef = malloc(sizeof(float) * (nc ? nc : 1));
    if (!box || !coef) {
        free(box);
        free(coef);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory packing %zu Bézier blocks", ne);
    }
    for (size_t e = 0; e < ne; e++) {
        for (int d = 0; d < 3; d++) {
            box[e * 8 + (size_t)d] = (float)bz->lo[e * 3 + (size_t)d];
            box[e * 8 + 4 + (size_t)d] = (float)bz->hi[e * 3 + (size_t)d];
        }
        /* The hull rounded outwards, so it stays a bound in float. */
        box[e * 8 + 3] = nextafterf((float)bz->hull_min[e], -INFINITY);
        box[e * 8 + 7] = nextafterf((float)bz->hull_max[e], INFINITY);
    }
    for (size_t i = 0; i < nc; i++)
        coef[i] = (float)bz->coef[i];
    sl_status st = make_buffer(&gpu->box_buffer, box, sizeof(float) * 8 * ne, "LR block boxes", err);
    if (st == SL_OK)
        st = make_buffer(&gpu->coef_buffer, coef, sizeof(float) * (nc ? nc : 1), "LR block coefficients", err);
    gpu->bytes = sizeof(float) * (8 * ne + nc);
    free(box);
    free(coef);
    if (st == SL_OK && want_double)
        st = sl_lr_bezier_upload_double(bz, gpu, err);
    if (st == SL_OK)
        st = lookup_upload(bz, gpu, err);
    gpu->element_count = ne;
    if (st != SL_OK)
        sl_lr_bezier_release(gpu);
    return st;
}

sl_status sl_lr_bezier_upload_double(const sl_lr_bezier *bz, sl_lr_bezier_gpu *gpu, sl_err *err)
{
    if (gpu->box_buffer_d)
        return SL_OK;
    size_t ne = bz->element_count, nc = ne * bz->stride;
    double *boxd = malloc(sizeof(double) * 8 * (ne ? ne : 1));
    if (!boxd)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory packing %zu double Bézier blocks", ne);
    for (size_t e = 0; e < ne; e++) {
        for (int d = 0; d < 3; d++) {
            boxd[e * 8 + (size_t)d] = bz->lo[e * 3 + (size_t)d];
            boxd[e * 8 + 4 + (size_t)d] = bz->hi[e * 3 + (size_t)d];
        }
        boxd[e * 8 + 3] = bz->hull_min[e];
        boxd[e * 8 + 7] = bz->hull_max[e];
    }
    GLuint box = 0, coef = 0;
    sl_status st = make_buffer(&box, boxd, sizeof(double) * 8 * ne, "LR double block boxes", err);
    if (st == SL_OK)
        st = make_buffer(&coef, bz->coef, sizeof(double) * (nc ? nc : 1), "LR double block coefficients", err);
    free(boxd);
    if (st != SL_OK) {
        GLuint b[2] = {box, coef};
        for (int i = 0; i < 2; i++)
            if (b[i])
                glDeleteBuffers(1, &b[i]);
        return st;
    }
    gpu->box_buffer_d = box;
    gpu->coef_buffer_d = coef;
    gpu->bytes += sizeof(double) * (8 * ne + nc);
    return SL_OK;
}

void sl_lr_bezier_bind(const sl_lr_bezier_gpu *gpu, unsigned program)
{
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SL_LR_BOX_BINDING, gpu->box_buffer);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SL_LR_COEF_BINDING, gpu->coef_buffer);
    if (gpu->box_buffer_d) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SL_LR_BOX_BINDING_D, gpu->box_buffer_d);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SL_LR_COEF_BINDING_D, gpu->coef_buffer_d);
    }
    sl_lr_lookup_gpu_bind(&gpu->lookup, program);
}

void sl_lr_bezier_release(sl_lr_bezier_gpu *gpu)
{
    if (!gpu)
        return;
    GLuint b[4] = {gpu->box_buffer, gpu->coef_buffer, gpu->box_buffer_d, gpu->coef_buffer_d};
    for (int i = 0; i < 4; i++)
        if (b[i])
            glDeleteBuffers(1, &b[i]);
    sl_lr_lookup_gpu_deinit(&gpu->lookup);
    memset(gpu, 0, sizeof *gpu);
}

void sl_lr_bezier_defines(const sl_lr_bezier *bz, int want_double, char *out, size_t size)
{
    snprintf(out, size, "#define LR_O0 %d\n#define LR_O1 %d\n#define LR_O2 %d\n#define LR_DIM %d\n"
             "#define LR_DOUBLE %d\n%s", bz->order[0], bz->order[1], bz->order[2], bz->dim, want_double ? 1 : 0,
             sl_lr_lookup_glsl_define(bz->lookup_kind));
}

void sl_lr_bezier_set_uniforms(unsigned program, const sl_lr_bezier *bz)
{
    glUniform1i(glGetUniformLocation(program, "u_lr_element_count"), (GLint)bz->element_count);
    glUniform3fv(glGetUniformLocation(program, "u_lr_domain_lo"), 1, bz->domain_lo);
    glUniform3fv(glGetUniformLocation(program, "u_lr_domain_hi"), 1, bz->domain_hi);
}
