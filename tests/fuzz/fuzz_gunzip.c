/* fuzz_gunzip.c — fuzz target for sl_gunzip (renderer/data/load_file.c).
 *
 * Inflates arbitrary bytes with a 1 MiB output limit (no path: sl_gunzip
 * works on memory only). On success the output must exist and fit the
 * limit, and every byte is read so ASan sees it; on failure the output must
 * be NULL / 0 and the message non-empty. Bombs must stop at the limit with
 * SL_ERR_LIMIT, never allocate past it. Seed corpus: tests/fuzz/corpus/gunzip/.
 * Single-threaded.
 */
#include <stdint.h>
#include <stdlib.h>

#include "data/sl_load.h"

#define FUZZ_GUNZIP_LIMIT (1u << 20)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t *out = NULL;
    size_t n = 12345;
    sl_err err = {0};
    sl_status st = sl_gunzip(data, size, FUZZ_GUNZIP_LIMIT, &out, &n, &err);
    if (st != SL_OK) {
        if (out || n != 0 || err.message[0] == '\0')
            abort();
        return 0;
    }
    if (!out || n > FUZZ_GUNZIP_LIMIT)
        abort();
    volatile unsigned sink = 0;
    for (size_t i = 0; i < n; i++)
        sink += out[i];
    (void)sink;
    free(out);
    return 0;
}
