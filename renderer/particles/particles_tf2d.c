/* particles_tf2d.c — the 2D curvature transfer function of `particles`
 * (particles_tf2d.h). */
#include "particles_tf2d.h"

#include <math.h>
#include <string.h>

#include "../gpu/sl_gpu.h"

void pt_tf2d_eval(const sl_transfer_function_2d *tf, const float ink[3], double k1, double k2, double out[3])
{
    for (int c = 0; c < 3; c++)
        out[c] = ink[c];
    for (int k = 0; k < tf->count; k++) {
        const double *w = tf->widget[k];
        double d1 = k1 - w[0], d2 = k2 - w[1];
        double q2 = (d1 * d1 + d2 * d2) / (w[2] * w[2]);
        double f = q2 < 1.0 ? (1.0 - q2) * (1.0 - q2) : 0.0;
        double a = w[6] * f;
        for (int c = 0; c < 3; c++)
            out[c] += (w[3 + c] - out[c]) * a;
    }
}

double pt_tf2d_texel_center(double range, int i)
{
    return -range + (i + 0.5) * (2.0 * range / PT_TF2D_SIZE);
}

static uint8_t unorm8(double v)
{
    v = v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v;
    return (uint8_t)lround(v * 255.0);
}

void pt_tf2d_bake(const sl_transfer_function_2d *tf, const float ink[3], uint8_t rgba[PT_TF2D_SIZE * PT_TF2D_SIZE * 4])
{
    for (int j = 0; j < PT_TF2D_SIZE; j++) {
        double row = pt_tf2d_texel_center(tf->range, j);
        for (int i = 0; i < PT_TF2D_SIZE; i++) {
            double k1 = pt_tf2d_texel_center(tf->range, i), k2 = row, c[3];
            if (k2 > k1) /* unreachable (k1 >= k2): the diagonal's value at the projection */
                k1 = k2 = 0.5 * (k1 + k2);
            pt_tf2d_eval(tf, ink, k1, k2, c);
            uint8_t *t = rgba + ((size_t)j * PT_TF2D_SIZE + i) * 4;
            t[0] = unorm8(c[0]), t[1] = unorm8(c[1]), t[2] = unorm8(c[2]), t[3] = 255;
        }
    }
}

sl_status pt_tf2d_init(pt_tf2d *t, sl_err *err)
{
    memset(t, 0, sizeof *t);
    glCreateTextures(GL_TEXTURE_2D, PT_TF2D_SETS, t->tex);
    for (int k = 0; k < PT_TF2D_SETS; k++) {
        glTextureStorage2D(t->tex[k], 1, GL_RGBA8, PT_TF2D_SIZE, PT_TF2D_SIZE);
        glTextureParameteri(t->tex[k], GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(t->tex[k], GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(t->tex[k], GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTextureParameteri(t->tex[k], GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glObjectLabel(GL_TEXTURE, t->tex[k], -1, "particles curvature transfer function");
    }
    return sl_gl_check_errors("particles: curvature transfer function textures", err);
}

void pt_tf2d_deinit(pt_tf2d *t)
{
    for (int k = 0; k < PT_TF2D_SETS; k++)
        if (t->tex[k])
            glDeleteTextures(1, &t->tex[k]);
    memset(t, 0, sizeof *t);
}

pt_curvature_lookup pt_tf2d_lookup(pt_tf2d *t, int k, int on, const sl_transfer_function_2d *tf, const float ink[3],
                                   double min_spacing)
{
    pt_curvature_lookup c = {0};
    if (!on || k < 0 || k >= PT_TF2D_SETS || !t->tex[k])
        return c;
    if (!t->baked[k] || !sl_transfer_function_2d_equal(&t->tf[k], tf) || memcmp(t->ink[k], ink, sizeof t->ink[k])) {
        static uint8_t table[PT_TF2D_SIZE * PT_TF2D_SIZE * 4]; /* render thread only */
        pt_tf2d_bake(tf, ink, table);
        glTextureSubImage2D(t->tex[k], 0, 0, 0, PT_TF2D_SIZE, PT_TF2D_SIZE, GL_RGBA, GL_UNSIGNED_BYTE, table);
        t->tf[k] = *tf;
        memcpy(t->ink[k], ink, sizeof t->ink[k]);
        t->baked[k] = 1;
        t->bakes++;
    }
    c.table = t->tex[k];
    c.range = (float)tf->range;
    c.min_spacing = (float)min_spacing;
    c.on = 1;
    return c;
}

void pt_tf2d_uniforms(GLuint program, const pt_curvature_lookup *c, GLuint unit)
{
    glUniform1i(glGetUniformLocation(program, "u_tf2d_on"), c->on);
    glUniform1i(glGetUniformLocation(program, "u_tf2d"), (GLint)unit);
    glUniform1f(glGetUniformLocation(program, "u_tf2d_range"), c->on ? c->range : 1.0f);
    glUniform1f(glGetUniformLocation(program, "u_tf2d_min_spacing"), c->min_spacing);
    if (c->on)
        glBindTextureUnit(unit, c->table);
}
