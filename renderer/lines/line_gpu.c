/* line_gpu.c — colormap texture, scalar SSBO and line-style uniforms (see sl_line_gpu.h).
 *
 * One copy of what tubes_mesh, lines_oit, tubes and voxel_lines each wrote
 * before. The SSBO has one float more than vertices so that an empty line set
 * still gets a valid buffer. Render thread only.
 */
#include "sl_line_gpu.h"

#include <stdio.h>
#include <string.h>

#include "../core/sl_colormap.h"
#include "../gpu/sl_gpu.h"

sl_status sl_line_colors_init(sl_line_colors *c, size_t vertex_count, int with_scalars, const char *owner,
                              sl_err *err)
{
    memset(c, 0, sizeof *c);
    c->colormap_loaded = -1;
    c->attribute_loaded = -2;
    c->vertex_count = vertex_count;
    if (with_scalars) {
        glCreateBuffers(1, &c->scalars);
        glNamedBufferStorage(c->scalars, (GLsizeiptr)((vertex_count + 1) * sizeof(float)), NULL,
                             GL_DYNAMIC_STORAGE_BIT);
    }
    glCreateTextures(GL_TEXTURE_2D, 1, &c->colormap_tex);
    glTextureStorage2D(c->colormap_tex, 1, GL_RGBA8, SL_COLORMAP_TEXELS, 1);
    glTextureParameteri(c->colormap_tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(c->colormap_tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(c->colormap_tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    char what[160];
    snprintf(what, sizeof what, "%s: the colormap texture and scalar buffer", owner);
    sl_status st = sl_gl_check_errors(what, err);
    if (st != SL_OK)
        sl_line_colors_deinit(c);
    return st;
}

int sl_line_colors_update(sl_line_colors *c, const sl_lines *l, const sl_line_style *style)
{
    if (style->colormap != c->colormap_loaded) {
        uint8_t table[SL_COLORMAP_TEXELS * 4];
        sl_colormap_table(style->colormap, table);
        glTextureSubImage2D(c->colormap_tex, 0, 0, 0, SL_COLORMAP_TEXELS, 1, GL_RGBA, GL_UNSIGNED_BYTE, table);
        c->colormap_loaded = style->colormap;
    }
    if (style->attribute == c->attribute_loaded)
        return 0;
    if (c->scalars && style->attribute >= 0 && c->vertex_count > 0)
        glNamedBufferSubData(c->scalars, 0, (GLsizeiptr)(c->vertex_count * sizeof(float)),
                             l->attributes[style->attribute].values);
    c->attribute_loaded = style->attribute;
    return 1;
}

void sl_line_colors_bind(const sl_line_colors *c, GLuint texture_unit, GLuint ssbo_binding)
{
    glBindTextureUnit(texture_unit, c->colormap_tex);
    if (c->scalars)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ssbo_binding, c->scalars);
}

size_t sl_line_colors_bytes(const sl_line_colors *c)
{
    return SL_LINE_COLORS_TEXTURE_BYTES + (c->scalars ? (c->vertex_count + 1) * sizeof(float) : 0);
}

void sl_line_colors_deinit(sl_line_colors *c)
{
    if (!c)
        return;
    if (c->colormap_tex)
        glDeleteTextures(1, &c->colormap_tex);
    if (c->scalars)
        glDeleteBuffers(1, &c->scalars);
    memset(c, 0, sizeof *c);
    c->colormap_loaded = -1;
    c->attribute_loaded = -2;
}

void sl_line_style_uniforms(GLuint program, const sl_line_style *style, int colormap_unit)
{
    glUniform1f(glGetUniformLocation(program, "u_radius"), style->radius);
    glUniform1f(glGetUniformLocation(program, "u_radius_scale"), style->radius_scale);
    glUniform2fv(glGetUniformLocation(program, "u_scalar_range"), 1, style->scalar_range);
    glUniform1i(glGetUniformLocation(program, "u_use_colormap"), style->attribute >= 0);
    glUniform3fv(glGetUniformLocation(program, "u_color"), 1, style->color);
    glUniform3fv(glGetUniformLocation(program, "u_light_eye"), 1, style->light_direction);
    glUniform4fv(glGetUniformLocation(program, "u_material"), 1, style->material);
    glUniform1i(glGetUniformLocation(program, "u_colormap"), colormap_unit);
}
