/* fuzz_generate.c — fuzz target for generator calls (sl_generate_json in renderer/data/generate.c).
 *
 * Generator JSON arrives from scenes over the network, so its parsing and
 * key validation get the same treatment as a file loader. The input is
 * NUL-terminated and passed as the call; the result is checked by
 * sl_fuzz_check (fuzz_check.h): on failure *out stays NULL with a
 * message, on success the dataset is consistent and fully read. Calls whose
 * numeric keys (other than seed and time) exceed 64 are skipped so each run
 * stays small; the validation of large values is covered by test_generate.
 * Seed corpus: tests/fuzz/corpus/generate/. Single-threaded.
 */
#include <cjson/cJSON.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_generate.h"
#include "fuzz_check.h"

/* 1 when a parsed call would generate more than a few thousand elements. */
static int too_big(const char *text)
{
    cJSON *root = cJSON_Parse(text);
    int big = 0;
    for (const cJSON *item = root && cJSON_IsObject(root) ? root->child : NULL; item; item = item->next)
        if (cJSON_IsNumber(item) && item->valuedouble > 64.0 && item->string &&
            strcmp(item->string, "seed") != 0 && strcmp(item->string, "time") != 0)
            big = 1;
    cJSON_Delete(root);
    return big;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    if (!too_big(text)) {
        sl_dataset *ds = NULL;
        sl_err err = {0};
        sl_status st = sl_generate_json(text, &ds, &err);
        sl_fuzz_check(st, ds, &err);
    }
    free(text);
    return 0;
}
