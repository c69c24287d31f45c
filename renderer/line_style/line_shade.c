/* line_shade.c — sl_line_shade.h: colormap.glsl and lighting.glsl, in C, in float as GLSL. */
#include <math.h>
#include <string.h>

#include "sl_line_shade.h"

void sl_line_shader_init(sl_line_shader *sh, const sl_line_style *style, const sl_view *view)
{
    memset(sh, 0, sizeof *sh);
    sl_colormap_table(style->colormap, sh->table);
    sh->use_colormap = style->attribute >= 0;
    memcpy(sh->range, style->scalar_range, sizeof sh->range);
    memcpy(sh->color, style->color, sizeof sh->color);
    memcpy(sh->material, style->material, sizeof sh->material);
    const float *l = style->light_direction;
    double w[3] = {l[0] * view->right.x + l[1] * view->upv.x - l[2] * view->forward.x,
                   l[0] * view->right.y + l[1] * view->upv.y - l[2] * view->forward.y,
                   l[0] * view->right.z + l[1] * view->upv.z - l[2] * view->forward.z};
    double len = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int k = 0; k < 3; k++)
        sh->light[k] = len > 0.0 ? w[k] / len : 0.0;
}

void sl_line_shader_base(const sl_line_shader *sh, float scalar, float rgb[3])
{
    if (!sh->use_colormap) {
        memcpy(rgb, sh->color, 3 * sizeof(float));
        return;
    }
    float span = sh->range[1] - sh->range[0];
    float t = span != 0.0f ? fminf(fmaxf((scalar - sh->range[0]) / span, 0.0f), 1.0f) : 0.5f;
    if (isnan(t))
        t = 0.0f;
    /* texture(map, (t * 255 + 0.5) / 256) with GL_LINEAR: texel centres at t * 255. */
    float x = t * 255.0f;
    int i = (int)floorf(x);
    if (i > SL_COLORMAP_TEXELS - 2)
        i = SL_COLORMAP_TEXELS - 2;
    float f = x - (float)i;
    for (int c = 0; c < 3; c++)
        rgb[c] = ((1.0f - f) * sh->table[4 * i + c] + f * sh->table[4 * (i + 1) + c]) / 255.0f;
}

void sl_line_shader_lit(const sl_line_shader *sh, const float base[3], const float n_in[3], const float v[3],
                        float rgb[3])
{
    float n[3] = {n_in[0], n_in[1], n_in[2]};
    float l[3] = {(float)sh->light[0], (float)sh->light[1], (float)sh->light[2]};
    if (n[0] * v[0] + n[1] * v[1] + n[2] * v[2] < 0.0f)
        for (int k = 0; k < 3; k++)
            n[k] = -n[k];
    float diff = fmaxf(n[0] * l[0] + n[1] * l[1] + n[2] * l[2], 0.0f);
    float h[3] = {l[0] + v[0], l[1] + v[1], l[2] + v[2]};
    float hl = sqrtf(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    float spec = 0.0f;
    if (diff > 0.0f && hl > 0.0f)
        spec = powf(fmaxf((n[0] * h[0] + n[1] * h[1] + n[2] * h[2]) / hl, 0.0f), sh->material[3]);
    for (int c = 0; c < 3; c++) {
        float value = base[c] * (sh->material[0] + sh->material[1] * diff) + sh->material[2] * spec;
        rgb[c] = fminf(fmaxf(value, 0.0f), 1.0f);
    }
}

void sl_line_shader_color(const sl_line_shader *sh, float scalar, const float n[3], const float v[3],
                          uint8_t rgba[4])
{
    float base[3], rgb[3];
    sl_line_shader_base(sh, scalar, base);
    sl_line_shader_lit(sh, base, n, v, rgb);
    for (int c = 0; c < 3; c++)
        rgba[c] = (uint8_t)lrintf(rgb[c] * 255.0f);
    rgba[3] = 255;
}
