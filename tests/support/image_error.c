/* image_error.c — see image_error.h. */
#include "image_error.h"

#include <math.h>
#include <stdlib.h>

image_error image_error_compare(const uint8_t *img, const uint8_t *ref, int w, int h, int block)
{
    image_error e = {0.0, 0.0, 0};
    double sum = 0.0, band = 0.0;
    long blocks = 0;
    for (int by = 0; by + block <= h; by += block)
        for (int bx = 0; bx + block <= w; bx += block)
            for (int c = 0; c < 3; c++) {
                long s = 0;
                for (int y = by; y < by + block; y++)
                    for (int x = bx; x < bx + block; x++) {
                        size_t i = 4 * ((size_t)y * (size_t)w + (size_t)x) + (size_t)c;
                        s += (long)img[i] - (long)ref[i];
                    }
                band += fabs((double)s / ((double)block * block));
                blocks++;
            }
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
        for (int c = 0; c < 3; c++) {
            int d = abs((int)img[4 * i + (size_t)c] - (int)ref[4 * i + (size_t)c]);
            sum += d;
            e.max = d > e.max ? d : e.max;
        }
    e.mean = w > 0 && h > 0 ? sum / (3.0 * (double)w * (double)h) : 0.0;
    e.band = blocks ? band / (double)blocks : 0.0;
    return e;
}
