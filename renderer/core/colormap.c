/* colormap.c — control points and sampling of the named colormaps (see sl_colormap.h). */
#include "sl_colormap.h"

#include <math.h>
#include <stddef.h>

const char *const sl_colormap_names[] = {"viridis", "magma", "plasma", "coolwarm", "gray", NULL};

/* Nine control points per map at t = 0, 1/8, ..., 1, as 0xRRGGBB. */
static const uint32_t control_points[][9] = {
    {0x440154, 0x472d7b, 0x3b528b, 0x2c728e, 0x21918c, 0x28ae80, 0x5ec962, 0xaddc30, 0xfde725},
    {0x000004, 0x1c1044, 0x4f127b, 0x812581, 0xb5367a, 0xe55064, 0xfb8761, 0xfec287, 0xfcfdbf},
    {0x0d0887, 0x4c02a1, 0x7e03a8, 0xa92395, 0xcc4778, 0xe66c5c, 0xf89540, 0xfdc527, 0xf0f921},
    {0x3b4cc0, 0x5977e3, 0x7b9ff9, 0x9ebeff, 0xdddddd, 0xf7b89c, 0xf49a7b, 0xde604d, 0xb40426},
    {0x000000, 0x202020, 0x404040, 0x606060, 0x808080, 0x9f9f9f, 0xbfbfbf, 0xdfdfdf, 0xffffff},
};

#define MAP_COUNT ((int)(sizeof control_points / sizeof control_points[0]))

void sl_colormap_sample(int colormap, double t, float rgb[3])
{
    if (colormap < 0 || colormap >= MAP_COUNT)
        colormap = 0;
    if (!(t > 0.0))
        t = 0.0;
    if (t > 1.0)
        t = 1.0;
    double x = t * 8.0;
    int k = (int)x;
    if (k > 7)
        k = 7;
    double f = x - k;
    uint32_t a = control_points[colormap][k], b = control_points[colormap][k + 1];
    for (int c = 0; c < 3; c++) {
        int shift = 16 - 8 * c;
        double ca = (double)((a >> shift) & 0xff), cb = (double)((b >> shift) & 0xff);
        rgb[c] = (float)((ca + (cb - ca) * f) / 255.0);
    }
}

void sl_colormap_table(int colormap, uint8_t rgba[SL_COLORMAP_TEXELS * 4])
{
    for (int k = 0; k < SL_COLORMAP_TEXELS; k++) {
        float rgb[3];
        sl_colormap_sample(colormap, (double)k / (SL_COLORMAP_TEXELS - 1), rgb);
        for (int c = 0; c < 3; c++)
            rgba[4 * k + c] = (uint8_t)lrintf(rgb[c] * 255.0f);
        rgba[4 * k + 3] = 255;
    }
}
