/* sl_colormap.h — named colormaps shared by every technique.
 *
 * A colormap is a piecewise-linear ramp through 9 sRGB control points
 * (matplotlib's viridis, magma, plasma; Moreland's cool-warm; grey).
 * Techniques upload sl_colormap_table() as a 256-texel texture and sample
 * it in GLSL (gpu/glsl/colormap.glsl); the CPU path (references, tests) uses
 * sl_colormap_sample. Use sl_colormap_names as an enum parameter's choices.
 */
#ifndef SL_COLORMAP_H
#define SL_COLORMAP_H

#include <stdint.h>

#define SL_COLORMAP_TEXELS 256

extern const char *const sl_colormap_names[]; /* NULL-terminated; index = colormap id */

/* rgb in 0..1 for t in [0, 1] (clamped; NaN gives the t = 0 colour). */
void sl_colormap_sample(int colormap, double t, float rgb[3]);

/* SL_COLORMAP_TEXELS RGBA8 texels, texel k at t = k / (TEXELS - 1). */
void sl_colormap_table(int colormap, uint8_t rgba[SL_COLORMAP_TEXELS * 4]);

#endif
