/* image_error.h — the difference of two RGBA8 images as the render tests
 * and benchmarks report it: mean and max |dRGB| (0..255, every RGB channel
 * of every pixel) and `band`, the mean over blocks and channels of
 * |average of the signed difference over a block x block square|: the
 * spatially coherent part of the error. Wood-grain rings survive the
 * average; noise of zero mean (jittered sampling) mostly does not, so the
 * two are told apart at equal mean error. Pixels of incomplete blocks at the
 * right and top edges count in mean and max only. Any thread; pure.
 */
#ifndef IMAGE_ERROR_H
#define IMAGE_ERROR_H

#include <stdint.h>

typedef struct image_error {
    double mean, band;
    int max;
} image_error;

/* w x h RGBA8 images, block >= 1 (1: band = mean |signed d| = mean). */
image_error image_error_compare(const uint8_t *img, const uint8_t *ref, int w, int h, int block);

#endif
