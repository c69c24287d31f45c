/* golden_offset.c — writes a PNG with a uniform error on every drawn pixel, to
 * prove that the golden-image limits catch one (tests/render/<technique>.cmake,
 * detects_uniform_error tests).
 *
 * usage: golden-offset IN.png OUT.png R,G,B N
 * Every pixel of IN whose RGB differs from the background R,G,B (0..255) gets
 * +N on each of R, G, B (-N where that would pass 255), so its max-channel
 * difference from IN is exactly N; background pixels and alpha are copied.
 * Prints the count of changed pixels. Exit 0 written, 2 bad usage or input.
 * Single-threaded; test-only.
 */
#include <stdio.h>
#include <stdlib.h>

#include "image/sl_image.h"

int main(int argc, char **argv)
{
    unsigned rgb[3];
    int add = 0;
    char tail;
    if (argc != 5 || sscanf(argv[3], "%u,%u,%u%c", &rgb[0], &rgb[1], &rgb[2], &tail) != 3 || rgb[0] > 255 ||
        rgb[1] > 255 || rgb[2] > 255 || sscanf(argv[4], "%d%c", &add, &tail) != 1 || add < 1 || add > 127) {
        fprintf(stderr, "usage: golden-offset IN.png OUT.png R,G,B N (R, G, B in 0..255, N in 1..127)\n");
        return 2;
    }
    const uint8_t bg[3] = {(uint8_t)rgb[0], (uint8_t)rgb[1], (uint8_t)rgb[2]};
    sl_image img = {0};
    sl_err err = {0};
    if (sl_png_read(argv[1], &img, &err) != SL_OK) {
        fprintf(stderr, "golden-offset: %s\n", err.message);
        return 2;
    }
    size_t n = (size_t)img.width * (size_t)img.height;
    long changed = 0;
    for (size_t i = 0; i < n; i++) {
        uint8_t *px = img.rgba + i * 4;
        if (px[0] == bg[0] && px[1] == bg[1] && px[2] == bg[2])
            continue;
        for (int c = 0; c < 3; c++)
            px[c] = (uint8_t)(px[c] + add <= 255 ? px[c] + add : px[c] - add);
        changed++;
    }
    sl_status st = sl_png_write(argv[2], img.rgba, img.width, img.height, &err);
    sl_image_deinit(&img);
    if (st != SL_OK) {
        fprintf(stderr, "golden-offset: %s\n", err.message);
        return 2;
    }
    printf("golden-offset: %ld of %zu pixels changed by %d\n", changed, n, add);
    return 0;
}
