/* sl_line_shade.h — the shared line style's shading on the CPU, for CPU executions of
 * line techniques (tubes' Embree backend) that must give the GL path's picture.
 *
 * The same formulas as gpu/glsl/colormap.glsl + lighting.glsl, step by step: the
 * scalar through the 256-texel colormap table with the GL texture's linear filter
 * (texel centres at t * 255), an empty range giving the middle colour and NaN the
 * start; Lambert + Blinn-Phong, two-sided, with the light given in eye space
 * (x right, y up, z towards the viewer) turned into the view's world frame; the
 * result rounded to RGBA8 as GL stores a unorm8 colour. The tubes backend tests
 * (unit.test_tubes_backend, render.tubes.backend.*) compare its frames with the GLSL's
 * over the covered pixels. Any thread after init.
 */
#ifndef SL_LINE_SHADE_H
#define SL_LINE_SHADE_H

#include <stdint.h>

#include "../core/sl_camera.h"
#include "../core/sl_colormap.h"
#include "sl_line_style.h"

typedef struct sl_line_shader {
    uint8_t table[SL_COLORMAP_TEXELS * 4]; /* the colormap texture's texels */
    int use_colormap;                      /* 0: color */
    float range[2];
    float color[3];
    double light[3];                       /* unit, world directions, towards the light */
    float material[4];                     /* ambient, diffuse, specular, shininess */
} sl_line_shader;

void sl_line_shader_init(sl_line_shader *sh, const sl_line_style *style, const sl_view *view);

/* The colormap's colour of `scalar` (0..1 per channel), as colormap.glsl samples it. */
void sl_line_shader_base(const sl_line_shader *sh, float scalar, float rgb[3]);

/* sl_shade of lighting.glsl, clamped to 0..1 (before rounding): base the unlit colour, n the
 * unit surface normal, v the unit direction towards the eye. */
void sl_line_shader_lit(const sl_line_shader *sh, const float base[3], const float n[3], const float v[3],
                        float rgb[3]);

/* The shaded colour: n the unit surface normal, v the unit direction towards the eye. */
void sl_line_shader_color(const sl_line_shader *sh, float scalar, const float n[3], const float v[3],
                          uint8_t rgba[4]);

#endif
