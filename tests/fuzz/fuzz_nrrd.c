/* fuzz_nrrd.c — fuzz target for the NRRD loader (sl_load_nrrd in renderer/data/load_nrrd.c).
 *
 * Feeds arbitrary bytes as an in-memory file; path is NULL, so a
 * "data file" field is refused (detached reads are covered by the unit test).
 * The result is checked by sl_fuzz_check (fuzz_check.h). The content-size probe of sl_load_file is driven
 * on the same bytes. Seed corpus: tests/fuzz/corpus/nrrd/. Single-threaded.
 */
#include <stdint.h>
#include <stdlib.h>

#include "data/load_common.h"
#include "data/sl_load.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* The content-size probe sl_load_file uses: with all bytes present it
     * must decide (0, "show me more", only for an empty file). */
    if (sl_load_nrrd_content_size(data, size, 1) == 0 && size > 0)
        abort();
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_nrrd(data, size, NULL, &ds, &err);
    sl_fuzz_check(st, ds, &err);
    return 0;
}
