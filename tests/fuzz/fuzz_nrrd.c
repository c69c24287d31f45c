/* fuzz_nrrd.c — fuzz target for the NRRD loader (sl_load_nrrd in renderer/data/load_nrrd.c).
 *
 * Feeds arbitrary bytes as an in-memory file; path is NULL, so a
 * "data file" field is refused (detached reads are covered by the unit test).
 * On success the dataset must be a consistent volume (dims >= 1 within
 * SL_MAX_VOXELS, 1 or 3 components, value range ordered) and every voxel is
 * read so ASan sees the whole array; on failure *out must stay NULL and the
 * message be non-empty. The content-size probe of sl_load_file is driven
 * on the same bytes. Seed corpus: tests/fuzz/corpus/nrrd/. Single-threaded.
 */
#include <stdint.h>
#include <stdlib.h>

#include "data/load_common.h"
#include "data/sl_load.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* The content-size probe sl_load_file uses: with all bytes present it
     * must decide (0, "show me more", only for an empty file). */
    if (sl_load_nrrd_content_size(data, size, 1) == 0 && size > 0)
        abort();
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_nrrd(data, size, NULL, &ds, &err);
    if (st != SL_OK) {
        if (ds || err.message[0] == '\0')
            abort();
        return 0;
    }
    if (!ds)
        abort();
    const sl_volume *v = &ds->volume;
    if ((ds->kind != SL_DATASET_VOLUME && ds->kind != SL_DATASET_VECTORS) || !v->data ||
        (v->components != 1 && v->components != 3) || v->dims[0] < 1 || v->dims[1] < 1 || v->dims[2] < 1 ||
        (uint64_t)v->dims[0] * (uint64_t)v->dims[1] * (uint64_t)v->dims[2] * (uint64_t)v->components > SL_MAX_VOXELS ||
        !(v->value_min <= v->value_max) || !(v->spacing[0] > 0 && v->spacing[1] > 0 && v->spacing[2] > 0))
        abort();
    volatile double sink = 0.0;
    for (size_t z = 0; z < (size_t)v->dims[2]; z++)
        for (size_t y = 0; y < (size_t)v->dims[1]; y++)
            for (size_t x = 0; x < (size_t)v->dims[0]; x++)
                for (int c = 0; c < v->components; c++)
                    sink += sl_volume_value(v, x, y, z, c);
    (void)sink;
    sl_dataset_destroy(ds);
    return 0;
}
