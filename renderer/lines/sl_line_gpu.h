/* sl_line_gpu.h — the GL half of the shared line preparation: colour path and style uniforms.
 *
 * sl_line_colors is the colormap texture (RGBA8 x SL_COLORMAP_TEXELS, linear,
 * clamped) and, unless texture-only, a per-vertex scalar SSBO of the style's
 * colour attribute (vertex_count + 1 floats, dataset vertex order); both are
 * re-uploaded only when the style's colormap or attribute changed. It does
 * not hold geometry, radii or anything per technique. Render thread only
 * (GL); every GL name here belongs to the struct, deleted by deinit.
 */
#ifndef SL_LINE_GPU_H
#define SL_LINE_GPU_H

#include <stddef.h>

#include <epoxy/gl.h>

#include "../data/sl_dataset.h"
#include "../line_style/sl_line_style.h"

typedef struct sl_line_colors {
    GLuint colormap_tex;   /* owned */
    GLuint scalars;        /* owned SSBO, or 0 (texture only) */
    int colormap_loaded;   /* colormap in colormap_tex, or -1 */
    int attribute_loaded;  /* attribute in scalars (texture only: last seen), or -2 */
    size_t vertex_count;
} sl_line_colors;

/* Creates the texture and, when with_scalars, the SSBO for vertex_count
 * vertices (nothing uploaded yet). SL_ERR_GPU (a GL error, e.g. out of
 * memory; the message starts with `owner`, the technique) with *c
 * deinitialized. */
sl_status sl_line_colors_init(sl_line_colors *c, size_t vertex_count, int with_scalars, const char *owner,
                              sl_err *err);

/* Uploads the style's colormap and (with scalars) its attribute's values when
 * they differ from what is loaded. Returns 1 when the attribute changed since
 * the last call (texture-only users refill their own colour buffers then),
 * else 0. style->attribute must be -1 or valid for l. */
int sl_line_colors_update(sl_line_colors *c, const sl_lines *l, const sl_line_style *style);

/* Binds the texture to texture_unit and the SSBO (if any) to ssbo_binding. */
void sl_line_colors_bind(const sl_line_colors *c, GLuint texture_unit, GLuint ssbo_binding);

/* GPU bytes of the texture plus the SSBO. */
size_t sl_line_colors_bytes(const sl_line_colors *c);
#define SL_LINE_COLORS_TEXTURE_BYTES ((size_t)SL_COLORMAP_TEXELS * 4u)

void sl_line_colors_deinit(sl_line_colors *c); /* zeroed or half-built is fine */

/* Sets the uniforms of gpu/glsl/line_style.glsl and the radii on the bound
 * program (glUseProgram(program) first): u_radius, u_radius_scale,
 * u_scalar_range, u_use_colormap, u_color, u_light_eye, u_material and
 * u_colormap = colormap_unit. Uniforms the program lacks are skipped by GL. */
void sl_line_style_uniforms(GLuint program, const sl_line_style *style, int colormap_unit);

#endif
