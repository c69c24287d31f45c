/* fuzz_pfm.c — fuzz target for the PFM parser (sl_pfm_parse in renderer/image/pfm.c).
 *
 * Feeds arbitrary bytes to sl_pfm_parse. On success the result must be
 * consistent (positive size within SL_IMAGE_MAX_PIXELS, every value readable);
 * on failure the output must be zeroed and the message non-empty. ASan/UBSan
 * catch over-reads; the size-vs-bytes check keeps allocations bounded by the
 * input length. Seed corpus: tests/fuzz/corpus/pfm/. Single-threaded.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "image/sl_image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sl_depth_image img;
    sl_err err = {0};
    sl_status st = sl_pfm_parse(data, size, &img, &err);
    if (st == SL_OK) {
        if (img.width <= 0 || img.height <= 0 || !img.values ||
            (uint64_t)img.width * (uint64_t)img.height > SL_IMAGE_MAX_PIXELS ||
            (uint64_t)img.width * (uint64_t)img.height * 4u > size)
            abort();
        volatile float sink = 0.0f;
        for (size_t i = 0; i < (size_t)img.width * (size_t)img.height; i++)
            sink += img.values[i];
        (void)sink;
    } else if (img.values || img.width || img.height || err.message[0] == '\0') {
        abort();
    }
    sl_depth_image_deinit(&img);
    return 0;
}
