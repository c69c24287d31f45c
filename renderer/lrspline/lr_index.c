/* lr_index.c — the CPU element look-up a model carries (sl_lr_index in
 * sl_lr.h; lr_eval.c's sl_lr_find_element asks it): the `auto` structure of sl_lr_lookup.h,
 * built once per finished model and read-only afterwards, so any number of
 * threads may query it; sl_lr_index_match hands it to whoever would build
 * the same structure again (the GPU blocks of sl_lr_bezier.h). */
#include <stdlib.h>

#include "lr_index.h"
#include "sl_lr_lookup.h"

sl_status sl_lr_index(sl_lr_volume *lr, sl_err *err)
{
    sl_lr_drop_index(lr);
    sl_lr_lookup *lk = calloc(1, sizeof *lk);
    if (!lk)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the element look-up");
    sl_status st = sl_lr_lookup_init(lk, lr, SL_LR_LOOKUP_AUTO, 0, err);
    if (st != SL_OK) {
        free(lk);
        return st;
    }
    lr->index = lk;
    return SL_OK;
}

void sl_lr_drop_index(sl_lr_volume *lr)
{
    if (lr->index) {
        sl_lr_lookup_deinit(lr->index);
        free(lr->index);
        lr->index = NULL;
    }
}

const sl_lr_lookup *sl_lr_index_match(const sl_lr_volume *lr, sl_lr_lookup_kind kind, int forest_axis)
{
    const sl_lr_lookup *lk = lr->index;
    if (!lk)
        return NULL;
    int default_forest = forest_axis == 0 || forest_axis == SL_LR_FOREST_DEFAULT_AXIS;
    if (kind == SL_LR_LOOKUP_AUTO || (kind == SL_LR_LOOKUP_TEXTURE && lk->kind == SL_LR_LOOKUP_TEXTURE) ||
        (kind == SL_LR_LOOKUP_KDFOREST && default_forest && lk->kind == SL_LR_LOOKUP_KDFOREST))
        return lk;
    return NULL;
}
