/* fuzz_png.c — fuzz target for the PNG reader (sl_png_decode in renderer/image/png.c).
 *
 * Feeds arbitrary bytes to sl_png_decode, which runs libpng with the same
 * transforms, limits and setjmp error path as sl_png_read. On success the
 * result must be a consistent RGBA8 image; on failure the output must be
 * zeroed with a message. Leaks on the longjmp path show up under ASan.
 * Seed corpus: tests/fuzz/corpus/png/. Single-threaded.
 */
#include <stdint.h>
#include <stdlib.h>

#include "image/sl_image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sl_image img;
    sl_err err = {0};
    sl_status st = sl_png_decode(data, size, &img, &err);
    if (st == SL_OK) {
        if (img.width <= 0 || img.height <= 0 || !img.rgba ||
            (uint64_t)img.width * (uint64_t)img.height > SL_IMAGE_MAX_PIXELS)
            abort();
        volatile unsigned sink = 0;
        size_t n = (size_t)img.width * (size_t)img.height * 4;
        for (size_t i = 0; i < n; i += 61)
            sink += img.rgba[i];
        sink += img.rgba[n - 1];
        (void)sink;
    } else if (img.rgba || img.width || img.height || err.message[0] == '\0') {
        abort();
    }
    sl_image_deinit(&img);
    return 0;
}
