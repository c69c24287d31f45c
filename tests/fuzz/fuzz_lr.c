/* fuzz_lr.c — fuzz target for the LR-spline loader (sl_load_lr in renderer/data/load_lr.c).
 *
 * Feeds arbitrary bytes as an in-memory .lr file with path NULL; the result
 * is checked by sl_fuzz_check (fuzz_check.h): on failure *out stays NULL
 * with a message, on success the model is consistent and evaluates to
 * finite values. Seed corpus: tests/fuzz/corpus/lr/. Single-threaded.
 */
#include <stdint.h>

#include "data/sl_load.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_lr(data, size, NULL, &ds, &err);
    sl_fuzz_check(st, ds, &err);
    return 0;
}
