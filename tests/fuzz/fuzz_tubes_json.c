/* fuzz_tubes_json.c — fuzz target for explicit Hermite tube data (sl_load_hermite_json,
 * renderer/tubes/tubes_nodes.c).
 *
 * Arbitrary bytes as a JSON document, path NULL. On failure *out must stay
 * NULL with a message; on success the line set must be consistent and the
 * node builder must give finite nodes and in-range segment indices (every
 * value is read, so ASan sees the arrays). Violations abort(). Seed corpus:
 * tests/fuzz/corpus/tubes_json/. Single-threaded.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "data/sl_load.h"
#include "tubes/tubes_nodes.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_hermite_json(data, size, NULL, &ds, &err);
    if (st != SL_OK) {
        if (ds || err.message[0] == '\0')
            abort();
        return 0;
    }
    if (!ds || ds->lines.vertex_count != 2 * ds->lines.line_count)
        abort();
    sl_tubes_nodes n;
    if (sl_tubes_nodes_build(&ds->lines, SL_TUBES_TANGENTS_AUTO, 0, &n, &err) != SL_OK)
        abort();
    for (size_t i = 0; i < n.node_count * SL_TUBES_NODE_FLOATS; i++)
        if (!isfinite(n.geometry[i]))
            abort();
    for (size_t i = 0; i < n.node_count * 2; i++)
        if (!isfinite(n.color[i]))
            abort();
    for (size_t i = 0; i < n.segment_count * 2; i++)
        if (n.segments[i] >= n.node_count)
            abort();
    sl_tubes_nodes_deinit(&n);
    sl_dataset_destroy(ds);
    return 0;
}
