/* tf2d_check.c — does the colour of a curvature-coloured particles image
 * follow the curvature? (renderer/particles/particles_tf2d.h; tests in
 * tests/render/particles.cmake, section "curvature transfer function").
 *
 * usage: tf2d-check --png P --split R [--min-share S] [--min-count N]
 *
 * Classifies each pixel as red (r > b + 60 and r > 80), blue (b > r + 60
 * and b > 80) or neither, and splits them at distance R pixels from the
 * image centre. Meant for the torus seen along its axis with a function
 * that maps k1 > 0 (the inner, saddle half) red and k1 < 0 (the outer half)
 * blue: inside R the red share red / (red + blue) and outside R the blue
 * share must each be at least S (default 0.8), with at least N (default 50)
 * classified pixels on each side. Prints the counts and shares.
 * exit: 0 pass, 1 a limit failed, 2 bad input. Any thread, no GL.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/sl_image.h"

static int usage(void)
{
    fprintf(stderr, "usage: tf2d-check --png P --split R [--min-share S] [--min-count N]\n");
    return 2;
}

int main(int argc, char **argv)
{
    const char *png = NULL;
    double split = -1.0, min_share = 0.8, min_count = 50;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--png") == 0)
            png = argv[i + 1];
        else if (strcmp(argv[i], "--split") == 0)
            split = atof(argv[i + 1]);
        else if (strcmp(argv[i], "--min-share") == 0)
            min_share = atof(argv[i + 1]);
        else if (strcmp(argv[i], "--min-count") == 0)
            min_count = atof(argv[i + 1]);
        else
            return usage();
    }
    if (!png || !(split > 0.0) || argc % 2 == 0)
        return usage();
    sl_image img = {0};
    sl_err err = {0};
    if (sl_png_read(png, &img, &err) != SL_OK) {
        fprintf(stderr, "tf2d-check: %s\n", err.message);
        return 2;
    }
    long red[2] = {0, 0}, blue[2] = {0, 0}; /* [inside, outside] */
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            const uint8_t *p = img.rgba + ((size_t)y * img.width + x) * 4;
            double d = hypot(x + 0.5 - 0.5 * img.width, y + 0.5 - 0.5 * img.height);
            int side = d < split ? 0 : 1;
            if (p[0] > p[2] + 60 && p[0] > 80)
                red[side]++;
            else if (p[2] > p[0] + 60 && p[2] > 80)
                blue[side]++;
        }
    sl_image_deinit(&img);
    double in = (double)(red[0] + blue[0]), out = (double)(red[1] + blue[1]);
    double red_in = in > 0 ? red[0] / in : 0.0, blue_out = out > 0 ? blue[1] / out : 0.0;
    printf("inside %.0f px: red share %.3f (red %ld, blue %ld); outside %.0f px: blue share %.3f (red %ld, blue %ld)\n",
           split, red_in, red[0], blue[0], split, blue_out, red[1], blue[1]);
    int ok = in >= min_count && out >= min_count && red_in >= min_share && blue_out >= min_share;
    if (!ok)
        fprintf(stderr, "tf2d-check: needs at least %g classified pixels per side and shares >= %g\n", min_count,
                min_share);
    return ok ? 0 : 1;
}
